//! The condensed harmonic balance: unknowns on the contact DOFs only.
//!
//! Split the DOFs into the contact (nonlinear) DOFs c and the rest l. Per harmonic h the
//! linear part acts on the cosine/sine pair through the real 2n form
//!
//! ```text
//! A_h(ω) = ⎡ K − (hω)²M    hωC      ⎤        (A_0 = K)
//!          ⎣   −hωC      K − (hω)²M ⎦
//! ```
//!
//! and the l rows carry no contact force, so x_l = A_ll⁻¹ (F_l − A_lc x_c) exactly. The
//! residual on the contact DOFs is then
//!
//! R_c(x_c, ω) = S_h x_c + F̂_nl(x_c) − f_h,   S_h = A_cc − A_cl A_ll⁻¹ A_lc,
//! f_h = F_c − A_cl A_ll⁻¹ F_l
//!
//! (a dynamic Schur complement per harmonic). Its zeros are exactly the zeros of the full
//! residual (paper Eq. 7) restricted to c; the l coefficients are recovered afterwards. This
//! pays off on reduced (Craig-Bampton) models whose modal and non-contact boundary DOFs are
//! many: Newton works on n_c · blocks unknowns with a dense Jacobian, and each frequency costs
//! one LU of A_ll per harmonic. ∂R_c/∂ω at fixed x_c is
//!
//! A'_cc x_c + A'_cl x_l + A_cl x_l',   x_l' = −A_ll⁻¹ (A'_ll x_l + A'_lc x_c),
//!
//! with A' = ∂A/∂ω. The real 2n form is used because the complex dynamic stiffness is
//! complex-symmetric, not Hermitian (no Cholesky/LDLᵀ); dense LU with partial pivoting.

use faer::linalg::solvers::PartialPivLu;
use faer::prelude::Solve;
use faer::Mat;

use crate::contact::harmonic::HarmonicSet;
use crate::contact::ContactState;
use crate::hbm::pattern::JacobianLayout;
use crate::hbm::{HbmError, HbmSystem};
use crate::model::Problem;
use crate::numerics::jacobian::AssembledJacobian;
use crate::numerics::linalg::checked_lu;

/// Condensation of one harmonic at one frequency.
struct HarmonicCondensation {
    /// Unknown blocks of this harmonic: (cos, sin), or (constant, None).
    blocks: (usize, Option<usize>),
    /// LU of A_ll (None when there are no l DOFs).
    lu_ll: Option<PartialPivLu<f64>>,
    /// A_cl (real form).
    a_cl: Mat<f64>,
    /// S = A_cc − A_cl A_ll⁻¹ A_lc (real form).
    schur: Mat<f64>,
    /// f = F_c − A_cl A_ll⁻¹ F_l (real form).
    load: Vec<f64>,
    /// A_ll⁻¹ F_l (real form).
    x_l_load: Mat<f64>,
    /// A_ll⁻¹ A_lc (real form).
    w: Mat<f64>,
}

/// The harmonic-balance operator condensed on the contact DOFs (see the module docs).
pub struct CondensedHbm<'p> {
    full: HbmSystem<'p>,
    contact_dofs: Vec<usize>,
    linear_dofs: Vec<usize>,
    layout: JacobianLayout,
    dense_k: Mat<f64>,
    dense_m: Mat<f64>,
    dense_c: Mat<f64>,
    cache: Option<(f64, Vec<HarmonicCondensation>)>,
    x_full: Vec<f64>,
    r_full: Vec<f64>,
}

impl<'p> CondensedHbm<'p> {
    /// Builds the operator for `problem` (its contact DOFs become the unknowns).
    pub fn new(problem: &'p Problem) -> Result<Self, HbmError> {
        let full = HbmSystem::new(problem)?;
        let split = problem.dof_split();
        let layout = JacobianLayout::contacts_only(
            problem,
            full.unknowns(),
            &split.local,
            split.contact.len(),
        );
        let dim_full = full.dim();
        Ok(Self {
            dense_k: problem.model.stiffness.to_dense(),
            dense_m: problem.model.mass.to_dense(),
            dense_c: problem.model.damping.to_dense(),
            full,
            contact_dofs: split.contact,
            linear_dofs: split.linear,
            layout,
            cache: None,
            x_full: vec![0.0; dim_full],
            r_full: vec![0.0; dim_full],
        })
    }

