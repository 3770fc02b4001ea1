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

/// The paper scene with `extra` tables appended (e.g. `[limits]`, `[sweep]`).
fn paper_plus(extra: &str) -> String {
    format!("{}\n{extra}", paper_wedge_scene())
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

mod accepted;
mod overrides;
mod physics;
mod tables;
