//! Upper bounds of the exit functions over blocks of grid cells, so that the event march
//! passes over a block where no event can happen with one comparison per exit function
//! instead of one evaluation per cell.
//!
//! Each exit function of the march ([`super::march`]) is a fixed trigonometric polynomial
//! shifted by a constant of the phase: kₜ(u − w) − L = (kₜu − L) − kₜw for a slip onset of
//! sign +, −kₜ(u − w) − L = (−kₜu − L) + kₜw for one of sign −, L′ ∓ kₜu′ for the end of a
//! slip of sign ±, and ∓v for opening and closing. Over a block τₐ ≤ τ ≤ τ_b a function f
//! stays below the chord of its end values plus (τ_b − τₐ)²/8 · max|f″|, and max|f″| is
//! bounded by the coefficients (Σ h² |ĉ_h| for the second derivative, Σ h³ |ĉ_h| for the
//! third). A block whose bound is negative holds no root and no graze: the march skips it,
//! and finds exactly what a cell-by-cell scan finds (which reports nothing in such cells).
//! The bounds cost two samples per block, not one per cell.

use crate::contact::harmonic::Block;
use std::f64::consts::PI;

/// Cells per block for N samples: N/32 between 4 and 16, so that a block spans at most
/// π/16 rad (its curvature margin stays a small fraction of the functions) and costs few
/// cells to scan where it holds an event.
pub fn block_cells(n: usize) -> usize {
    (n / 32).clamp(4, 16)
}

/// Which bounded function (index into [`CellBounds::max`]'s entries).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bounded {
    /// kₜu − L (N): a slip onset of sign + once kₜw is subtracted.
    SlipPositive = 0,
    /// −kₜu − L (N): a slip onset of sign − once kₜw is added.
    SlipNegative = 1,
    /// L′ − kₜu′ (N/rad): the end of a slip of sign +.
    StickPositive = 2,
    /// L′ + kₜu′ (N/rad): the end of a slip of sign −.
    StickNegative = 3,
    /// −v (m): an opening.
    Opening = 4,
    /// v (m): a closing.
    Closing = 5,
}

/// What the bounds need of the Jenkins law (see [`super::march::LawParams`]).
#[derive(Debug, Clone, Copy)]
pub struct BoundLaw {
    /// Tangential stiffness kₜ (N/m).
    pub kt: f64,
    /// μ kₙ (N/m).
    pub mu_kn: f64,
    /// The constant friction limit (N) under a constant normal load; `None` with a variable one.
    pub constant_limit: Option<f64>,
}

/// Per block of [`Self::cells`] cells, an upper bound of each [`Bounded`] function over the
/// block: the larger of its values at the block's ends plus the curvature margin.
#[derive(Debug, Clone, Default)]
pub struct CellBounds {
    /// Cells per block ([`block_cells`]).
    pub cells: usize,
    /// One entry per block, indexed by [`Bounded`].
    pub max: Vec<[f64; 6]>,
}

impl CellBounds {
    /// The bound of `which` over block `block`.
    #[inline]
    pub fn of(&self, block: usize, which: Bounded) -> f64 {
        self.max[block][which as usize]
    }

    /// Fills the bounds from the grid samples of u, u′ (`u`) and v, v′ (`v`), N each, and the
    /// coefficients (blocks, û, v̂) of u and v (for the curvature margins).
    pub fn fill(
        &mut self,
        law: BoundLaw,
        (blocks, u_hat, v_hat): (&[Block], &[f64], &[f64]),
        u: [&[f64]; 2],
        v: [&[f64]; 2],
    ) {
        let n = u[0].len();
        let cell = 2.0 * PI / n as f64;
        let variable = law.constant_limit.is_none();
        let mu_kn = if variable { law.mu_kn } else { 0.0 };
        // Σ h^p |ĉ| of u and v, p = 2 and 3.
        let (mut u2, mut u3, mut v2, mut v3) = (0.0, 0.0, 0.0, 0.0);
        for (j, b) in blocks.iter().enumerate() {
            if let Block::Cos(h) | Block::Sin(h) = *b {
                let h = h as f64;
                let (cu, cv) = (u_hat[j].abs(), v_hat[j].abs());
                u2 += h * h * cu;
                u3 += h * h * h * cu;
                v2 += h * h * cv;
                v3 += h * h * h * cv;
            }
        }
        // Curvature margins per unit of (block length)²/8.
        let force = law.kt * u2 + mu_kn * v2;
        let rate = law.kt * u3 + mu_kn * v3;
        let curvature = [force, force, rate, rate, v2, v2];
        let kt = law.kt;
        // The six functions at sample k (L unclamped, as in the exit functions); with a
        // constant load L = L₀ and L′ = 0 (`mu_kn` is 0 then).
        let l0 = law.constant_limit.unwrap_or(0.0);
        let values = |k: usize| {
            let k = if k == n { 0 } else { k };
            let (limit, rate) = (l0 + mu_kn * v[0][k], mu_kn * v[1][k]);
            let (ktu, ktdu) = (kt * u[0][k], kt * u[1][k]);
            [
                ktu - limit,
                -ktu - limit,
                rate - ktdu,
                rate + ktdu,
                -v[0][k],
                v[0][k],
            ]
        };
        let cells = block_cells(n);
        self.cells = cells;
        let blocks = n.div_ceil(cells);
        self.max.clear();
        self.max.resize(blocks, [0.0; 6]);
        let mut start = values(0);
        for (j, m) in self.max.iter_mut().enumerate() {
            let (first, last) = (j * cells, ((j + 1) * cells).min(n));
            let end = values(last);
            let length = (last - first) as f64 * cell;
            let chord = length * length / 8.0;
            for (i, m) in m.iter_mut().enumerate() {
                let larger = if end[i] > start[i] { end[i] } else { start[i] };
                *m = larger + chord * curvature[i];
            }
            start = end;
        }
    }
}
