//! Validation of what drives the structure: the `[[static_loads]]` summed into one static
//! force vector, the `[harmonics]` table into the harmonic set and AFT sampling, and the
//! `[[harmonic_loads]]`, each on a harmonic of that set.

use crate::model::HarmonicLoad;
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::fe_input::FeStructure;
use crate::scene::schema::{HarmonicLoadSpec, HarmonicsSpec, StaticLoadSpec};

/// Most AFT samples per period a scene may ask for (2²⁰).
pub const MAX_SAMPLES: usize = 1 << 20;

/// The static force (N) on each of the `n` DOFs: the sum of the `[[static_loads]]`; and the
/// DOFs each entry loads (in entry order), so that later checks can name the entry that sets
/// a body's load.
pub(super) fn static_load(
    loads: &[StaticLoadSpec],
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
    n: usize,
) -> Result<(Vec<f64>, Vec<Vec<usize>>), SceneError> {
    let mut static_load = vec![0.0; n];
    let mut entry_dofs = Vec::with_capacity(loads.len());
    for (i, l) in loads.iter().enumerate() {
        let value = ck.finite(&format!("static_loads[{i}].value"), l.value)?;
        let targets = ck.load_targets(
            &format!("static_loads[{i}]"),
            l.dof.as_deref(),
            l.group.as_deref(),
            l.direction.as_deref(),
            dofs,
            fe,
        )?;
        for &(d, w) in &targets {
            static_load[d] += w * value;
        }
        entry_dofs.push(targets.into_iter().map(|(d, _)| d).collect());
    }
    Ok((static_load, entry_dofs))
}

/// The balanced dynamic harmonics (sorted, ≥ 1) of the `[harmonics]` table, after checking
/// that the AFT sampling resolves the highest one and that the march may run long enough.
pub(super) fn harmonic_set(spec: &HarmonicsSpec, ck: &Checker) -> Result<Vec<usize>, SceneError> {
    let h_max = match (&spec.max, &spec.list) {
        (Some(h), None) => {
            if *h == 0 {
                return Err(ck.err(
                    "harmonics.max",
                    "must be ≥ 1 (the 0th harmonic alone has no dynamics)",
                ));
            }
            *h
        }
        (None, Some(list)) => match list.iter().copied().max() {
            Some(h) if h > 0 => h,
            _ => return Err(ck.err("harmonics.list", "must hold at least one harmonic ≥ 1")),
        },
        _ => {
            return Err(ck.err(
                "harmonics",
                "give exactly one of `max` (harmonics 1..H) or `list`",
            ))
        }
    };
    // The sampling check comes before the set is built, so that an absurd H is an error
    // rather than an allocation of H entries.
    if spec.samples <= h_max.saturating_mul(2) || spec.samples < 8 {
        return Err(ck.err(
            "harmonics.samples",
            format!(
                "must be ≥ 8 and > 2·H = {} to resolve harmonic {h_max}, got {}",
                h_max.saturating_mul(2),
                spec.samples
            ),
        ));
    }
    if spec.samples > MAX_SAMPLES {
        return Err(ck.err(
            "harmonics.samples",
            format!("must be ≤ {MAX_SAMPLES}, got {}", spec.samples),
        ));
    }
    if spec.max_periods < 2 {
        return Err(ck.err("harmonics.max_periods", "must be ≥ 2"));
    }
    let harmonics: Vec<usize> = match &spec.list {
        Some(list) => {
            let mut l: Vec<usize> = list.iter().copied().filter(|&h| h > 0).collect();
            l.sort_unstable();
            l.dedup();
            l
        }
        None => (1..=h_max).collect(),
    };
    Ok(harmonics)
}

/// The `[[harmonic_loads]]` (N), each on a harmonic of `harmonics`; at least one must be
/// non-zero.
pub(super) fn harmonic_loads(
    loads: &[HarmonicLoadSpec],
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
    harmonics: &[usize],
) -> Result<Vec<HarmonicLoad>, SceneError> {
    let mut harmonic_loads = Vec::new();
    for (i, l) in loads.iter().enumerate() {
        let targets = ck.load_targets(
            &format!("harmonic_loads[{i}]"),
            l.dof.as_deref(),
            l.group.as_deref(),
            l.direction.as_deref(),
            dofs,
            fe,
        )?;
        if l.harmonic == 0 {
            return Err(ck.err(
                format!("harmonic_loads[{i}].harmonic"),
                "must be ≥ 1 (static forces go in [[static_loads]])",
            ));
        }
        if !harmonics.contains(&l.harmonic) {
            return Err(ck.err(
                format!("harmonic_loads[{i}].harmonic"),
                format!(
                    "harmonic {} is not in the harmonic set {harmonics:?}",
                    l.harmonic
                ),
            ));
        }
        let cos = ck.finite(&format!("harmonic_loads[{i}].cos"), l.cos)?;
        let sin = ck.finite(&format!("harmonic_loads[{i}].sin"), l.sin)?;
        for (dof, w) in targets {
            harmonic_loads.push(HarmonicLoad {
                dof,
                harmonic: l.harmonic,
                cos: w * cos,
                sin: w * sin,
            });
        }
    }
    if harmonic_loads.iter().all(|l| l.cos == 0.0 && l.sin == 0.0) {
        return Err(ck.err(
            "harmonic_loads",
            "no non-zero harmonic load: a forced response needs an excitation",
        ));
    }
    Ok(harmonic_loads)
}
