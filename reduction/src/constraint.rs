//! Static constraint modes Ψ = −K_II⁻¹ K_IB, block by block: each block of Ψ is solved and
//! folded into K_BB + K_BI Ψ, the boundary mass and the boundary-modal coupling, and never
//! held whole.

use crate::block::{sym_mul_rows, RowBlock};
use crate::csc::{Blocks, Part};
use crate::factor::SpdFactor;
use crate::ReductionError;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use rayon::prelude::*;
use std::time::Instant;

pub(crate) struct ConstraintResult {
    /// K_BB + K_BI Ψ
    pub(crate) k_bb: Mat<f64>,
    /// M_BB + M_BI Ψ + Ψᵀ M_IB + Ψᵀ M_II Ψ
    pub(crate) m_bb: Mat<f64>,
    /// (M_BI + Ψᵀ M_II) Φ, nb × nm
    pub(crate) coupling: Mat<f64>,
    /// Ψ rows (length nb) of the recovered DOFs (empty for boundary ones)
    pub(crate) psi_rows: Vec<Vec<f64>>,
    pub(crate) t_solve: f64,
    pub(crate) t_mass: f64,
}

/// Output of one column block `a` of Ψ.
struct BlockOut {
    start: usize,
    /// (K_BB + K_BI Ψ)[:, a], nb × w
    k_cols: Mat<f64>,
    /// M_BI Ψ_a, nb × w
    p_cols: Mat<f64>,
    /// −K_BI K_II⁻¹ M_II Ψ_a = Ψᵀ M_II Ψ_a, nb × w (columns a of Ψᵀ M_II Ψ)
    g_cols: Mat<f64>,
    /// (M_II Ψ_a)ᵀ Φ, w × nm
    coupling_rows: Mat<f64>,
    /// Ψ_a rows of the recovered interior DOFs: (position in recover, values)
    psi: Vec<(usize, Vec<f64>)>,
    t_solve: f64,
    t_mass: f64,
}

