//! Overrides (`--set`) that name no field, index past a list, give no value or make the
//! scene invalid are refused naming the assignment; valid ones are applied, remove a field or
//! create an omitted table.

use super::*;

#[test]
fn override_unknown_path() {
    let file = SceneFile::new(paper_wedge_scene());
    let label = file.label();
    for (assignment, reason) in [
        ("analysis.nothing.step=1", "unknown field `nothing`"),
        ("harmonics.maxx=3", "unknown field `maxx`"),
        ("contacts.0.mus=0.3", "unknown field `mus`"),
        ("harmonics.max=abc", "invalid type"),
        ("analysis.nothing=", "no field `nothing` to remove"),
        ("contacts.0.kt=", "missing field `kt`"),
    ] {
        let err = library_error(&file, &[assignment]);
        assert_override(&err, &label, assignment, reason);
        let err = match scene::parse(paper_wedge_scene(), "paper", &strings(&[assignment])) {
            Ok(_) => panic!("`--set {assignment}` was accepted"),
            Err(e) => e,
        };
        assert_override(&err, "paper", assignment, reason);
        assert_cli_rejects(&label, &[assignment], &[assignment, reason]);
    }
}

#[test]
fn override_index_out_of_range() {
    let file = SceneFile::new(paper_wedge_scene());
    let label = file.label();
    for (assignment, reason) in [
        ("contacts.2.mu=0.3", "index 2 out of range (length 2)"),
        ("model.mass.6.0=1.0", "index 6 out of range (length 6)"),
        ("contacts.first.mu=0.3", "`first` is not an array index"),
    ] {
        let err = library_error(&file, &[assignment]);
        assert_override(&err, &label, assignment, reason);
        let err = match scene::parse(paper_wedge_scene(), "paper", &strings(&[assignment])) {
            Ok(_) => panic!("`--set {assignment}` was accepted"),
            Err(e) => e,
        };
        assert_override(&err, "paper", assignment, reason);
        assert_cli_rejects(&label, &[assignment], &[assignment, reason]);
    }
}

#[test]
fn override_without_value() {
    let file = SceneFile::new(paper_wedge_scene());
    let err = library_error(&file, &["harmonics.max"]);
    assert_override(&err, &file.label(), "harmonics.max", "expected FIELD=VALUE");
    assert_cli_rejects(&file.label(), &["harmonics.max"], &["expected FIELD=VALUE"]);
}

#[test]
fn override_makes_the_scene_invalid() {
    let file = SceneFile::new(paper_wedge_scene());
    let label = file.label();
    let err = library_error(&file, &["contacts.0.mu=-1"]);
    assert_invalid(&err, &label, "contacts[0].mu", "must be ≥ 0");
    assert_cli_rejects(
        &label,
        &["contacts.0.mu=-1"],
        &["contacts[0].mu", "must be ≥ 0"],
    );

    let err = library_error(&file, &["harmonics.max=2", "harmonics.samples=4"]);
    assert_invalid(&err, &label, "harmonics.samples", "must be ≥ 8");
}

#[test]
fn overrides_are_applied() {
    let o = strings(&[
        "contacts.0.initial_state=-1",
        "static_loads.0.value=-80",
        "harmonics.max=5",
        "analysis.initial_step=0.5",
    ]);
    let problem = scene::parse(paper_wedge_scene(), "paper", &o)
        .expect("parse")
        .validate("paper")
        .expect("valid");
    assert_eq!(problem.contacts[0].law.initial_state, -1.0);
    assert_eq!(problem.static_load[5], -80.0);
    assert_eq!(problem.harmonics, vec![1, 2, 3, 4, 5]);
    assert_eq!(problem.analysis.continuation.initial_step, 0.5);
}

#[test]
fn override_removes_a_field() {
    let o = strings(&[
        "harmonics.max=",
        "harmonics.list=[1, 3]",
        "harmonics_loads.1=",
    ]);
    let err = match scene::parse(paper_wedge_scene(), "paper", &o) {
        Ok(_) => panic!("`--set harmonics_loads.1=` was accepted"),
        Err(e) => e,
    };
    assert_override(
        &err,
        "paper",
        "harmonics_loads.1=",
        "no field `harmonics_loads`",
    );

    let o = strings(&[
        "harmonics.max=",
        "harmonics.list=[1, 3]",
        "harmonic_loads.1=",
    ]);
    let problem = scene::parse(paper_wedge_scene(), "paper", &o)
        .expect("parse")
        .validate("paper")
        .expect("valid");
    assert_eq!(problem.harmonics, vec![1, 3]);
    assert_eq!(problem.harmonic_loads.len(), 1);

    let err = library_error(&SceneFile::new(paper_wedge_scene()), &["harmonics.max="]);
    match &err {
        SceneError::Invalid { field, reason, .. } => {
            assert_eq!(field, "harmonics");
            assert!(reason.contains("exactly one of `max`"), "{err}");
        }
        other => panic!("expected SceneError::Invalid, got {other:?}"),
    }
}

#[test]
fn override_creates_an_omitted_table() {
    let o = strings(&["effects.liftoff=false", "effects.coupling=uncoupled"]);
    let problem = scene::parse(DOC_EXAMPLE, "example", &o)
        .expect("parse")
        .validate("example")
        .expect("valid");
    assert!(!problem.effects.contact.liftoff);
    assert_eq!(
        problem.effects.coupling,
        fricbound::model::Coupling::Uncoupled
    );

    let err = match scene::parse(DOC_EXAMPLE, "example", &strings(&["effect.liftoff=false"])) {
        Ok(_) => panic!("`--set effect.liftoff=false` was accepted"),
        Err(e) => e,
    };
    assert_override(
        &err,
        "example",
        "effect.liftoff=false",
        "unknown field `effect`",
    );
}
