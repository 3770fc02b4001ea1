//! Real Fourier basis, unknown ordering and time sampling for harmonic balance.
//!
//! # Convention
//!
//! Time is non-dimensional, τ = ωt, and a periodic signal is written with real coefficients
//!
//! q(τ) = q₀ + Σ_h (q_ch cos hτ + q_sh sin hτ),
//!
//! over the harmonics `h` of a [`HarmonicSet`]. A harmonic set holds *coefficient blocks*: the
//! 0th harmonic contributes one block (q₀), every h ≥ 1 two blocks (q_ch then q_sh). The
//! unknown vector of a model with `n` DOFs is **harmonic-major**: block `j` occupies entries
//! `j·n .. (j+1)·n`, so the linear part D(ω) is block-diagonal (2×2 blocks per harmonic).
//!
//! Time samples are τ_k = 2πk/N, k = 0..N−1; N must exceed twice the highest harmonic
//! (Nyquist). [`SampleBasis`] holds the dense sample matrix E (E\[k\]\[j\] = basis function j at τ_k)
//! and the projection P (Fourier coefficients = P·samples), used by the analytic AFT Jacobian;
//! the forces themselves go through real FFTs (see [`crate::contact::aft`]).

use std::f64::consts::PI;

/// One coefficient block: the constant term, or the cosine / sine part of harmonic `h`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Block {
    /// The 0th harmonic (static part).
    Constant,
    /// Cosine coefficient of harmonic h ≥ 1.
    Cos(usize),
    /// Sine coefficient of harmonic h ≥ 1.
    Sin(usize),
}

impl Block {
    /// The harmonic number of the block.
    pub fn harmonic(self) -> usize {
        match self {
            Block::Constant => 0,
            Block::Cos(h) | Block::Sin(h) => h,
        }
    }

    /// The block's name in output files (the `blocks` list of `solution.json`): `0` for the
    /// constant, `c<h>` / `s<h>` for the cosine and sine parts of harmonic h.
    pub fn label(self) -> String {
        match self {
            Block::Constant => "0".to_string(),
            Block::Cos(h) => format!("c{h}"),
            Block::Sin(h) => format!("s{h}"),
        }
    }
}

/// An ordered set of distinct harmonics, e.g. `[0, 1, 2, 3]` or `[0, 1, 3, 5]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HarmonicSet {
    harmonics: Vec<usize>,
    blocks: Vec<Block>,
}

impl HarmonicSet {
    /// Builds a set from harmonic numbers (sorted and deduplicated here).
    pub fn new(mut harmonics: Vec<usize>) -> Self {
        harmonics.sort_unstable();
        harmonics.dedup();
        let mut blocks = Vec::with_capacity(2 * harmonics.len());
        for &h in &harmonics {
            if h == 0 {
                blocks.push(Block::Constant);
            } else {
                blocks.push(Block::Cos(h));
                blocks.push(Block::Sin(h));
            }
        }
        Self { harmonics, blocks }
    }

    /// The harmonics 0, 1, …, `h_max`.
    pub fn up_to(h_max: usize) -> Self {
        Self::new((0..=h_max).collect())
    }

    /// Harmonic numbers in ascending order.
    pub fn harmonics(&self) -> &[usize] {
        &self.harmonics
    }

    /// Coefficient blocks in unknown order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// The names of the blocks in unknown order (see [`Block::label`]).
    pub fn block_labels(&self) -> Vec<String> {
        self.blocks.iter().map(|b| b.label()).collect()
    }

    /// Number of coefficient blocks (1 for h = 0, 2 per h ≥ 1).
    pub fn n_blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Highest harmonic (0 for an empty set).
    pub fn max_harmonic(&self) -> usize {
        self.harmonics.last().copied().unwrap_or(0)
    }

    /// Whether the 0th harmonic (static part) is an unknown.
    pub fn has_constant(&self) -> bool {
        self.harmonics.first() == Some(&0)
    }

    /// Index of the block holding the cosine part of harmonic `h`, if present.
    pub fn cos_block(&self, h: usize) -> Option<usize> {
        self.blocks.iter().position(|b| *b == Block::Cos(h))
    }

    /// Index of the block holding the sine part of harmonic `h`, if present.
    pub fn sin_block(&self, h: usize) -> Option<usize> {
        self.blocks.iter().position(|b| *b == Block::Sin(h))
    }

    /// The block that d/dτ maps block `block` onto, with the sign of that map per unit of
    /// harmonic: d/dτ (cos hτ) = −h sin hτ, so a cosine block's partner is its sine block with
    /// −1, and a sine block's its cosine block with +1. None for the constant block and for a
    /// block whose partner is not in the set.
    pub fn quadrature_partner(&self, block: Block) -> Option<(usize, f64)> {
        match block {
            Block::Cos(h) => self.sin_block(h).map(|b| (b, -1.0)),
            Block::Sin(h) => self.cos_block(h).map(|b| (b, 1.0)),
            Block::Constant => None,
        }
    }

