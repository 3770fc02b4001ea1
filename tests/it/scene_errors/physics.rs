//! Refusals that say why: free bodies, loads the contacts cannot carry, extreme values,
//! FE materials out of bounds, and sweeps checked at every point.

use super::*;

// ---------------------------------------------------------------------------------------------
// Refusals that say why: free bodies, extreme values, and sweeps checked at every point.
// ---------------------------------------------------------------------------------------------

/// The paper scene (or `text`) with `overrides` must be refused by the library with an
/// `Invalid` error for `field` whose reason holds every one of `parts`, by `fricbound check`
/// with an `error:` line holding the field and the parts, and by `fricbound run` at the door:
/// non-zero exit and no output folder written.
fn rejects_with(text: &str, overrides: &[&str], field: &str, parts: &[&str]) {
    let file = SceneFile::new(text);
    let label = file.label();
    let err = library_error(&file, overrides);
    assert_invalid(&err, &label, field, parts[0]);
    let message = err.to_string();
    for part in parts {
        assert!(message.contains(part), "`{part}` missing from: {message}");
    }
    let mut cli_parts = vec![field];
    cli_parts.extend_from_slice(parts);
    assert_cli_rejects(&label, overrides, &cli_parts);

    let out = tempfile::tempdir().expect("temporary folder");
    let out_dir = out.path().join("results");
    let out_label = out_dir.display().to_string();
    let mut args = vec![
        "run",
        label.as_str(),
        "--quiet",
        "--out",
        out_label.as_str(),
    ];
    for o in overrides {
        args.extend(["--set", o]);
    }
    let run = fricbound(&args);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    assert_ne!(run.code, Some(0), "run accepted the scene:\n{}", run.stdout);
    assert!(
        run.stderr
            .lines()
            .any(|l| l.starts_with("error:") && l.contains(field)),
        "run did not name `{field}`:\n{}",
        run.stderr
    );
    assert!(
        !out_dir.exists(),
        "run wrote {} before refusing the scene",
        out_dir.display()
    );
}

/// The scene `text` with `overrides` must validate.
fn accepts(text: &str, overrides: &[&str]) {
    if let Err(e) = scene::parse(text, "scene", &strings(overrides)).and_then(|s| {
        s.validate_with_limits("scene")?;
        Ok(())
    }) {
        panic!("refused with {overrides:?}: {e}");
    }
}

#[test]
fn free_damper_without_preload_names_the_body() {
    // F0 = 0: the damper is held by nothing; before this check the run failed with "no
    // convergence in 36 iterations" and no reason.
    rejects_with(
        paper_wedge_scene(),
        &["static_loads.0.value=0"],
        "static_loads[0].value",
        &[
            "the body with DOFs xD, yD is held only by its contacts `left`, `right`",
            "1 rigid-body mode",
            "nothing presses it onto them",
            "the friction limit μN is zero",
            "give it a pre-load",
        ],
    );
    // Without the static load entry at all, the field is the table.
    let err = match scene::parse(paper_wedge_scene(), "paper", &strings(&["static_loads.0="]))
        .and_then(|s| s.validate("paper"))
    {
        Ok(_) => panic!("a scene without pre-load was accepted"),
        Err(e) => e,
    };
    assert_invalid(
        &err,
        "paper",
        "static_loads",
        "the body with DOFs xD, yD is held only by its contacts",
    );
}

#[test]
fn free_damper_check_refuses_only_an_unheld_body() {
    let paper = paper_wedge_scene();
    // A tiny pre-load still presses the damper onto its contacts.
    accepts(paper, &["static_loads.0.value=-1e-3"]);
    // Bilateral normal springs hold it without pre-load; uncoupled statics fix it at rest.
    accepts(paper, &["static_loads.0.value=0", "effects.liftoff=false"]);
    accepts(
        paper,
        &["static_loads.0.value=0", "effects.coupling=uncoupled"],
    );
    // A damper grounded by K is not free.
    accepts(
        paper,
        &[
            "static_loads.0.value=0",
            "model.stiffness.4.4=4.0e5",
            "model.stiffness.5.5=4.0e5",
        ],
    );
    // A load on a blade may squeeze the damper: not shown to be free, not refused.
    accepts(
        paper,
        &["static_loads.0.dof=x1", "static_loads.0.value=500"],
    );
    // An interference presses the contacts.
    accepts(
        paper,
        &[
            "static_loads.0.value=0",
            "contacts.0.gap=-1e-5",
            "contacts.1.gap=-1e-5",
        ],
    );
}

