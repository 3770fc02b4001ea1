//! What the elimination per harmonic keeps: the glued structure Ã_zz factored, W and the Schur
//! complement S_h of each harmonic, cached for the ω of the last factorisation.

use std::sync::Arc;

use faer::{c64, Mat};

use crate::numerics::linalg::PackedLu;

/// The per-harmonic elimination (LU of Ã_zz, W = Ã_zz⁻¹ Ã_zq and S_h) depends on ω alone, not
/// on the contact blocks: a factorisation at the ω of the previous one (every Newton iteration
/// of a fixed-frequency solve: limit-curve grids, refined peaks, the envelope) reuses it: on
/// the 3D blade pair a factorisation then takes 6.3 ms of CPU instead of 15 ms (benches/README.md,
/// "Where a 3D Newton iteration spends its time"). A continuation step changes ω at every
/// iteration and gains nothing. Holds the last ω's elimination (ω as bits: the same ω
/// exactly) and is shared by every factorisation of the coordinates, whatever thread makes it.
#[derive(Default)]
pub(super) struct EliminationCache(
    pub(super) std::sync::Mutex<Option<(u64, Arc<Vec<EliminatedHarmonic>>)>>,
);

impl std::fmt::Debug for EliminationCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("EliminationCache")
    }
}

/// One harmonic's elimination of the z coordinates: W = Ã_zz⁻¹ Ã_zq, Ã_qz and the Schur
/// complement S_h, real for a single block, complex (on x_cos − i x_sin) for a cosine/sine
/// pair, where it costs half the real 2n form.
pub(super) enum Elimination {
    /// One block (h = 0).
    Real {
        lu_zz: Option<PackedLu<f64>>,
        w: Mat<f64>,
        a_qz: Mat<f64>,
        schur: Mat<f64>,
    },
    /// Cosine and sine blocks.
    Complex {
        lu_zz: Option<PackedLu<c64>>,
        w: Mat<c64>,
        a_qz: Mat<c64>,
        schur: Mat<c64>,
    },
}

/// The elimination of one harmonic and its unknown blocks (one, or cosine and sine).
pub(super) struct EliminatedHarmonic {
    pub(super) blocks: Vec<usize>,
    pub(super) elimination: Elimination,
}

impl EliminatedHarmonic {
    /// Writes S_h into the reduced Newton matrix `s` (real form: S = Sr + i Si acts on the
    /// cosine/sine blocks as [[Sr, Si], [−Si, Sr]]).
    pub(super) fn add_schur_complement(&self, s: &mut Mat<f64>, n_q: usize) {
        match &self.elimination {
            Elimination::Real { schur, .. } => {
                let jb = self.blocks[0] * n_q;
                for k in 0..n_q {
                    for i in 0..n_q {
                        s[(jb + i, jb + k)] += schur[(i, k)];
                    }
                }
            }
            Elimination::Complex { schur, .. } => {
                let (jc, js) = (self.blocks[0] * n_q, self.blocks[1] * n_q);
                for k in 0..n_q {
                    for i in 0..n_q {
                        let v = schur[(i, k)];
                        s[(jc + i, jc + k)] += v.re;
                        s[(jc + i, js + k)] += v.im;
                        s[(js + i, jc + k)] -= v.im;
                        s[(js + i, js + k)] += v.re;
                    }
                }
            }
        }
    }
}

/// The z part of a right-hand side, kept between the two passes of a solve.
pub(super) enum ZPart {
    Real(Option<Mat<f64>>),
    Complex(Option<Mat<c64>>),
}
