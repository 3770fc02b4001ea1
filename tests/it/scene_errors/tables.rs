//! Errors in the analysis tables: limit cases, peak windows, hysteresis frequencies and
//! sweeps.

use super::*;

#[test]
fn limit_case_names_an_unknown_side() {
    rejects_invalid(
        &paper_plus("[limits]\n[[limits.cases]]\nsides = { middle = 0.5 }\n"),
        "limits.cases[0].sides.middle",
        "unknown damper side `middle` (the scene has left, right)",
    );
}

#[test]
fn limit_case_names_an_unknown_contact() {
    rejects_invalid(
        &paper_plus("[limits]\n[[limits.cases]]\ncontacts = { nope = 0.5 }\n"),
        "limits.cases[0].contacts.nope",
        "unknown contact `nope`",
    );
}

#[test]
fn limit_case_state_outside_the_slip_limits() {
    rejects_invalid(
        &paper_plus("[limits]\n[[limits.cases]]\nsides = { left = 1.5 }\n"),
        "limits.cases[0].sides.left",
        "must lie in [-1, 1]",
    );
}

#[test]
fn limit_case_without_any_state() {
    rejects_invalid(
        &paper_plus("[limits]\n[[limits.cases]]\nname = \"empty\"\n"),
        "limits.cases[0]",
        "give m for at least one damper side",
    );
}

#[test]
fn limit_case_name_clashes_with_a_limit_curve() {
    rejects_invalid(
        &paper_plus("[limits]\n[[limits.cases]]\nname = \"m+1\"\nsides = { left = 0.5 }\n"),
        "limits.cases[0].name",
        "already used",
    );
    rejects_invalid(
        &paper_plus(
            "[limits]\n[[limits.cases]]\nsides = { left = 0.5 }\n\
             [[limits.cases]]\nsides = { left = 0.5 }\n",
        ),
        "limits.cases[1].name",
        "`left+0.5` is already used",
    );
}

#[test]
fn peak_window_reversed_or_outside_the_range() {
    rejects_invalid(
        &paper_plus("[limits]\npeak_window_hz = [230.0, 200.0]\n"),
        "limits.peak_window_hz",
        "reversed or empty",
    );
    rejects_invalid(
        &paper_plus("[limits]\npeak_window_hz = [400.0, 500.0]\n"),
        "limits.peak_window_hz",
        "outside the analysis range 50 .. 350 Hz",
    );
}

#[test]
fn hysteresis_frequency_outside_the_range() {
    rejects_invalid(
        &paper_plus("[limits]\n[limits.hysteresis]\nfreqs_hz = [100.0, 400.0]\n"),
        "limits.hysteresis.freqs_hz[1]",
        "400 Hz lies outside the analysis range",
    );
}

#[test]
fn sweep_series_without_values() {
    rejects_invalid(
        &paper_plus(
            "[limits]\n[sweep]\nparameter = \"F0\"\nvalues = [60.0]\n\
             targets = [{ field = \"static_loads.0.value\", scale = -1.0 }]\n\
             [sweep.series]\nparameter = \"beta\"\nvalues = []\n\
             targets = [{ field = \"contacts.0.angle_deg\" }]\n",
        ),
        "sweep.series.values",
        "must hold at least one value",
    );
}

#[test]
fn sweep_output_unknown() {
    let file = SceneFile::new(&paper_plus(
        "[limits]\n[sweep]\nparameter = \"F0\"\noutput = \"curves\"\nvalues = [60.0]\n\
         targets = [{ field = \"static_loads.0.value\" }]\n",
    ));
    let err = library_error(&file, &[]);
    assert_parse(
        &err,
        &file.label(),
        &["unknown variant `curves`", "peaks", "limits"],
    );
    assert_cli_rejects(&file.label(), &[], &["unknown variant `curves`"]);
}