/// A point mass (x, y) without stiffness, held only by grounded contacts: a floor below it
/// (normal −y from the mass into the floor), plus the contacts in `extra`.
fn free_mass(extra: &str, static_loads: &str) -> String {
    format!(
        r#"title = "A free mass on grounded contacts"

[model]
dofs = ["x", "y"]
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[0.0, 0.0], [0.0, 0.0]]

[[contacts]]
name = "floor"
damper = ["x", "y"]
tangent = [1.0, 0.0]
normal = [0.0, -1.0]
kt = 1.0e5
kn = 1.0e5
mu = 0.5
{extra}
{static_loads}
[[harmonic_loads]]
dof = "x"
cos = 1.0

[harmonics]
max = 1
samples = 64

[analysis]
freq_start_hz = 10.0
freq_end_hz = 100.0

[output]
dofs = ["x"]
"#
    )
}

/// A grounded contact of the free mass named `name` with its normal (from the mass into the
/// obstacle) and tangent.
fn wall(name: &str, normal: [f64; 2], tangent: [f64; 2]) -> String {
    format!(
        "\n[[contacts]]\nname = \"{name}\"\ndamper = [\"x\", \"y\"]\n\
         tangent = [{:?}, {:?}]\nnormal = [{:?}, {:?}]\nkt = 1.0e5\nkn = 1.0e5\nmu = 0.5\n",
        tangent[0], tangent[1], normal[0], normal[1]
    )
}

#[test]
fn body_locked_between_contacts_needs_no_preload() {
    let walls = [
        wall("ceiling", [0.0, 1.0], [1.0, 0.0]),
        wall("left", [-1.0, 0.0], [0.0, 1.0]),
        wall("right", [1.0, 0.0], [0.0, 1.0]),
    ];
    // Contacts on every side: no rigid motion opens them all, the mass is held without load.
    accepts(&free_mass(&walls.concat(), ""), &[]);
    // Without the right wall it can move off every contact towards +x.
    rejects_with(
        &free_mass(&walls[..2].concat(), ""),
        &[],
        "static_loads",
        &[
            "the body with DOFs x, y is held only by its contacts `floor`, `ceiling`, `left`",
            "2 rigid-body modes",
        ],
    );
}

#[test]
fn static_load_the_contacts_cannot_carry() {
    let load =
        |dof: &str, value: f64| format!("\n[[static_loads]]\ndof = \"{dof}\"\nvalue = {value:?}\n");
    // Pressed onto the floor: carried.
    accepts(&free_mass("", &load("y", -10.0)), &[]);
    // Pulled off the floor: no compressive normal force balances it.
    rejects_with(
        &free_mass("", &load("y", 10.0)),
        &[],
        "static_loads[0].value",
        &[
            "the static load on the body with DOFs x, y cannot be carried by its contacts `floor`",
            "N ≥ 0",
            "check the sign of the static loads",
        ],
    );
    // Pushed along the floor within the friction limit (4 N ≤ 0.5 · 10 N) and beyond it (6 N).
    accepts(&free_mass("", &(load("y", -10.0) + &load("x", 4.0))), &[]);
    rejects_with(
        &free_mass("", &(load("y", -10.0) + &load("x", 6.0))),
        &[],
        "static_loads[0].value",
        &["cannot be carried by its contacts `floor`", "|T| ≤ μN"],
    );
}

