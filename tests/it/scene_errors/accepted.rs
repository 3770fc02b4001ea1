//! Scenes that must be accepted: the paper scene, the shipped scene file and the minimal
//! example of the scene reference, verbatim.

use super::*;

#[test]
fn check_accepts_the_paper_scene() {
    let file = SceneFile::new(paper_wedge_scene());
    let out = fricbound(&["check", &file.label()]);
    assert_eq!(out.code, Some(0), "stderr:\n{}", out.stderr);
    assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
    assert!(
        out.stdout
            .contains("DOFs         6: x1, y1, x2, y2, xD, yD"),
        "{}",
        out.stdout
    );
    assert!(
        out.stdout
            .contains("harmonics    [0, 1] (3 blocks), 256 samples"),
        "{}",
        out.stdout
    );
}

#[test]
fn check_accepts_the_shipped_scene_file() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/meshes/paper-wedge/full-range.toml"
    );
    let out = fricbound(&["check", path]);
    assert_eq!(out.code, Some(0), "stderr:\n{}", out.stderr);
    assert!(out.stdout.contains("DOFs         6"), "{}", out.stdout);
    assert!(out.stdout.contains("harmonics    [0, 1]"), "{}", out.stdout);
}

#[test]
fn doc_example_is_valid() {
    let problem = scene::parse(DOC_EXAMPLE, "example", &[])
        .expect("parse")
        .validate("example")
        .expect("valid");
    assert_eq!(problem.model.n_dofs(), 1);
    assert_eq!(problem.harmonics, vec![1, 2, 3]);
    let c = &problem.contacts[0];
    assert_eq!(c.tangential, vec![(0, 1.0)]);
    assert!(c.normal.is_empty());
    assert_eq!(c.gap, -1.0e-4);

    let file = SceneFile::new(DOC_EXAMPLE);
    let out = fricbound(&["check", &file.label()]);
    assert_eq!(out.code, Some(0), "stderr:\n{}", out.stderr);
    assert!(out.stdout.contains("DOFs         1: x"), "{}", out.stdout);
    assert!(
        out.stdout.contains("harmonics    [0, 1, 2, 3]"),
        "{}",
        out.stdout
    );
}

#[test]
fn doc_example_matches_the_docs() {
    let docs = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/src/scene.md");
    let text = std::fs::read_to_string(docs).expect("docs/src/scene.md");
    assert!(
        text.contains(DOC_EXAMPLE),
        "the minimal example in docs/src/scene.md differs from DOC_EXAMPLE"
    );
}
