//! Shared helpers of the tests that run the `fricbound` binary (`tests/it/cli_run.rs`,
//! `tests/it/outputs.rs`): running it, naming the paper scenes, reading what it wrote.
// Not every test file uses every helper.
#![allow(dead_code)]

pub mod doc_links;
pub mod rust_source;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the binary with `args` in the test's working folder.
pub fn fricbound(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .args(args)
        .output()
        .expect("fricbound runs")
}

/// Runs the binary in `cwd` (for default output folders, which are relative).
pub fn fricbound_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fricbound"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("fricbound runs")
}

/// Path of the paper scene `name` in `meshes/paper-wedge`.
pub fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("meshes/paper-wedge")
        .join(name)
        .display()
        .to_string()
}

/// Process output as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A JSON result file, parsed.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// File names in `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A CSV result file as its header line and rows of cells.
pub fn csv(path: &Path) -> (String, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default().to_string();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

/// Runs `fricbound run SCENE --quiet --out OUT` with each override as `--set`.
pub fn run_scene(scene: &str, out: &Path, overrides: &[&str]) -> Output {
    let out = out.to_str().expect("a UTF-8 output path");
    let mut args = vec!["run", scene, "--quiet", "--out", out];
    for o in overrides {
        args.extend(["--set", o]);
    }
    fricbound(&args)
}

/// The first piece of a VTU file written by the binary or the library, with its data loaded.
pub fn vtu_piece(path: &Path) -> vtkio::model::UnstructuredGridPiece {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        panic!("{}: not an unstructured grid", path.display());
    };
    pieces
        .into_iter()
        .next()
        .expect("one piece")
        .into_loaded_piece_data(None)
        .unwrap()
}

/// The point data arrays of a VTU piece by name, as f64 (vectors flattened per node).
pub fn vtu_point_arrays(
    piece: &vtkio::model::UnstructuredGridPiece,
) -> std::collections::BTreeMap<String, Vec<f64>> {
    piece
        .data
        .point
        .iter()
        .filter_map(|attribute| match attribute {
            vtkio::model::Attribute::DataArray(array) => {
                Some((array.name.clone(), array.data.clone().cast_into().unwrap()))
            }
            _ => None,
        })
        .collect()
}
