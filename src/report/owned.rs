//! The result files a run owns in its output folder, and their removal before a run starts, so
//! that a failed or incomplete run never sits beside an earlier run's results.
//!
//! The list is collected from the writers: [`crate::report::files`] (`frf.csv`,
//! `solution.json`, `coefficients.bin`, the linear references, and an FRF run's `peaks.csv` of
//! refined resonances and anti-resonances), the figures of
//! [`crate::report::plot`] as `fricbound run` names them (`frf_*`, `limits_*`, `hysteresis_*`,
//! `optimal_*`, `resonance_*`, `bands_*`, PNG and SVG), the limit-analysis tables of
//! [`crate::report::limit_files`] (`limits.csv`, `peaks.csv`, `curve_*.csv`,
//! `hysteresis_*.csv`, `limits.json`), the nonlinear modes' of
//! [`crate::report::modes_nl_files`] (`modes_nl.csv`, `modes_nl.json`, `modes_nl_band.csv`,
//! `modes_nl_*` figures and mesh files), the sweep's (`sweep.csv`, `sweep.json`,
//! `variability.csv`), the results on the mesh of [`crate::report::mesh_results`] and
//! [`crate::report::mesh_modes`] (`response_peak.vtu`, `peak_*.vtu`, `modes_stuck.vtu`), and
//! the temporaries of atomic writes (`<owned name>.partial`). A sweep with
//! `output = "limits"` writes a whole limit analysis per value into a sub-folder; a sub-folder
//! holding a `limits.json` is such a folder: its owned files are removed, and the sub-folder
//! too when nothing else is left in it.
//!
//! Nothing else is touched: files of other names stay, and the output folder itself is never
//! removed.

use std::path::{Path, PathBuf};

use crate::report::files::WriteError;

/// Result files of fixed names (`peaks.csv` is written by FRF runs and limit analyses alike).
pub const OWNED_FILES: &[&str] = &[
    "frf.csv",
    "solution.json",
    "coefficients.bin",
    "linear_open.csv",
    "linear_stuck.csv",
    "modes_stuck.vtu",
    "response_peak.vtu",
    "limits.csv",
    "peaks.csv",
    "limits.json",
    "sweep.csv",
    "sweep.json",
    "variability.csv",
    "modes_nl.csv",
    "modes_nl.json",
    "modes_nl_band.csv",
];

/// Result files named `<prefix><anything><suffix>`: figures per output DOF or contact, one
/// table per curve or loop set, one VTU per limit curve's peak.
pub const OWNED_PATTERNS: &[(&str, &[&str])] = &[
    ("frf_", &[".png", ".svg"]),
    ("limits_", &[".png", ".svg"]),
    ("hysteresis_", &[".png", ".svg", ".csv"]),
    ("optimal_", &[".png", ".svg"]),
    ("resonance_", &[".png", ".svg"]),
    ("bands_", &[".png", ".svg"]),
    ("curve_", &[".csv"]),
    ("peak_", &[".vtu"]),
    ("modes_nl_", &[".png", ".svg", ".vtu"]),
];

/// Suffix of the temporary file of an atomic write ([`crate::report::files::write_atomic`]).
const PARTIAL: &str = ".partial";

/// Whether a file named `name` is a result file a run owns (see the module docs).
pub fn is_owned(name: &str) -> bool {
    let name = name.strip_suffix(PARTIAL).unwrap_or(name);
    OWNED_FILES.contains(&name)
        || OWNED_PATTERNS.iter().any(|(prefix, suffixes)| {
            name.len() > prefix.len()
                && name.starts_with(prefix)
                && suffixes
                    .iter()
                    .any(|s| name.len() > prefix.len() + s.len() && name.ends_with(s))
        })
}

/// Removes the result files a run owns from `dir` (and the sweep sub-folders holding a limit
/// analysis, see the module docs); returns what was removed. A missing `dir` is not an error
/// (nothing to remove); the folder itself is kept.
pub fn clear_results(dir: &Path) -> Result<Vec<PathBuf>, WriteError> {
    let mut removed = Vec::new();
    clear_folder(dir, true, &mut removed)?;
    Ok(removed)
}

/// Removes what an earlier study of several runs (`fricbound paper`) left in `dir`: in each of
/// its `sub_folders` (one run each) the result files [`clear_results`] removes, and the
/// sub-folder itself when left empty; in `dir` the study's own `files` (and their partials).
/// Files of other names stay, as for a single run. Returns what was removed.
pub fn clear_study_results(
    dir: &Path,
    sub_folders: &[&str],
    files: &[&str],
) -> Result<Vec<PathBuf>, WriteError> {
    let mut removed = Vec::new();
    for sub in sub_folders {
        let path = dir.join(sub);
        removed.extend(clear_results(&path)?);
        if std::fs::read_dir(&path).is_ok_and(|mut d| d.next().is_none()) {
            std::fs::remove_dir(&path).map_err(|source| WriteError {
                path: path.display().to_string(),
                source,
            })?;
            removed.push(path);
        }
    }
    for name in files {
        for path in [dir.join(name), dir.join(format!("{name}{PARTIAL}"))] {
            match std::fs::remove_file(&path) {
                Ok(()) => removed.push(path),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(source) => {
                    return Err(WriteError {
                        path: path.display().to_string(),
                        source,
                    })
                }
            }
        }
    }
    Ok(removed)
}

