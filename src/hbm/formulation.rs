//! Which formulation of the harmonic balance a problem is solved in: the scene's choice, or
//! for `auto` a choice from the model's size and storage and from whether its contact points
//! have independent relative coordinates (which the schur formulation needs).

use faer::Mat;

use crate::model::{Formulation, Problem};

/// Largest model (DOFs) the schur formulation accepts: it holds the structural matrices dense.
pub const MAX_DOFS: usize = 10_000;

/// Why a problem has no relative contact coordinates.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RelativeCoordinatesError {
    /// No contact point.
    #[error("the schur formulation needs at least one contact point with a non-zero tangential or normal direction")]
    NoContacts,
    /// The model is too large to hold dense.
    #[error("the schur formulation holds the structural matrices dense; {n} DOFs is above its limit of {MAX_DOFS} (reduce the model, or use the sparse formulation)")]
    TooLarge {
        /// DOFs of the model.
        n: usize,
    },
    /// The contact rows are linearly dependent.
    #[error("the tangential and normal rows of the contact points are linearly dependent (smallest/largest pivot of B Bᵀ {ratio:.3e}, at contact `{contact}`): relative coordinates are not independent unknowns (use the dense, sparse or condensed formulation)")]
    Dependent {
        /// Contact at which the dependence shows.
        contact: String,
        /// Pivot ratio of the Gram matrix.
        ratio: f64,
    },
}

/// One contact row over the DOFs: (DOF, coefficient) entries.
type ContactRow<'a> = &'a [(usize, f64)];

/// Checks that the problem has independent relative contact coordinates: the pivots of the
/// Cholesky factor of B Bᵀ (one row per non-zero contact direction, see
/// `Problem::nonzero_contact_rows`) stay above 1e-12 of the largest. Cheap (n_q² entries at most).
pub fn check_relative_coordinates(problem: &Problem) -> Result<(), RelativeCoordinatesError> {
    let n = problem.model.n_dofs();
    if problem.contacts.is_empty() {
        return Err(RelativeCoordinatesError::NoContacts);
    }
    if n > MAX_DOFS {
        return Err(RelativeCoordinatesError::TooLarge { n });
    }
    // The non-zero rows, each with the contact it belongs to.
    let active = problem.nonzero_contact_rows();
    let (rows, row_contact): (Vec<ContactRow>, Vec<usize>) = problem
        .contacts
        .iter()
        .zip(&active)
        .enumerate()
        .flat_map(|(p, (c, a))| {
            c.rows()
                .zip(a.iter())
                .filter(|(_, on)| **on)
                .map(move |(row, _)| (row, p))
        })
        .unzip();
    if rows.is_empty() {
        return Err(RelativeCoordinatesError::NoContacts);
    }
    let n_q = rows.len();
    // Per DOF, the rows touching it with their coefficient (duplicates summed): the Gram
    // products come from these sparse columns.
    let mut touching: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    for (r, row) in rows.iter().enumerate() {
        for &(d, a) in row.iter() {
            match touching[d].last_mut() {
                Some(last) if last.0 == r => last.1 += a,
                _ => touching[d].push((r, a)),
            }
        }
    }
    let mut gram = Mat::<f64>::zeros(n_q, n_q);
    for column in &touching {
        for &(i, ai) in column {
            for &(j, aj) in column {
                gram[(i, j)] += ai * aj;
            }
        }
    }
    // Unpivoted Cholesky by hand: the pivot where it fails names the contact.
    let max_diag = (0..n_q).map(|i| gram[(i, i)]).fold(0.0_f64, f64::max);
    for k in 0..n_q {
        let pivot = gram[(k, k)];
        let ratio = pivot / max_diag.max(f64::MIN_POSITIVE);
        if ratio.is_nan() || ratio <= 1e-12 {
            return Err(RelativeCoordinatesError::Dependent {
                contact: problem.contacts[row_contact[k]].name.clone(),
                ratio,
            });
        }
        let root = pivot.sqrt();
        for i in k..n_q {
            gram[(i, k)] /= root;
        }
        for j in k + 1..n_q {
            let gjk = gram[(j, k)];
            if gjk == 0.0 {
                continue;
            }
            for i in j..n_q {
                gram[(i, j)] -= gram[(i, k)] * gjk;
            }
        }
    }
    Ok(())
}

