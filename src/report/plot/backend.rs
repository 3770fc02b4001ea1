//! Writing a figure: every figure is drawn twice by the same code, into a 1200×800 PNG (bitmap
//! backend) and an SVG of the same size, and named `<stem>.png` and `<stem>.svg`.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::style::{font_ready, SIZE};

/// Error of a figure.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Drawing or writing a file failed.
    #[error("{path}: cannot draw figure: {reason}")]
    Draw {
        /// File being written.
        path: String,
        /// What went wrong.
        reason: String,
    },
}

/// A figure that can be drawn on any backend.
pub(super) trait Figure {
    /// Draws the whole figure into `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<(), DB>;
}

/// Draws `figure` into a 1200×800 PNG and an SVG of the same size.
pub(super) fn write_figure<F: Figure>(figure: &F, png: &Path, svg: &Path) -> Result<(), PlotError> {
    let fail = |path: &Path, reason: String| PlotError::Draw {
        path: path.display().to_string(),
        reason,
    };
    if !font_ready() {
        return Err(fail(png, "the embedded font cannot be loaded".to_string()));
    }
    {
        let root = BitMapBackend::new(png, SIZE).into_drawing_area();
        figure
            .draw(&root)
            .and_then(|()| root.present())
            .map_err(|e| fail(png, e.to_string()))?;
    }
    {
        let root = SVGBackend::new(svg, SIZE).into_drawing_area();
        figure
            .draw(&root)
            .and_then(|()| root.present())
            .map_err(|e| fail(svg, e.to_string()))?;
    }
    Ok(())
}

/// The two files of figure `stem` in `dir`: `<stem>.png` and `<stem>.svg`, in the order the
/// `plot_*` functions take them.
pub fn figure_files(dir: &Path, stem: &str) -> (PathBuf, PathBuf) {
    (
        dir.join(format!("{stem}.png")),
        dir.join(format!("{stem}.svg")),
    )
}
