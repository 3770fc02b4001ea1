//! The accuracy study's Craig-Bampton interior-modes variation on a small reduced scene: the
//! generated 2D blade pair with 2 contact pairs per side, 8 interior modes, around its
//! resonance near 918 Hz. The study's rows vary `reduction.modes`, its reference takes the
//! most modes of the list, and the error of the modes rows falls as the modes grow.

use fricbound::study::accuracy::{self, StudyCurve};

use crate::common;
use common::blade_pair::reduced_blade_pair_2d;

#[test]
fn modes_rows_vary_the_interior_modes_and_their_error_falls() {
    let dir = tempfile::tempdir().unwrap();
    let text = reduced_blade_pair_2d(dir.path());
    let label = dir.path().join("blade-pair.toml").display().to_string();

    // The full study's list: a quarter, half, once and twice the scene's modes; the reference
    // and its check take the most.
    let (scene, problem, _) = accuracy::load(&text, &label, &[]).unwrap();
    let (reference, check, settings) = accuracy::settings(&scene, &problem, false);
    let modes: Vec<&str> = settings
        .iter()
        .filter(|s| s.group == "modes")
        .map(|s| s.label.as_str())
        .collect();
    assert_eq!(modes, ["modes = 2", "modes = 4", "modes = 8", "modes = 16"]);
    for r in [&reference, &check] {
        assert!(
            r.overrides.contains(&"reduction.modes=16".to_string()),
            "{r:?}"
        );
    }

    // The quick study at the reference's harmonics and samples (H = 7, 512), so that its
    // modes rows differ from the reference in the interior modes alone (and the tolerance).
    let user: Vec<String> = [
        "analysis.freq_start_hz=890",
        "analysis.freq_end_hz=945",
        "harmonics.max=7",
        "harmonics.samples=512",
        "analysis.max_points=4000",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let (scene, problem, base) = accuracy::load(&text, &label, &user).unwrap();
    let (reference, _, settings) = accuracy::settings(&scene, &problem, true);
    assert!(
        reference.label.ends_with("modes = 8"),
        "{}",
        reference.label
    );
    let rows: Vec<&accuracy::Setting> = settings.iter().filter(|s| s.group == "modes").collect();
    assert_eq!(rows.len(), 2);
    let curve = StudyCurve::frf();
    let mut jobs = vec![(&curve, &reference)];
    jobs.extend(rows.iter().map(|s| (&curve, *s)));
    let results = accuracy::run_settings(&text, &label, &base, &jobs, |_, _| {});
    // Every setting covers the range and follows every branch: the reference and the
    // modes = 8 row follow the resonance near 918 Hz over its many small folds (1182 points,
    // more than the scene's 1000, hence `max_points` above); while no progress meant no new
    // highest frequency they gave that branch up before its peak, at 918.28 Hz.
    for r in &results {
        let label = &r.setting.label;
        println!("{label}: {} points, {}", r.points, r.status);
        assert_eq!(r.status, "complete", "{label}");
        assert!(!r.peaks.is_empty(), "{label}: no peak");
    }
    // The rows solve models of different sizes: 4 more interior modes, 15 coefficient blocks.
    assert_eq!(results[2].unknowns - results[1].unknowns, 4 * 15);
    let errors: Vec<accuracy::SettingErrors> = results[1..]
        .iter()
        .map(|r| accuracy::errors(r, &results[0]))
        .collect();
    let (half, full) = (&errors[0], &errors[1]);
    println!("modes = 4: {half:?}\nmodes = 8: {full:?}");
    // Half the modes: a stiffer model, its peak shifted and its curve off by far more than
    // the scene's own modes (which differ from the reference by the tolerance alone).
    assert!(half.max_peak_frequency() > 1e-4, "{half:?}");
    assert!(half.curve_l2 > 1e-3, "{half:?}");
    assert!(half.curve_l2 > 100.0 * full.curve_l2, "{half:?} {full:?}");
    assert!(
        half.max_peak_amplitude() > 10.0 * full.max_peak_amplitude(),
        "{half:?} {full:?}"
    );
    assert!(half.max_peak_frequency() > 10.0 * full.max_peak_frequency());
}
