//! What the elimination per harmonic keeps: the glued structure Ã_zz factored, W and the Schur
//! complement S_h of each harmonic, cached for the ω of the last factorisation.

use std::sync::Arc;

use faer::{c64, Mat};

use super::modal::{ModalBasis, ModalHarmonic, ModalSchur};
use crate::numerics::linalg::PackedLu;

/// The per-harmonic elimination (LU of Ã_zz, W = Ã_zz⁻¹ Ã_zq and S_h) depends on ω alone, not
/// on the contact blocks: a factorisation at the ω of the previous one (every Newton iteration
/// of a fixed-frequency solve: limit-curve grids, refined peaks, the envelope) reuses it: on
/// the 3D blade pair a factorisation then takes 6.3 ms of CPU instead of 15 ms (benches/README.md,
/// "Where a 3D Newton iteration spends its time"). A continuation step changes ω at every
/// iteration and gains nothing. Holds the last ω's elimination (ω as bits: the same ω
/// exactly, and whether it was made from the glued modes) and is shared by every factorisation
/// of the coordinates, whatever thread makes it.
#[derive(Default)]
pub(super) struct EliminationCache(pub(super) std::sync::Mutex<Option<CachedElimination>>);

/// The cached elimination: ω (bits), whether from modes, and every harmonic's elimination.
pub(super) type CachedElimination = (u64, bool, Arc<Vec<EliminatedHarmonic>>);

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
    /// From the glued structure's modes ([`super::modal`]).
    Modal(ModalHarmonic),
}

