//! Test support shared by the figures' tests: a synthetic resonance and the check that a
//! figure was written as a valid PNG and SVG.

use std::path::Path;

use super::backend::{figure_files, PlotError};

/// Amplitude of a damped single-DOF resonance at `f` (natural frequency `f0`, damping ratio
/// `zeta`, static amplitude `a0`).
pub(super) fn resonance(f: f64, f0: f64, zeta: f64, a0: f64) -> f64 {
    let r = f / f0;
    a0 / ((1.0 - r * r).powi(2) + (2.0 * zeta * r).powi(2)).sqrt()
}

/// Checks that `png` is a PNG file and `svg` an SVG file, neither empty.
pub(super) fn check_files(png: &Path, svg: &Path) {
    let png_bytes = std::fs::read(png).unwrap();
    assert!(!png_bytes.is_empty());
    assert!(png_bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]));
    let svg_text = std::fs::read_to_string(svg).unwrap();
    assert!(!svg_text.is_empty());
    assert!(svg_text.contains("<svg"));
}

/// Draws figure `stem` into `dir` with `plot` (given the PNG and SVG paths), checks both files
/// with [`check_files`] and returns the SVG text.
pub(super) fn drawn(
    dir: &Path,
    stem: &str,
    plot: impl FnOnce(&Path, &Path) -> Result<(), PlotError>,
) -> String {
    let (png, svg) = figure_files(dir, stem);
    plot(&png, &svg).unwrap();
    check_files(&png, &svg);
    std::fs::read_to_string(&svg).unwrap()
}
