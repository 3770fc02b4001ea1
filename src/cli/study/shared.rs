//! What both studies share: their [`StudyReport`], reading the scene, the output folder and
//! the error of a file that cannot be written.

use std::path::PathBuf;

use crate::cli::context::CommandError;
use crate::scene::SceneError;

/// What a study produced: the summary text and, when some setting failed or did not cover the
/// range, why (exit code 3).
#[derive(Debug, Clone)]
pub struct StudyReport {
    /// Printable summary.
    pub summary: String,
    /// Failed or incomplete settings, None when all are complete.
    pub incomplete: Option<String>,
}

/// A file of the study that could not be written.
pub(super) fn io_error(path: &std::path::Path, source: std::io::Error) -> CommandError {
    CommandError::Write(crate::report::files::WriteError {
        path: path.display().to_string(),
        source,
    })
}

/// The scene file's label (its path) and text.
pub(super) fn read_scene(scene_path: &std::path::Path) -> Result<(String, String), CommandError> {
    let label = scene_path.display().to_string();
    let text = std::fs::read_to_string(scene_path).map_err(|source| SceneError::Io {
        file: label.clone(),
        source,
    })?;
    Ok((label, text))
}

/// The study's output folder, created (`out` or `out/<scene stem>-<study>`), and the stem.
pub(super) fn study_dir(
    scene_path: &std::path::Path,
    out: Option<PathBuf>,
    study: &str,
) -> Result<(PathBuf, String), CommandError> {
    let stem = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(format!("{stem}-{study}")));
    std::fs::create_dir_all(&dir).map_err(|source| CommandError::OutputDir {
        path: dir.display().to_string(),
        source,
    })?;
    Ok((dir, stem))
}