    /// Index of the constant block, if present.
    pub fn constant_block(&self) -> Option<usize> {
        self.blocks.iter().position(|b| *b == Block::Constant)
    }

    /// Value of basis function `block` at τ.
    pub fn basis(block: Block, tau: f64) -> f64 {
        match block {
            Block::Constant => 1.0,
            Block::Cos(h) => (h as f64 * tau).cos(),
            Block::Sin(h) => (h as f64 * tau).sin(),
        }
    }

    /// Evaluates a signal at τ from its coefficients (one per block).
    pub fn evaluate(&self, coefficients: &[f64], tau: f64) -> f64 {
        self.blocks
            .iter()
            .zip(coefficients)
            .map(|(b, c)| c * Self::basis(*b, tau))
            .sum()
    }
}

/// ∫ g b_j b_i (or Σ_k g_k b_j(τ_k) b_i(τ_k)) for a weight g given by its cosine and sine
/// moments c(m) = ∫ g cos(mτ), s(m) = ∫ g sin(mτ) at integer m (any sign), using
/// cos a cos b = ½[cos(a−b) + cos(a+b)], sin a sin b = ½[cos(a−b) − cos(a+b)],
/// cos a sin b = ½[sin(a+b) − sin(a−b)]. Shared by the sampled AFT's Jacobian (moments from
/// one real FFT of g) and the event-resolved law (moments integrated over its phases).
pub fn product_integral(
    c: impl Fn(i64) -> f64,
    s: impl Fn(i64) -> f64,
    bj: Block,
    bi: Block,
) -> f64 {
    use Block::{Constant, Cos, Sin};
    match (bj, bi) {
        (Constant, Constant) => c(0),
        (Constant, Cos(h)) | (Cos(h), Constant) => c(h as i64),
        (Constant, Sin(h)) | (Sin(h), Constant) => s(h as i64),
        (Cos(a), Cos(b)) => 0.5 * (c(a as i64 - b as i64) + c(a as i64 + b as i64)),
        (Sin(a), Sin(b)) => 0.5 * (c(a as i64 - b as i64) - c(a as i64 + b as i64)),
        (Cos(a), Sin(b)) => 0.5 * (s(a as i64 + b as i64) - s(a as i64 - b as i64)),
        (Sin(a), Cos(b)) => 0.5 * (s(a as i64 + b as i64) + s(a as i64 - b as i64)),
    }
}

/// Dense sampled basis and projection for a harmonic set at N samples per period.
#[derive(Debug, Clone)]
pub struct SampleBasis {
    /// Samples per period N.
    pub n_samples: usize,
    /// Number of coefficient blocks.
    pub n_blocks: usize,
    /// E, row-major N × n_blocks: E\[k\]\[j\] = basis_j(τ_k).
    pub synthesis: Vec<f64>,
    /// P, row-major n_blocks × N: coefficient_j = Σ_k P\[j\]\[k\] f(τ_k) (exact for the set's harmonics).
    pub projection: Vec<f64>,
}

impl SampleBasis {
    /// Builds E and P. `n_samples` must exceed twice the highest harmonic.
    pub fn new(set: &HarmonicSet, n_samples: usize) -> Self {
        let nb = set.n_blocks();
        let mut synthesis = vec![0.0; n_samples * nb];
        let mut projection = vec![0.0; nb * n_samples];
        for k in 0..n_samples {
            let tau = 2.0 * PI * k as f64 / n_samples as f64;
            for (j, b) in set.blocks().iter().enumerate() {
                let e = HarmonicSet::basis(*b, tau);
                synthesis[k * nb + j] = e;
                let w = if *b == Block::Constant { 1.0 } else { 2.0 };
                projection[j * n_samples + k] = w * e / n_samples as f64;
            }
        }
        Self {
            n_samples,
            n_blocks: nb,
            synthesis,
            projection,
        }
    }

    /// Row k of E.
    #[inline]
    pub fn row(&self, k: usize) -> &[f64] {
        &self.synthesis[k * self.n_blocks..(k + 1) * self.n_blocks]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_harmonic_major() {
        let s = HarmonicSet::new(vec![3, 0, 1, 1]);
        assert_eq!(s.harmonics(), &[0, 1, 3]);
        assert_eq!(
            s.blocks(),
            &[
                Block::Constant,
                Block::Cos(1),
                Block::Sin(1),
                Block::Cos(3),
                Block::Sin(3)
            ]
        );
        assert_eq!(s.sin_block(3), Some(4));
        assert_eq!(s.cos_block(2), None);
    }

    #[test]
    fn projection_inverts_synthesis() {
        let s = HarmonicSet::new(vec![0, 1, 2, 5]);
        let b = SampleBasis::new(&s, 16);
        let nb = s.n_blocks();
        for j in 0..nb {
            for i in 0..nb {
                let pe: f64 = (0..16)
                    .map(|k| b.projection[j * 16 + k] * b.synthesis[k * nb + i])
                    .sum();
                let expect = if i == j { 1.0 } else { 0.0 };
                assert!((pe - expect).abs() < 1e-13, "P·E[{j}][{i}] = {pe}");
            }
        }
    }
}
