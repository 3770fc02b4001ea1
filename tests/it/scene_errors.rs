//! Bad scene files are rejected at the door: the library returns the right [`SceneError`]
//! naming the file, the field and the reason, and `fricbound check` exits non-zero with an
//! `error:` line on stderr, without panicking. Each bad scene is the paper scene with one
//! thing changed.

use std::path::{Path, PathBuf};
use std::process::Command;

use fricbound::scene::paper_wedge_scene;
use fricbound::scene::{self, SceneError};
use tempfile::TempDir;

/// A scene file written into its own temporary folder.
struct SceneFile {
    _dir: TempDir,
    path: PathBuf,
}

impl SceneFile {
    fn new(text: &str) -> Self {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).expect("write scene");
        Self { _dir: dir, path }
    }

    fn label(&self) -> String {
        self.path.display().to_string()
    }
}

/// The paper scene with the first occurrence of `from` replaced by `to`.
fn paper_with(from: &str, to: &str) -> String {
    let text = paper_wedge_scene();
    assert!(
        text.contains(from),
        "the paper scene no longer contains {from:?}"
    );
    text.replacen(from, to, 1)
}

/// The paper scene without the text from `start` (inclusive) to `end` (exclusive).
fn paper_without(start: &str, end: &str) -> String {
    let text = paper_wedge_scene();
    let a = text.find(start).expect("start marker");
    let b = a + text[a..].find(end).expect("end marker");
    format!("{}{}", &text[..a], &text[b..])
}

fn strings(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| s.to_string()).collect()
}

/// The library's verdict on a scene file, which must be an error.
fn library_error(file: &SceneFile, overrides: &[&str]) -> SceneError {
    match scene::load_problem(&file.path, &strings(overrides)) {
        Ok(_) => panic!("the scene was accepted:\n{}", read(&file.path)),
        Err(e) => e,
    }
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_default()
}

/// Checks an `Invalid` error: file, exact field, and a fragment of the reason, all also in the
/// displayed message.
fn assert_invalid(err: &SceneError, file: &str, field: &str, reason_part: &str) {
    match err {
        SceneError::Invalid {
            file: f,
            field: fd,
            reason,
        } => {
            assert_eq!(f, file, "{err}");
            assert_eq!(fd, field, "{err}");
            assert!(reason.contains(reason_part), "reason of {err}");
        }
        other => panic!("expected SceneError::Invalid for `{field}`, got {other:?}"),
    }
    let text = err.to_string();
    for part in [file, field, reason_part] {
        assert!(text.contains(part), "`{part}` missing from: {text}");
    }
}

/// Checks a `Parse` error: file and fragments of the message, all also in the displayed
/// message.
fn assert_parse(err: &SceneError, file: &str, parts: &[&str]) {
    match err {
        SceneError::Parse { file: f, message } => {
            assert_eq!(f, file, "{err}");
            for part in parts {
                assert!(message.contains(part), "`{part}` missing from: {message}");
            }
        }
        other => panic!("expected SceneError::Parse, got {other:?}"),
    }
    assert!(err.to_string().contains(file), "{err}");
}

/// Checks an `Override` error: file, the assignment as given, and a fragment of the reason.
fn assert_override(err: &SceneError, file: &str, assignment: &str, reason_part: &str) {
    match err {
        SceneError::Override {
            file: f,
            assignment: a,
            reason,
        } => {
            assert_eq!(f, file, "{err}");
            assert_eq!(a, assignment, "{err}");
            assert!(reason.contains(reason_part), "reason of {err}");
        }
        other => panic!("expected SceneError::Override for `{assignment}`, got {other:?}"),
    }
    let text = err.to_string();
    for part in [file, assignment, reason_part] {
        assert!(text.contains(part), "`{part}` missing from: {text}");
    }
}