    /// The full operator (contact forces and time histories on full coefficients).
    pub fn full(&mut self) -> &mut HbmSystem<'p> {
        &mut self.full
    }

    /// The full operator, read-only.
    pub fn full_ref(&self) -> &HbmSystem<'p> {
        &self.full
    }

    /// Contact DOFs, in unknown order within each block.
    pub fn contact_dofs(&self) -> &[usize] {
        &self.contact_dofs
    }

    /// Number of unknowns n_c × blocks.
    pub fn dim(&self) -> usize {
        self.contact_dofs.len() * self.full.unknowns().n_blocks()
    }

    /// Contact states of the last evaluation.
    pub fn states(&self) -> &[ContactState] {
        &self.full.states
    }

    /// The contact-DOF coefficients of full coefficients.
    pub fn restrict(&self, x_full: &[f64]) -> Vec<f64> {
        let n = self.full.problem().model.n_dofs();
        let nc = self.contact_dofs.len();
        let nb = self.full.unknowns().n_blocks();
        let mut x = vec![0.0; nc * nb];
        for j in 0..nb {
            for (i, &d) in self.contact_dofs.iter().enumerate() {
                x[j * nc + i] = x_full[j * n + d];
            }
        }
        x
    }

    /// Real-form block of A_h (or A'_h with `derivative`) on rows `rows` and columns `cols`.
    fn block(
        &self,
        h: usize,
        omega: f64,
        rows: &[usize],
        cols: &[usize],
        derivative: bool,
    ) -> Mat<f64> {
        let hf = h as f64;
        let hw = hf * omega;
        let (d_k, d_m, d_c) = if derivative {
            (0.0, -2.0 * hf * hf * omega, hf)
        } else {
            (1.0, -hw * hw, hw)
        };
        let (nr, nc) = (rows.len(), cols.len());
        let d = |i: usize, j: usize| {
            let (p, q) = (rows[i], cols[j]);
            d_k * self.dense_k[(p, q)] + d_m * self.dense_m[(p, q)]
        };
        if h == 0 {
            return Mat::from_fn(nr, nc, |i, j| {
                if derivative {
                    0.0
                } else {
                    self.dense_k[(rows[i], cols[j])]
                }
            });
        }
        Mat::from_fn(2 * nr, 2 * nc, |i, j| {
            let (bi, ii) = (i / nr, i % nr);
            let (bj, jj) = (j / nc, j % nc);
            match (bi, bj) {
                (0, 0) | (1, 1) => d(ii, jj),
                (0, 1) => d_c * self.dense_c[(rows[ii], cols[jj])],
                _ => -d_c * self.dense_c[(rows[ii], cols[jj])],
            }
        })
    }

    /// The loads of harmonic h on `dofs` in real form (cos then sin; constant for h = 0).
    fn loads(&self, blocks: (usize, Option<usize>), dofs: &[usize]) -> Vec<f64> {
        let n = self.full.problem().model.n_dofs();
        let f = self.full.excitation();
        let mut out: Vec<f64> = dofs.iter().map(|&d| f[blocks.0 * n + d]).collect();
        if let Some(s) = blocks.1 {
            out.extend(dofs.iter().map(|&d| f[s * n + d]));
        }
        out
    }

    /// The harmonics of the unknowns with their blocks.
    fn harmonic_blocks(set: &HarmonicSet) -> Vec<(usize, (usize, Option<usize>))> {
        set.harmonics()
            .iter()
            .map(|&h| {
                if h == 0 {
                    (
                        0,
                        (set.constant_block().expect("h = 0 is in the set"), None),
                    )
                } else {
                    (
                        h,
                        (
                            set.cos_block(h).expect("cosine block of h"),
                            set.sin_block(h),
                        ),
                    )
                }
            })
            .collect()
    }

    /// Condensation at ω, cached while ω does not change.
    fn condense(&mut self, omega: f64) -> Result<(), HbmError> {
        if matches!(&self.cache, Some((w, _)) if *w == omega) {
            return Ok(());
        }
        let harmonics = Self::harmonic_blocks(self.full.unknowns());
        let (c, l) = (&self.contact_dofs, &self.linear_dofs);
        let mut out = Vec::with_capacity(harmonics.len());
        for (h, blocks) in harmonics {
            let a_cc = self.block(h, omega, c, c, false);
            let a_cl = self.block(h, omega, c, l, false);
            let a_lc = self.block(h, omega, l, c, false);
            let f_c = self.loads(blocks, c);
            let f_l = self.loads(blocks, l);
            let (lu_ll, w, x_l_load) = if l.is_empty() {
                (None, Mat::zeros(0, a_cc.ncols()), Mat::zeros(0, 1))
            } else {
                let a_ll = self.block(h, omega, l, l, false);
                let lu = checked_lu(&a_ll)?;
                let w = lu.solve(&a_lc);
                let x_l_load = lu.solve(Mat::from_fn(f_l.len(), 1, |i, _| f_l[i]));
                (Some(lu), w, x_l_load)
            };
            let (schur, load) = if l.is_empty() {
                (a_cc, f_c)
            } else {
                let schur = &a_cc - &a_cl * &w;
                let correction = &a_cl * &x_l_load;
                let load = f_c
                    .iter()
                    .enumerate()
                    .map(|(i, v)| v - correction[(i, 0)])
                    .collect();
                (schur, load)
            };
            out.push(HarmonicCondensation {
                blocks,
                lu_ll,
                a_cl,
                schur,
                load,
                x_l_load,
                w,
            });
        }
        self.cache = Some((omega, out));
        Ok(())
    }

    /// Real-form contact coefficients of harmonic `hc` from the unknowns.
    fn harmonic_unknowns(&self, hc: &HarmonicCondensation, x: &[f64]) -> Vec<f64> {
        let nc = self.contact_dofs.len();
        let mut v = x[hc.blocks.0 * nc..(hc.blocks.0 + 1) * nc].to_vec();
        if let Some(s) = hc.blocks.1 {
            v.extend_from_slice(&x[s * nc..(s + 1) * nc]);
        }
        v
    }

    /// Puts the contact unknowns into the full-layout buffer (other DOFs zero).
    fn scatter(&mut self, x: &[f64]) {
        let n = self.full.problem().model.n_dofs();
        let nc = self.contact_dofs.len();
        let nb = self.full.unknowns().n_blocks();
        self.x_full.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..nb {
            for (i, &d) in self.contact_dofs.iter().enumerate() {
                self.x_full[j * n + d] = x[j * nc + i];
            }
        }
    }

    /// R_c into r, with the contact Jacobian into `jac` and ∂R_c/∂ω into `dr` if given.
    fn evaluate(
        &mut self,
        x: &[f64],
        omega: f64,
        r: &mut [f64],
        mut jac: Option<&mut AssembledJacobian>,
        dr: Option<&mut [f64]>,
    ) -> Result<(), HbmError> {
        self.condense(omega)?;
        let n = self.full.problem().model.n_dofs();
        let nc = self.contact_dofs.len();
        let nb = self.full.unknowns().n_blocks();
        let (_, cache) = self.cache.take().expect("condensed above");
        if let Some(j) = jac.as_deref_mut() {
            j.clear();
        }
        let mut dr = dr;
        for hc in &cache {
            let xh = self.harmonic_unknowns(hc, x);
            let rows: Vec<usize> = std::iter::once(hc.blocks.0).chain(hc.blocks.1).collect();
            for (bi, &jb) in rows.iter().enumerate() {
                for i in 0..nc {
                    let row = bi * nc + i;
                    let mut acc = -hc.load[row];
                    for (k, xk) in xh.iter().enumerate() {
                        acc += hc.schur[(row, k)] * xk;
                    }
                    r[jb * nc + i] = acc;
                }
            }
            if let Some(j) = jac.as_deref_mut() {
                for (bi, &jb) in rows.iter().enumerate() {
                    for (bk, &kb) in rows.iter().enumerate() {
                        for i in 0..nc {
                            for k in 0..nc {
                                let v = hc.schur[(bi * nc + i, bk * nc + k)];
                                if v != 0.0 {
                                    let slot = j.slot(jb * nc + i, kb * nc + k);
                                    j.add_at(slot, v);
                                }
                            }
                        }
                    }
                }
            }
            if let Some(dr) = dr.as_deref_mut() {
                let h = self.full.unknowns().blocks()[hc.blocks.0].harmonic();
                let d = self.omega_derivative(h, omega, hc, &xh);
                for (bi, &jb) in rows.iter().enumerate() {
                    dr[jb * nc..(jb + 1) * nc].copy_from_slice(&d[bi * nc..(bi + 1) * nc]);
                }
            }
        }
        self.cache = Some((omega, cache));
        // Contact forces on the full layout, gathered back to the contact DOFs.
        self.scatter(x);
        self.r_full.iter_mut().for_each(|v| *v = 0.0);
        let x_full = std::mem::take(&mut self.x_full);
        let mut r_full = std::mem::take(&mut self.r_full);
        let slots = &self.layout.contacts;
        let result =
            self.full
                .add_contact_terms(&x_full, &mut r_full, jac.map(|j| (j, slots.as_slice())));
        for j in 0..nb {
            for (i, &d) in self.contact_dofs.iter().enumerate() {
                r[j * nc + i] += r_full[j * n + d];
            }
        }
        self.x_full = x_full;
        self.r_full = r_full;
        result
    }

    /// ∂R_c/∂ω of harmonic h at fixed contact unknowns xh (real form).
    fn omega_derivative(
        &self,
        h: usize,
        omega: f64,
        hc: &HarmonicCondensation,
        xh: &[f64],
    ) -> Vec<f64> {
        let (c, l) = (&self.contact_dofs, &self.linear_dofs);
        let col = |v: &[f64]| Mat::from_fn(v.len(), 1, |i, _| v[i]);
        let xc = col(xh);
        let mut d = &self.block(h, omega, c, c, true) * &xc;
        if let Some(lu) = &hc.lu_ll {
            let x_l = &hc.x_l_load - &hc.w * &xc;
            let rhs =
                &self.block(h, omega, l, l, true) * &x_l + &self.block(h, omega, l, c, true) * &xc;
            let x_l_prime = lu.solve(&rhs);
            d = d + &self.block(h, omega, c, l, true) * &x_l - &hc.a_cl * &x_l_prime;
        }
        (0..d.nrows()).map(|i| d[(i, 0)]).collect()
    }

    /// Full coefficients (all DOFs, the unknown layout of the full problem) from the contact
    /// unknowns at ω: x_l = A_ll⁻¹ (F_l − A_lc x_c) per harmonic.
    pub fn expand(&mut self, x: &[f64], omega: f64) -> Result<Vec<f64>, HbmError> {
        self.condense(omega)?;
        let n = self.full.problem().model.n_dofs();
        let nc = self.contact_dofs.len();
        let mut out = vec![0.0; self.full.dim()];
        let (_, cache) = self.cache.as_ref().expect("condensed above");
        for hc in cache {
            let xh = self.harmonic_unknowns(hc, x);
            let rows: Vec<usize> = std::iter::once(hc.blocks.0).chain(hc.blocks.1).collect();
            let xc = Mat::from_fn(xh.len(), 1, |i, _| xh[i]);
            let x_l = if hc.lu_ll.is_some() {
                &hc.x_l_load - &hc.w * &xc
            } else {
                Mat::zeros(0, 1)
            };
            let nl = self.linear_dofs.len();
            for (bi, &jb) in rows.iter().enumerate() {
                for (i, &d) in self.contact_dofs.iter().enumerate() {
                    out[jb * n + d] = xh[bi * nc + i];
                }
                for (i, &d) in self.linear_dofs.iter().enumerate() {
                    out[jb * n + d] = x_l[(bi * nl + i, 0)];
                }
            }
        }
        Ok(out)
    }

    /// R_c(x, ω) into r; ω in rad/s.
    pub fn residual(&mut self, x: &[f64], omega: f64, r: &mut [f64]) -> Result<(), HbmError> {
        self.evaluate(x, omega, r, None, None)
    }

    /// R_c, ∂R_c/∂x (analytic contact part) and ∂R_c/∂ω.
    pub fn residual_and_jacobian(
        &mut self,
        x: &[f64],
        omega: f64,
        r: &mut [f64],
        jac: &mut AssembledJacobian,
        dr_domega: &mut [f64],
    ) -> Result<(), HbmError> {
        self.evaluate(x, omega, r, Some(jac), Some(dr_domega))
    }

    /// An empty dense Jacobian on the contact unknowns.
    pub fn new_jacobian(&self) -> AssembledJacobian {
        self.layout.new_jacobian()
    }
}