#[test]
fn blade_pair_damper_without_preload_or_pulled_inwards() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/blade-pair/blade-pair-2d.toml"
    );
    let text = std::fs::read_to_string(path).expect("blade-pair scene");
    let text = text.replace(
        "mesh = \"blade-pair-2d.msh\"",
        &format!(
            "mesh = {:?}",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/meshes/blade-pair/blade-pair-2d.msh"
            )
        ),
    );
    let file = SceneFile::new(&text);
    for (value, parts) in [
        (
            "0",
            &[
                "is held only by its contacts `left-1`",
                "3 rigid-body modes",
            ][..],
        ),
        ("-50", &["cannot be carried by its contacts `left-1`"][..]),
    ] {
        let set = format!("static_loads.0.value={value}");
        let err = library_error(&file, &[set.as_str()]);
        assert_invalid(&err, &file.label(), "static_loads[0].value", parts[0]);
        for part in parts {
            assert!(
                err.to_string().contains(part),
                "`{part}` missing from {err}"
            );
        }
    }
}

#[test]
fn contact_stiffness_far_above_the_structure() {
    // Blamed on `model.stiffness` ("singular even with all contacts stuck") before.
    for (set, field) in [
        ("contacts.0.kt=1e300", "contacts[0].kt"),
        ("contacts.1.kn=1e20", "contacts[1].kn"),
    ] {
        rejects_with(
            paper_wedge_scene(),
            &[set],
            field,
            &[
                "more than 1e12 times the model's stiffness scale",
                "1.3e6 N/m",
                "use at most 1.3e18 N/m",
            ],
        );
    }
    // Stiff but resolvable contacts pass.
    accepts(
        paper_wedge_scene(),
        &["contacts.0.kt=1e15", "contacts.0.kn=1e15"],
    );
}

#[test]
fn end_frequency_above_what_the_model_resolves() {
    // The linear reference failed with "non-finite entries in a linear solve" before.
    for set in ["analysis.freq_end_hz=1e300", "analysis.freq_end_hz=1e9"] {
        rejects_with(
            paper_wedge_scene(),
            &[set],
            "analysis.freq_end_hz",
            &[
                "is above 4.7746e8 Hz, the highest frequency this model resolves",
                "lost in round-off",
            ],
        );
    }
    // The bound divides by the highest harmonic.
    let file = SceneFile::new(paper_wedge_scene());
    let err = library_error(&file, &["harmonics.max=10", "analysis.freq_end_hz=1e8"]);
    assert_invalid(
        &err,
        &file.label(),
        "analysis.freq_end_hz",
        "is above 4.7746e7 Hz",
    );
    accepts(
        paper_wedge_scene(),
        &["harmonics.max=10", "analysis.freq_end_hz=1e7"],
    );
}

#[test]
fn absurd_values_name_their_field() {
    // Each failed at run time before ("relative residual NaN", "inf", or a singular matrix).
    for (set, field) in [
        ("static_loads.0.value=-1e300", "static_loads[0].value"),
        ("harmonic_loads.0.sin=1e300", "harmonic_loads[0].sin"),
        ("contacts.0.gap=-1e300", "contacts[0].gap"),
        ("contacts.1.gap=1e300", "contacts[1].gap"),
        ("model.mass.0.0=1e300", "model.mass[0][0]"),
    ] {
        rejects_with(
            paper_wedge_scene(),
            &[set],
            field,
            &["is out of range", "magnitude ≤ 1e50"],
        );
    }
}

/// The paper scene with `[limits]` and a `[sweep]` of F0 over `values` with `target`.
fn paper_sweep(values: &str, target: &str) -> String {
    paper_plus(&format!(
        "[limits]\n[sweep]\nparameter = \"F0\"\nunit = \"N\"\nvalues = {values}\n\
         targets = [{target}]\n"
    ))
}

#[test]
fn sweep_target_that_does_not_exist() {
    // `check` passed this before, and `run` refused it after writing the linear references.
    rejects_with(
        &paper_sweep(
            "[60.0, 120.0]",
            "{ field = \"static_loads.7.value\", scale = -1.0 }",
        ),
        &[],
        "sweep.targets[0].field",
        &[
            "`static_loads.7.value` cannot be set",
            "index 7 out of range (length 1)",
        ],
    );
}