struct CliOutput {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

fn fricbound(args: &[&str]) -> CliOutput {
    let out = Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .args(args)
        .output()
        .expect("run fricbound");
    CliOutput {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `fricbound check FILE [--set ...]` must fail cleanly with an `error:` line that names the
/// file and contains every one of `parts` (the field, the assignment, the reason).
fn assert_cli_rejects(file: &str, overrides: &[&str], parts: &[&str]) {
    let mut args = vec!["check", file];
    for o in overrides {
        args.extend(["--set", o]);
    }
    let out = fricbound(&args);
    assert!(
        !out.stderr.contains("panicked"),
        "fricbound panicked:\n{}",
        out.stderr
    );
    match out.code {
        Some(0) => panic!("fricbound check accepted the scene:\n{}", out.stdout),
        Some(_) => {}
        None => panic!("fricbound was killed by a signal:\n{}", out.stderr),
    }
    let line = out
        .stderr
        .lines()
        .find(|l| l.starts_with("error:"))
        .unwrap_or_else(|| panic!("no `error:` line on stderr:\n{}", out.stderr));
    assert!(line.contains(file), "file missing from: {line}");
    for part in parts {
        assert!(line.contains(part), "`{part}` missing from: {line}");
    }
}

/// One bad scene rejected by validation: library `Invalid` with the field and reason, CLI
/// error line with the same.
fn rejects_invalid(text: &str, field: &str, reason_part: &str) {
    let file = SceneFile::new(text);
    let err = library_error(&file, &[]);
    assert_invalid(&err, &file.label(), field, reason_part);
    assert_cli_rejects(&file.label(), &[], &[field, reason_part]);
}

#[test]
fn malformed_toml() {
    let text = paper_with("[model]", "[model");
    let line = 1 + text[..text.find("[model").expect("edited")]
        .matches('\n')
        .count();
    let at = format!("line {line}, column 7");
    let file = SceneFile::new(&text);
    let err = library_error(&file, &[]);
    assert_parse(&err, &file.label(), &[&at, "unclosed table", "| [model"]);
    assert_cli_rejects(&file.label(), &[], &[&at, "unclosed table"]);
}

#[test]
fn unknown_field() {
    let text = paper_with("mu = 0.5", "mus = 0.5");
    let line = 1 + text[..text.find("mus = 0.5").expect("edited")]
        .matches('\n')
        .count();
    let at = format!("line {line}, column 1");
    let file = SceneFile::new(&text);
    let err = library_error(&file, &[]);
    assert_parse(
        &err,
        &file.label(),
        &[&at, "unknown field `mus`", "| mus = 0.5"],
    );
    assert_cli_rejects(&file.label(), &[], &[&at, "unknown field `mus`"]);
}

#[test]
fn missing_required_field() {
    let file = SceneFile::new(&paper_with("kt = 3.0e5\n", ""));
    let err = library_error(&file, &[]);
    assert_parse(&err, &file.label(), &["missing field `kt`"]);
    assert_cli_rejects(&file.label(), &[], &["missing field `kt`"]);
}

#[test]
fn wrong_type() {
    let file = SceneFile::new(&paper_with("samples = 256", "samples = \"many\""));
    let err = library_error(&file, &[]);
    assert_parse(&err, &file.label(), &["samples", "invalid type"]);
    assert_cli_rejects(&file.label(), &[], &["invalid type"]);
}

/// Two tangential stiffnesses where the law takes one (an anisotropic kₜ along t₁, t₂): refused
/// at parsing with the line, the field and why, in the file and through `--set`, on contacts
/// and on patches.
#[test]
fn two_tangential_stiffnesses_are_refused() {
    let text = paper_with("kt = 3.0e5", "kt = [3.0e5, 1.0e5]");
    let line = 1 + text[..text.find("kt = [3.0e5").expect("edited")]
        .matches('\n')
        .count();
    let at = format!("line {line}, column 6");
    let file = SceneFile::new(&text);
    let err = library_error(&file, &[]);
    let why = "`kt` takes one number (N/m), got an array of 2";
    assert_parse(
        &err,
        &file.label(),
        &[&at, why, "isotropic", "| kt = [3.0e5, 1.0e5]"],
    );
    assert_cli_rejects(&file.label(), &[], &[&at, why]);

    let file = SceneFile::new(paper_wedge_scene());
    let assignment = "contacts.1.kt=[3.0e5, 1.0e5]";
    let err = library_error(&file, &[assignment]);
    assert_override(&err, &file.label(), assignment, why);

    let blade = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("meshes/blade-pair/blade-pair-3d-limits.toml")
        .display()
        .to_string();
    let assignment = "contact_patches.0.kt=[2.0e7, 1.0e7, 5.0e6]";
    assert_cli_rejects(
        &blade,
        &[assignment],
        &[assignment, "`kt` takes one number (N/m), got an array of 3"],
    );
}

#[test]
fn missing_file() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("no-such-scene.toml");
    let label = path.display().to_string();
    let err = match scene::load_problem(&path, &[]) {
        Ok(_) => panic!("a missing file was accepted"),
        Err(e) => e,
    };
    match &err {
        SceneError::Io { file, source } => {
            assert_eq!(file, &label);
            assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("expected SceneError::Io, got {other:?}"),
    }
    assert!(err.to_string().contains(&label), "{err}");
    assert!(err.to_string().contains("cannot read scene"), "{err}");
    assert_cli_rejects(&label, &[], &["cannot read scene"]);
}

#[test]
fn matrix_row_too_short() {
    rejects_invalid(
        &paper_with(
            "  [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],\n",
            "  [1.0, 0.0, 0.0, 0.0, 0.0],\n",
        ),
        "model.mass[0]",
        "has 5 entries but the model has 6 DOFs",
    );
}

#[test]
fn matrix_too_few_rows() {
    rejects_invalid(
        &paper_with("  [ 0.0,    0.0,    0.0,    0.0,   -3.0e5,  3.0e5],\n", ""),
        "model.stiffness",
        "has 5 rows but the model has 6 DOFs",
    );
}

#[test]
fn mass_not_symmetric() {
    rejects_invalid(
        &paper_with(
            "  [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],\n",
            "  [1.0, 0.5, 0.0, 0.0, 0.0, 0.0],\n",
        ),
        "model.mass",
        "is not symmetric",
    );
}

#[test]
fn stiffness_not_symmetric() {
    rejects_invalid(
        &paper_with("[ 1.3e6, -3.0e5, -7.0e5,", "[ 1.3e6, -3.1e5, -7.0e5,"),
        "model.stiffness",
        "is not symmetric",
    );
}

#[test]
fn stiffness_indefinite() {
    rejects_invalid(
        &paper_with("[ 1.3e6, -3.0e5, -7.0e5,", "[-1.3e6, -3.0e5, -7.0e5,"),
        "model.stiffness",
        "is indefinite",
    );
}

#[test]
fn mass_indefinite() {
    rejects_invalid(
        &paper_with(
            "[0.0, 0.0, 0.0, 0.0, 0.1, 0.0]",
            "[0.0, 0.0, 0.0, 0.0, -0.1, 0.0]",
        ),
        "model.mass",
        "is indefinite",
    );
}

#[test]
fn nan_in_matrix() {
    rejects_invalid(
        &paper_with(
            "  [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],\n",
            "  [nan, 0.0, 0.0, 0.0, 0.0, 0.0],\n",
        ),
        "model.mass[0][0]",
        "must be a finite number",
    );
}

#[test]
fn infinity_in_matrix() {
    rejects_invalid(
        &paper_with("  [20.0, 0.0, 0.0,", "  [inf, 0.0, 0.0,"),
        "model.damping[0][0]",
        "must be a finite number",
    );
}

#[test]
fn negative_friction_coefficient() {
    rejects_invalid(
        &paper_with("mu = 0.5", "mu = -0.1"),
        "contacts[0].mu",
        "must be ≥ 0",
    );
}

#[test]
fn negative_tangential_stiffness() {
    rejects_invalid(
        &paper_with("kt = 3.0e5", "kt = -3.0e5"),
        "contacts[0].kt",
        "must be > 0",
    );
}

#[test]
fn zero_normal_stiffness() {
    rejects_invalid(
        &paper_with("kn = 3.0e5", "kn = 0.0"),
        "contacts[0].kn",
        "must be > 0",
    );
}

#[test]
fn initial_state_above_one() {
    rejects_invalid(
        &paper_with("initial_state = 0.0", "initial_state = 1.5"),
        "contacts[0].initial_state",
        "must lie in [-1, 1]",
    );
}

#[test]
fn initial_state_below_minus_one() {
    rejects_invalid(
        &paper_with("initial_state = 0.0", "initial_state = -1.01"),
        "contacts[0].initial_state",
        "must lie in [-1, 1]",
    );
}

#[test]
fn frequency_range_reversed() {
    rejects_invalid(
        &paper_with("freq_end_hz = 350.0", "freq_end_hz = 40.0"),
        "analysis.freq_end_hz",
        "the range is reversed or empty",
    );
}

#[test]
fn harmonics_max_zero() {
    rejects_invalid(
        &paper_with("max = 1\n", "max = 0\n"),
        "harmonics.max",
        "must be ≥ 1",
    );
}

#[test]
fn samples_too_few_for_harmonics() {
    rejects_invalid(
        &paper_with("max = 1\nsamples = 256", "max = 5\nsamples = 10"),
        "harmonics.samples",
        "> 2·H = 10",
    );
}

#[test]
fn absurd_harmonic_count_is_an_error_not_an_allocation() {
    rejects_invalid(
        &paper_with("max = 1\n", "max = 1000000000000\n"),
        "harmonics.samples",
        "to resolve harmonic 1000000000000",
    );
}

#[test]
fn contact_names_unknown_dof() {
    rejects_invalid(
        &paper_with("body = [\"x1\", \"y1\"]", "body = [\"x1\", \"z1\"]"),
        "contacts[0].body[1]",
        "unknown DOF `z1`",
    );
}

#[test]
fn contact_body_shares_a_damper_dof() {
    rejects_invalid(
        &paper_with("body = [\"x1\", \"y1\"]", "body = [\"x1\", \"yD\"]"),
        "contacts[0].body[1]",
        "also a DOF of the damper point",
    );
}

#[test]
fn contact_point_lists_a_dof_twice() {
    rejects_invalid(
        &paper_with("damper = [\"xD\", \"yD\"]", "damper = [\"xD\", \"xD\"]"),
        "contacts[0].damper[1]",
        "listed twice",
    );
}

#[test]
fn dof_name_unusable_in_file_names() {
    rejects_invalid(
        &paper_with("\"x2\", \"y2\", \"xD\"", "\"x2\", \"y/2\", \"xD\""),
        "model.dofs[3]",
        "contains '/'",
    );
}

#[test]
fn contact_name_unusable_in_csv() {
    rejects_invalid(
        &paper_with("name = \"left\"", "name = \"left,1\""),
        "contacts[0].name",
        "contains ','",
    );
}

#[test]
fn empty_side_name() {
    rejects_invalid(
        &paper_with("side = \"left\"", "side = \"\""),
        "contacts[0].side",
        "must not be empty",
    );
}

#[test]
fn empty_contact_set() {
    rejects_invalid(
        &paper_without("[[contacts]]", "# Pre-load"),
        "contacts",
        "the contact set is empty",
    );
}

#[test]
fn output_dof_does_not_exist() {
    rejects_invalid(
        &paper_with("dofs = [\"y2\"]", "dofs = [\"y3\"]"),
        "output.dofs[0]",
        "unknown DOF `y3`",
    );
}

#[test]
fn harmonic_load_outside_the_harmonic_set() {
    rejects_invalid(
        &paper_with("harmonic = 1", "harmonic = 2"),
        "harmonic_loads[0].harmonic",
        "harmonic 2 is not in the harmonic set [1]",
    );
}

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

/// The minimal example of `docs/src/scene.md`, verbatim.
const DOC_EXAMPLE: &str = r#"title = "Single-DOF oscillator grounded through one Jenkins contact"

[model]
dofs = ["x"]
mass = [[1.0]]            # kg
stiffness = [[1.0e4]]     # N/m
damping = [[2.0]]         # N·s/m

# The mass slides on the ground: no body DOFs. With tangent = [1] and normal = [0] the
# tangential displacement is u = x and the normal one is v = 0 − gap = 1e-4 m, so the
# normal load is the constant N = kn·v = 10 N and the slip force is μN = 3 N.
[[contacts]]
name = "ground"
damper = ["x"]
tangent = [1.0]
normal = [0.0]
kt = 1.0e5                # N/m
kn = 1.0e5                # N/m
mu = 0.3
gap = -1.0e-4             # m, an interference
initial_state = 0.0

# F(t) = 5 cos(ωt) N.
[[harmonic_loads]]
dof = "x"
harmonic = 1
cos = 5.0

[harmonics]
max = 3
samples = 128

[analysis]
freq_start_hz = 5.0
freq_end_hz = 100.0

[output]
dofs = ["x"]
"#;

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

/// The paper scene with `extra` tables appended (e.g. `[limits]`, `[sweep]`).
fn paper_plus(extra: &str) -> String {
    format!("{}\n{extra}", paper_wedge_scene())
}

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