#[allow(clippy::too_many_arguments)]
/// Ψ = −K_II⁻¹ K_IB computed `block_size` columns at a time; only the block
/// in hand is held (3 dense `n_I × block_size` arrays). The term Ψᵀ M_II Ψ,
/// which pairs every block with every other, is obtained without holding Ψ
/// through `Ψ_bᵀ M_II Ψ_a = −K_BI_b (K_II⁻¹ M_II Ψ_a)`: one more solve per
/// block.
pub(crate) fn constraint_blocks(
    kb: &Blocks,
    mb: &Blocks,
    inv: &[usize],
    factor: &SpdFactor,
    phi: &Mat<f64>,
    part: &[Part],
    recover: &[usize],
    (block_size, threads): (usize, usize),
) -> Result<ConstraintResult, ReductionError> {
    let n_i = kb.ii_lower.ncols;
    let nb = kb.ib.ncols;
    let nm = phi.ncols();
    let bs = block_size;
    // recovered interior DOFs: (position in recover, interior index)
    let rec_int: Vec<(usize, usize)> = recover
        .iter()
        .enumerate()
        .filter_map(|(pos, &d)| match part[d] {
            Part::Interior(i) => Some((pos, i)),
            Part::Boundary(_) => None,
        })
        .collect();
    // M_BI Φ (nb × nm)
    let mbi_phi = mb.ib.transpose_mul_rows(&RowBlock::from_mat(phi.as_ref()));

    let starts: Vec<usize> = (0..nb).step_by(bs).collect();
    let run_block = |start: usize| -> BlockOut {
        let w = bs.min(nb - start);
        // Ψ_a = −K_II⁻¹ K_IB[:, a]   (row-major n_I × w)
        let mut psi = RowBlock::take(n_i, w);
        psi.data.fill(0.0);
        for c in 0..w {
            let (rows, vals) = kb.ib.col(start + c);
            for (&i, &v) in rows.iter().zip(vals) {
                psi.row_mut(i)[c] = -v;
            }
        }
        let t = Instant::now();
        factor.solve_rows(&mut psi);
        let mut t_solve = t.elapsed().as_secs_f64();
        let mut k_cols = kb.ib.transpose_mul_rows(&psi);
        let p_cols = mb.ib.transpose_mul_rows(&psi);
        for c in 0..w {
            for i in 0..nb {
                k_cols[(i, c)] += kb.bb[(i, start + c)];
            }
        }
        let psi_rec: Vec<(usize, Vec<f64>)> = rec_int
            .iter()
            .map(|&(pos, i)| (pos, psi.row(i).to_vec()))
            .collect();
        // Z = M_II Ψ_a
        let mut z = RowBlock::take(n_i, w);
        let t = Instant::now();
        sym_mul_rows(&mb.ii_lower, Some(inv), &psi, &mut z);
        let t_mass = t.elapsed().as_secs_f64();
        psi.give_back();
        let mut coupling_rows = Mat::zeros(w, nm);
        matmul(
            coupling_rows.as_mut(),
            Accum::Replace,
            z.view().transpose(),
            phi.as_ref(),
            1.0,
            Par::Seq,
        );
        for c in 0..w {
            for a in 0..nm {
                coupling_rows[(c, a)] += mbi_phi[(start + c, a)];
            }
        }
        // Y = K_II⁻¹ Z; Ψᵀ M_II Ψ_a = −K_BI Y
        let t = Instant::now();
        factor.solve_rows(&mut z);
        t_solve += t.elapsed().as_secs_f64();
        let mut g_cols = kb.ib.transpose_mul_rows(&z);
        z.give_back();
        for c in 0..w {
            for i in 0..nb {
                g_cols[(i, c)] = -g_cols[(i, c)];
            }
        }
        BlockOut {
            start,
            k_cols,
            p_cols,
            g_cols,
            coupling_rows,
            psi: psi_rec,
            t_solve,
            t_mass,
        }
    };
    let threads = threads.max(1);
    let outs: Vec<BlockOut> = if threads == 1 {
        starts.iter().map(|&s| run_block(s)).collect()
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| ReductionError::InvalidArgument(format!("thread pool: {e}")))?;
        pool.install(|| starts.par_iter().map(|&s| run_block(s)).collect())
    };
    let mut k_bb = Mat::zeros(nb, nb);
    let mut p = Mat::zeros(nb, nb);
    let mut g = Mat::zeros(nb, nb);
    let mut coupling = Mat::zeros(nb, nm);
    let mut psi_rows: Vec<Vec<f64>> = recover.iter().map(|_| Vec::new()).collect();
    for &(pos, _) in &rec_int {
        psi_rows[pos] = vec![0.0; nb];
    }
    let (mut t_solve, mut t_mass) = (0.0, 0.0);
    for o in outs {
        t_solve += o.t_solve;
        t_mass += o.t_mass;
        let w = o.k_cols.ncols();
        k_bb.as_mut().subcols_mut(o.start, w).copy_from(&o.k_cols);
        p.as_mut().subcols_mut(o.start, w).copy_from(&o.p_cols);
        g.as_mut().subcols_mut(o.start, w).copy_from(&o.g_cols);
        coupling
            .as_mut()
            .subrows_mut(o.start, w)
            .copy_from(&o.coupling_rows);
        for (pos, vals) in o.psi {
            psi_rows[pos][o.start..o.start + w].copy_from_slice(&vals);
        }
    }
    // M̂_BB = M_BB + P + Pᵀ + G
    let m_bb = Mat::from_fn(nb, nb, |i, j| {
        mb.bb[(i, j)] + p[(i, j)] + p[(j, i)] + 0.5 * (g[(i, j)] + g[(j, i)])
    });
    Ok(ConstraintResult {
        k_bb,
        m_bb,
        coupling,
        psi_rows,
        t_solve,
        t_mass,
    })
}