#[test]
fn sweep_target_that_is_not_a_number() {
    for (target, part) in [
        ("contacts.0.name", "expected a string"),
        ("analysis.frequency", "unknown field `frequency`"),
        ("harmonics.max", "expected usize"),
    ] {
        rejects_invalid(
            &paper_sweep("[60.0]", &format!("{{ field = \"{target}\" }}")),
            "sweep.targets[0].field",
            part,
        );
    }
}

#[test]
fn sweep_point_where_the_scene_is_invalid() {
    // F0 = 0 frees the damper at the second point only.
    rejects_with(
        &paper_sweep(
            "[60.0, 0.0, 120.0]",
            "{ field = \"static_loads.0.value\", scale = -1.0 }",
        ),
        &[],
        "sweep.values[1]",
        &[
            "at the sweep point F0 = 0 N",
            "field `static_loads[0].value`",
            "the body with DOFs xD, yD is held only by its contacts",
        ],
    );
    // A point whose value breaks a range check.
    rejects_invalid(
        &paper_sweep("[0.5, -0.5]", "{ field = \"contacts.1.mu\" }"),
        "sweep.values[1]",
        "field `contacts[1].mu`: friction coefficient must be ≥ 0, got -0.5",
    );
    // With a series, the series value is named too.
    rejects_invalid(
        &paper_plus(
            "[limits]\n[sweep]\nparameter = \"F0\"\nvalues = [60.0, 120.0]\n\
             targets = [{ field = \"static_loads.0.value\", scale = -1.0 }]\n\
             [sweep.series]\nparameter = \"mu\"\nvalues = [0.5, -1.0]\n\
             targets = [{ field = \"contacts.0.mu\" }]\n",
        ),
        "sweep.values[0]",
        "at the sweep point mu = -1 (sweep.series.values[1]), F0 = 60",
    );
}