/// How much faster (by the cost estimate) another formulation must be for `auto` to leave the
/// dense one on a dense model: the estimate is rough (README, `fricbound check`), and within
/// this margin the dense LU, the simplest and most robust, is kept.
pub const AUTO_MARGIN: f64 = 1.5;

/// Relative contact coordinates from which `auto` considers schur-lowrank. Its structure pays
/// with many contact points: with few, its per-harmonic blocks are tiny and the flop counts of
/// the cost model (which leave out the work per block) say nothing of which schur formulation
/// is faster, so a problem with few contacts and many harmonics (the paper case at H = 31 or 63,
/// in the error estimate's extended sets) stays on schur. The smallest case measured, the
/// reduced blade pair with 25 pairs per side (100 coordinates) at H = 3, took 0.8× schur's time
/// with it (benches/README.md, "Contact count").
pub const LOW_RANK_AUTO_MIN_COORDINATES: usize = 100;

/// The formulation choice belongs to the harmonic-balance layer, which knows the formulations'
/// limits; it is a method of [`Problem`] so that every caller asks the problem the same way.
impl Problem {
    /// The formulation actually used: the scene's choice, or for `auto` what
    /// [`Self::auto_formulation`] picks.
    pub fn formulation(&self) -> Formulation {
        match self.analysis.formulation {
            Formulation::Auto => self.auto_formulation().0,
            f => f,
        }
    }

    /// What `auto` picks, and why. Sparse models: the sparse formulation. Dense models: the
    /// formulation with the lowest estimated time per continuation point
    /// ([`crate::hbm::cost::estimate_for`]) among dense, sparse, condensed (when the contact
    /// DOFs are at most half of the DOFs), schur and schur-lowrank (when the contact points have
    /// independent relative coordinates, [`check_relative_coordinates`]); dense unless another is estimated
    /// at least [`AUTO_MARGIN`] times faster. On a chain of 40 masses with 10 Jenkins elements
    /// to ground at H = 5 (440 unknowns) this is sparse: the same FRF took 5.5 s against 17 s
    /// condensed and 62 s dense (measured on the loaded 2-core machine).
    pub fn auto_formulation(&self) -> (Formulation, String) {
        use crate::hbm::cost::{estimate_for, formulation_name};
        if self.model.stiffness.is_sparse() {
            return (
                Formulation::Sparse,
                "the model's matrices are sparse".to_string(),
            );
        }
        let mut candidates = vec![Formulation::Dense, Formulation::Sparse];
        if 2 * self.contact_dofs().len() <= self.model.n_dofs() {
            candidates.push(Formulation::Condensed);
        }
        if check_relative_coordinates(self).is_ok() {
            candidates.push(Formulation::Schur);
            if self.relative_coordinate_count() >= LOW_RANK_AUTO_MIN_COORDINATES {
                candidates.push(Formulation::SchurLowRank);
            }
        }
        let times: Vec<(Formulation, f64)> = candidates
            .iter()
            .map(|&f| (f, estimate_for(self, f).seconds_per_point()))
            .collect();
        let dense = times[0].1;
        // The choice among the formulations with a dense reduced LU, then schur-lowrank in its
        // place only where it is estimated AUTO_MARGIN× faster than that choice and than schur
        // (the dense reduced LU is the simpler, and exact whatever the contacts do; on small
        // problems the estimates of both are dominated by what the cost model leaves out).
        let (best, best_time) = times
            .iter()
            .copied()
            .filter(|t| t.0 != Formulation::SchurLowRank)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((Formulation::Dense, dense));
        let (chosen, chosen_time) = if best_time * AUTO_MARGIN < dense {
            (best, best_time)
        } else {
            (Formulation::Dense, dense)
        };
        let time_of = |f: Formulation| times.iter().find(|t| t.0 == f).map(|t| t.1);
        let chosen = match (
            time_of(Formulation::SchurLowRank),
            time_of(Formulation::Schur),
        ) {
            (Some(t), Some(schur)) if t * AUTO_MARGIN < chosen_time.min(schur) => {
                Formulation::SchurLowRank
            }
            _ => chosen,
        };
        let listed: Vec<String> = times
            .iter()
            .map(|(f, t)| format!("{} {:.3} ms", formulation_name(*f), 1e3 * t))
            .collect();
        let reason = format!(
            "estimated time per point: {}; dense unless another is estimated {AUTO_MARGIN}× faster, \
             schur-lowrank only where estimated {AUTO_MARGIN}× faster than that and than schur",
            listed.join(", ")
        );
        (chosen, reason)
    }
}