/// A harmonic's Schur complement S_h, real or complex.
pub(super) enum SchurRef<'a> {
    Real(&'a Mat<f64>),
    Complex(&'a Mat<c64>),
}

/// The elimination of one harmonic and its unknown blocks (one, or cosine and sine).
pub(super) struct EliminatedHarmonic {
    pub(super) blocks: Vec<usize>,
    pub(super) elimination: Elimination,
}

impl EliminatedHarmonic {
    /// This harmonic's S_h.
    pub(super) fn schur(&self) -> SchurRef<'_> {
        match &self.elimination {
            Elimination::Real { schur, .. } => SchurRef::Real(schur),
            Elimination::Complex { schur, .. } => SchurRef::Complex(schur),
            Elimination::Modal(m) => match &m.schur {
                ModalSchur::Real(schur) => SchurRef::Real(schur),
                ModalSchur::Complex(schur) => SchurRef::Complex(schur),
            },
        }
    }

    /// Writes S_h into the reduced Newton matrix `s` (real form: S = Sr + i Si acts on the
    /// cosine/sine blocks as [[Sr, Si], [−Si, Sr]]).
    pub(super) fn add_schur_complement(&self, s: &mut Mat<f64>, n_q: usize) {
        match self.schur() {
            SchurRef::Real(schur) => {
                let jb = self.blocks[0] * n_q;
                for k in 0..n_q {
                    for i in 0..n_q {
                        s[(jb + i, jb + k)] += schur[(i, k)];
                    }
                }
            }
            SchurRef::Complex(schur) => {
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
    /// Modal coordinates of Ã_zz⁻¹ b_z ([`ModalHarmonic::reduce`]).
    Modal(Mat<c64>),
}

impl EliminatedHarmonic {
    /// The first pass of a solve: writes this harmonic's rows of the reduced right-hand side
    /// b_q − Ã_qz Ã_zz⁻¹ b_z into `r_q` (n_q rows per block) from `by` (Tᵀ b, one column per
    /// block) and returns the z part kept for [`Self::back_substitute`]. `basis` holds the
    /// glued modes when a harmonic was eliminated from them.
    pub(super) fn reduce_rhs(
        &self,
        basis: Option<&ModalBasis>,
        by: &Mat<f64>,
        n_q: usize,
        r_q: &mut Mat<f64>,
    ) -> ZPart {
        let n = by.nrows();
        let (jc, js) = (self.blocks[0], self.blocks.get(1).copied());
        // A harmonic's coefficients on x_cos − i x_sin (real for a single block).
        let packed = |i: usize| c64::new(by[(i, jc)], js.map_or(0.0, |js| -by[(i, js)]));
        let mut write = |rq: &Mat<c64>| {
            for i in 0..n_q {
                r_q[(jc * n_q + i, 0)] = rq[(i, 0)].re;
                if let Some(js) = js {
                    r_q[(js * n_q + i, 0)] = -rq[(i, 0)].im;
                }
            }
        };
        match &self.elimination {
            Elimination::Real { lu_zz, a_qz, .. } => {
                let mut rq = Mat::from_fn(n_q, 1, |i, _| by[(i, jc)]);
                let g = lu_zz.as_ref().map(|lu| {
                    let g = lu.solve(&Mat::from_fn(n - n_q, 1, |i, _| by[(n_q + i, jc)]));
                    rq -= a_qz * &g;
                    g
                });
                write(&Mat::from_fn(n_q, 1, |i, _| c64::new(rq[(i, 0)], 0.0)));
                ZPart::Real(g)
            }
            Elimination::Complex { lu_zz, a_qz, .. } => {
                let mut rq = Mat::from_fn(n_q, 1, |i, _| packed(i));
                let g = lu_zz.as_ref().map(|lu| {
                    let g = lu.solve(&Mat::from_fn(n - n_q, 1, |i, _| packed(n_q + i)));
                    rq -= a_qz * &g;
                    g
                });
                write(&rq);
                ZPart::Complex(g)
            }
            Elimination::Modal(m) => {
                let basis = basis.expect("a modal elimination was made from the basis");
                let b_q = Mat::from_fn(n_q, 1, |i, _| packed(i));
                let b_z = Mat::from_fn(n - n_q, 1, |i, _| packed(n_q + i));
                let (rq, modes) = m.reduce(basis, b_q, &b_z);
                write(&rq);
                ZPart::Modal(modes)
            }
        }
    }

    /// The second pass of a solve: from the reduced solution `y_q` (n_q rows per block) and the
    /// kept z part, writes this harmonic's columns of y (y coordinates, one column per block).
    pub(super) fn back_substitute(
        &self,
        basis: Option<&ModalBasis>,
        y_q: &Mat<f64>,
        z: ZPart,
        n_q: usize,
        y: &mut Mat<f64>,
    ) {
        let (jc, js) = (self.blocks[0], self.blocks.get(1).copied());
        let yq = Mat::from_fn(n_q, 1, |i, _| {
            c64::new(
                y_q[(jc * n_q + i, 0)],
                js.map_or(0.0, |js| -y_q[(js * n_q + i, 0)]),
            )
        });
        let yz: Option<Mat<c64>> = match (&self.elimination, z) {
            (Elimination::Real { w, .. }, ZPart::Real(g)) => g.map(|g| {
                let yq_re = Mat::from_fn(n_q, 1, |i, _| yq[(i, 0)].re);
                let yz = g - w * &yq_re;
                Mat::from_fn(yz.nrows(), 1, |i, _| c64::new(yz[(i, 0)], 0.0))
            }),
            (Elimination::Complex { w, .. }, ZPart::Complex(g)) => g.map(|g| g - w * &yq),
            (Elimination::Modal(m), ZPart::Modal(modes)) => {
                let basis = basis.expect("a modal elimination was made from the basis");
                Some(m.back_substitute(basis, modes, &yq))
            }
            _ => unreachable!("z parts are kept in the order of the eliminations"),
        };
        let mut put = |row: usize, v: c64| {
            y[(row, jc)] = v.re;
            if let Some(js) = js {
                y[(row, js)] = -v.im;
            }
        };
        for i in 0..n_q {
            put(i, yq[(i, 0)]);
        }
        if let Some(yz) = yz {
            for i in 0..yz.nrows() {
                put(n_q + i, yz[(i, 0)]);
            }
        }
    }
}