#[test]
fn sweep_points_of_the_shipped_scenes_are_valid() {
    // The figure scenes sweep F0 from 10 N up, β from 30° to 180° and P from 0 N: every point
    // must pass the checks, as must every shipped scene.
    let mut checked = 0;
    for folder in ["meshes/paper-wedge", "meshes/blade-pair"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
        for entry in std::fs::read_dir(&dir).expect("scene folder") {
            let path = entry.expect("folder entry").path();
            if path.extension().is_some_and(|e| e == "toml") {
                let scene = scene::load(&path, &[]).expect("shipped scene parses");
                if let Err(e) = scene.validate_with_limits(&path.display().to_string()) {
                    panic!("{} refused: {e}", path.display());
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 18, "only {checked} shipped scenes found");
}

#[test]
fn sweep_parameter_unusable_in_file_names() {
    rejects_invalid(
        &paper_plus(
            "[limits]\n[sweep]\nparameter = \"F/0\"\nvalues = [60.0]\n\
             targets = [{ field = \"static_loads.0.value\", scale = -1.0 }]\n",
        ),
        "sweep.parameter",
        "cannot appear in CSV column or file names",
    );
}

// Refusals that say why: pre-loads and interferences that leave the damper
// held by nothing, values out of proportion to the model, FE materials out of physical bounds,
// and a sweep value given twice. Each is refused by `check` and `run` naming the field.

/// The blade-pair FE scene with its mesh path made absolute (it is copied to a temporary
/// folder).
fn blade_pair_text() -> String {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/meshes/blade-pair");
    let text = std::fs::read_to_string(format!("{dir}/blade-pair-2d.toml")).expect("scene");
    text.replace(
        "mesh = \"blade-pair-2d.msh\"",
        &format!("mesh = {:?}", format!("{dir}/blade-pair-2d.msh")),
    )
}

#[test]
fn preload_that_pulls_the_damper_off_its_contacts() {
    // +120 N lifts the damper out of the wedge (−120 N presses it in): with the contacts
    // closed the static balance puts both in tension; opened, nothing holds the damper.
    rejects_with(
        paper_wedge_scene(),
        &["static_loads.0.value=120"],
        "static_loads[0].value",
        &["the static load pulls it off them", "`left`, `right`"],
    );
}

#[test]
fn interference_on_one_side_without_preload_pushes_the_damper_out() {
    // An interference on one face only pushes the damper away from it; nothing presses it back.
    rejects_with(
        paper_wedge_scene(),
        &["static_loads.0.value=0", "contacts.0.gap=-1e-4"],
        "contacts[0].gap",
        &["the interferences (gap < 0) push it off them"],
    );
    // On both faces it clamps the damper: accepted.
    let file = SceneFile::new(paper_wedge_scene());
    scene::load_problem(
        &file.path,
        &strings(&[
            "static_loads.0.value=0",
            "contacts.0.gap=-1e-4",
            "contacts.1.gap=-1e-4",
        ]),
    )
    .expect("a damper clamped by interferences on both faces is held");
}

#[test]
fn open_gaps_that_the_preload_closes_are_accepted() {
    // Gaps of 1 mm on both faces: the pre-load pushes the damper 1 mm down onto them (it slides
    // into the wedge). A stuck-contact static balance would hold it off with its tangential
    // springs; the scene must not be refused.
    let file = SceneFile::new(paper_wedge_scene());
    scene::load_problem(
        &file.path,
        &strings(&["contacts.0.gap=1e-3", "contacts.1.gap=1e-3"]),
    )
    .expect("a damper pressed onto open gaps is held once they close");
}

#[test]
fn extreme_mass_and_gap() {
    rejects_with(
        paper_wedge_scene(),
        &["model.mass.4.4=1e40"],
        "model.mass[4][4]",
        &["times the lightest DOF's mass"],
    );
    for (set, field) in [
        ("contacts.0.gap=1e40", "contacts[0].gap"),
        ("contacts.1.gap=-1e40", "contacts[1].gap"),
    ] {
        rejects_with(
            paper_wedge_scene(),
            &[set],
            field,
            &["times the model's displacement scale"],
        );
    }
}

#[test]
fn fe_material_out_of_physical_bounds() {
    let text = blade_pair_text();
    for (set, field, reason) in [
        (
            "model.materials.0.poisson=0.5",
            "model.materials[0].poisson",
            "must lie in (-1, 0.5)",
        ),
        (
            "model.materials.0.poisson=-1",
            "model.materials[0].poisson",
            "must lie in (-1, 0.5)",
        ),
        (
            "model.materials.0.young=1e40",
            "model.materials[0].young",
            "outside the range of solids",
        ),
        (
            "model.materials.0.young=-2.1e11",
            "model.materials[0].young",
            "outside the range of solids",
        ),
        (
            "model.materials.0.density=1e40",
            "model.materials[0].density",
            "must be 0 (massless) or within",
        ),
        (
            "model.materials.0.density=-7850",
            "model.materials[0].density",
            "must be 0 (massless) or within",
        ),
    ] {
        let file = SceneFile::new(&text);
        let err = library_error(&file, &[set]);
        assert_invalid(&err, &file.label(), field, reason);
        assert_cli_rejects(&file.label(), &[set], &[field, reason]);
    }
}

#[test]
fn sweep_value_given_twice() {
    rejects_with(
        &paper_sweep(
            "[60.0, 90.0, 60.0]",
            "{ field = \"static_loads.0.value\", scale = -1.0 }",
        ),
        &[],
        "sweep.values[2]",
        &["duplicate value 60 (also sweep.values[0])"],
    );
}

#[test]
fn accuracy_threshold_must_be_a_relative_error() {
    for (value, part) in [
        ("0", "must be > 0"),
        ("1.5", "must be ≤ 1"),
        ("nan", "must be a finite number"),
    ] {
        let o = format!("accuracy.threshold={value}");
        rejects_with(
            paper_wedge_scene(),
            &[o.as_str()],
            "accuracy.threshold",
            &[part],
        );
    }
}

#[test]
fn accuracy_beyond_linear_range_takes_solve_or_flag() {
    let file = SceneFile::new(&paper_plus("[accuracy]\nbeyond_linear_range = \"skip\"\n"));
    let err = library_error(&file, &[]);
    let parts = ["unknown variant `skip`", "`auto`, `solve`, `flag`"];
    assert_parse(&err, &file.label(), &parts);
    // The CLI names the line and column of the field in the scene.
    assert_cli_rejects(&file.label(), &[], &parts);
}