/// Removes the owned files of `dir`; with `top`, also looks into its sub-folders that hold a
/// `limits.json` (a sweep value's limit analysis) and removes them when left empty.
fn clear_folder(dir: &Path, top: bool, removed: &mut Vec<PathBuf>) -> Result<(), WriteError> {
    let err = |path: &Path, source| WriteError {
        path: path.display().to_string(),
        source,
    };
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(err(dir, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| err(dir, e))?;
        let path = entry.path();
        let kind = entry.file_type().map_err(|e| err(&path, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if kind.is_file() && is_owned(&name) {
            std::fs::remove_file(&path).map_err(|e| err(&path, e))?;
            removed.push(path);
        } else if top && kind.is_dir() && path.join("limits.json").is_file() {
            clear_folder(&path, false, removed)?;
            // Left empty: the sub-folder was the sweep's alone.
            if std::fs::read_dir(&path).is_ok_and(|mut d| d.next().is_none()) {
                std::fs::remove_dir(&path).map_err(|e| err(&path, e))?;
                removed.push(path);
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owned_names_and_others() {
        for name in [
            "frf.csv",
            "frf.csv.partial",
            "solution.json",
            "frf_y2.png",
            "frf_y2.svg",
            "curve_m+1.csv",
            "hysteresis_m+1_peak.csv",
            "hysteresis_left.png",
            "limits_y2.svg",
            "peak_m-1.vtu",
            "optimal_y2.png",
            "bands_y2_beta_90.svg",
            "sweep.json",
        ] {
            assert!(is_owned(name), "{name}");
        }
        for name in [
            "notes.txt",
            "frf.csv.bak",
            "frf_.png",
            "my_frf.csv",
            "summary.md",
            "scene.toml",
            "curve_m+1.txt",
            "peak.vtu",
        ] {
            assert!(!is_owned(name), "{name}");
        }
    }

    #[test]
    fn clears_owned_files_and_sweep_folders_only() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for f in ["frf.csv", "frf_y2.png", "solution.json", "notes.txt"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        // A sweep value's folder: removed with its files.
        std::fs::create_dir(d.join("F0_60")).unwrap();
        for f in ["limits.json", "curve_m+1.csv", "limits_y2.png"] {
            std::fs::write(d.join("F0_60").join(f), "x").unwrap();
        }
        // A sweep folder with a file of the user's: kept with it.
        std::fs::create_dir(d.join("F0_90")).unwrap();
        for f in ["limits.json", "mine.txt"] {
            std::fs::write(d.join("F0_90").join(f), "x").unwrap();
        }
        // A folder of the user's: untouched, even its owned-looking files.
        std::fs::create_dir(d.join("old")).unwrap();
        std::fs::write(d.join("old").join("frf.csv"), "x").unwrap();

        let removed = clear_results(d).unwrap();
        assert_eq!(removed.len(), 8, "{removed:?}");
        assert!(d.is_dir());
        assert!(d.join("notes.txt").is_file());
        assert!(!d.join("frf.csv").exists() && !d.join("frf_y2.png").exists());
        assert!(!d.join("F0_60").exists());
        assert!(d.join("F0_90").join("mine.txt").is_file());
        assert!(!d.join("F0_90").join("limits.json").exists());
        assert!(d.join("old").join("frf.csv").is_file());
        // A missing folder has nothing to clear.
        assert!(clear_results(&d.join("missing")).unwrap().is_empty());
    }

    /// A study's folder: each run's sub-folder loses its results (and goes when left empty),
    /// the study's own files go, and everything else stays.
    #[test]
    fn a_study_clears_its_runs_and_its_own_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for (path, text) in [
            ("summary.md", "old"),
            ("summary.json.partial", "old"),
            ("notes.txt", "mine"),
            ("fig12/frf.csv", "old"),
            ("fig12/frf_y2.png", "old"),
            ("fig13/limits.json", "old"),
            ("fig13/keep.txt", "mine"),
            ("other/frf.csv", "not the study's"),
        ] {
            std::fs::create_dir_all(d.join(path).parent().unwrap()).unwrap();
            std::fs::write(d.join(path), text).unwrap();
        }
        let removed = clear_study_results(
            d,
            &["fig12", "fig13", "fig19"],
            &["summary.md", "summary.json"],
        )
        .unwrap();
        assert_eq!(removed.len(), 6, "{removed:?}");
        assert!(!d.join("fig12").exists());
        assert!(!d.join("summary.md").exists() && !d.join("summary.json.partial").exists());
        assert!(!d.join("fig13/limits.json").exists());
        for kept in ["notes.txt", "fig13/keep.txt", "other/frf.csv"] {
            assert!(d.join(kept).exists(), "{kept}");
        }
    }
}
