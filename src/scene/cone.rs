//! Cone membership for the checks of how bodies are held: whether a vector (a load resultant
//! on a body's rigid-body modes, or a direction of rigid motion) is a non-negative combination
//! of given generators (what the body's contacts can transmit). Lawson-Hanson non-negative
//! least squares on a few rows (one per rigid-body mode), with generators and target scaled to
//! unit length, so that every tolerance is relative.

/// Relative residual at or below which a target counts as inside the cone.
const INSIDE: f64 = 1e-9;

/// Relative residual at or above which a target counts as outside the cone. Between the two
/// thresholds the answer is [`Membership::Unknown`], and the checks then refuse nothing.
const OUTSIDE: f64 = 1e-6;

/// Gradient below which non-negative least squares stops adding generators (unit scale).
const GRADIENT_TOL: f64 = 1e-12;

/// Generators shorter than this fraction of the longest are round-off and dropped.
const NEGLIGIBLE: f64 = 1e-10;

/// The answer of a membership test.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Membership {
    /// The target is a non-negative combination of the generators (to round-off).
    Inside,
    /// The target is clearly not a non-negative combination of the generators.
    Outside,
    /// The computation was inconclusive (degenerate generators, residual between the
    /// thresholds): callers treat it as "not shown to be outside".
    Unknown,
}

/// Whether `target` (r components) lies in the cone {Σ λⱼ gⱼ : λⱼ ≥ 0} of `generators` (each r
/// components). A zero target is inside every cone; an empty set of generators spans only the
/// zero vector.
pub(super) fn cone_membership(generators: &[Vec<f64>], target: &[f64]) -> Membership {
    let target_norm = norm(target);
    if target_norm == 0.0 {
        return Membership::Inside;
    }
    let b: Vec<f64> = target.iter().map(|v| v / target_norm).collect();
    let longest = generators.iter().map(|g| norm(g)).fold(0.0_f64, f64::max);
    let columns: Vec<Vec<f64>> = generators
        .iter()
        .filter_map(|g| {
            let n = norm(g);
            (n > NEGLIGIBLE * longest && n > 0.0).then(|| g.iter().map(|v| v / n).collect())
        })
        .collect();
    match nnls_residual(&columns, &b) {
        Some(r) if r <= INSIDE => Membership::Inside,
        Some(r) if r >= OUTSIDE => Membership::Outside,
        _ => Membership::Unknown,
    }
}

/// Whether every direction of ℝʳ is a non-negative combination of `generators` (r components
/// each), i.e. whether no direction α ≠ 0 has gⱼ·α ≤ 0 for every generator. By Farkas' lemma
/// that holds exactly when the cone contains ±eᵢ for every axis i. `Unknown` when some test
/// was inconclusive and none was clearly outside.
pub(super) fn spans_every_direction(generators: &[Vec<f64>], r: usize) -> Membership {
    let mut answer = Membership::Inside;
    for i in 0..r {
        for sign in [1.0, -1.0] {
            let mut e = vec![0.0; r];
            e[i] = sign;
            match cone_membership(generators, &e) {
                Membership::Outside => return Membership::Outside,
                Membership::Unknown => answer = Membership::Unknown,
                Membership::Inside => {}
            }
        }
    }
    answer
}

/// Euclidean norm.
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Dot product.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The residual norm ‖b − Σ λⱼ cⱼ‖ of the non-negative least-squares fit of `b` by `columns`
/// (Lawson & Hanson, *Solving Least Squares Problems*, ch. 23); `None` when the iteration
/// meets a degenerate step (dependent passive columns, an iteration cap), so that no decision
/// rests on it.
fn nnls_residual(columns: &[Vec<f64>], b: &[f64]) -> Option<f64> {
    let r = b.len();
    let m = columns.len();
    let mut x = vec![0.0; m];
    let mut passive: Vec<usize> = Vec::new();
    let residual = |x: &[f64]| -> Vec<f64> {
        let mut res = b.to_vec();
        for (c, &xj) in columns.iter().zip(x) {
            if xj != 0.0 {
                for (ri, ci) in res.iter_mut().zip(c) {
                    *ri -= xj * ci;
                }
            }
        }
        res
    };
    for _ in 0..(3 * m + 3 * r + 10) {
        let res = residual(&x);
        let best = (0..m)
            .filter(|j| !passive.contains(j))
            .map(|j| (j, dot(&columns[j], &res)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((j, w)) if w > GRADIENT_TOL => passive.push(j),
            _ => return Some(norm(&res)),
        }
        let newest = *passive.last().expect("just pushed");
        let mut settled = false;
        for _ in 0..(m + 10) {
            if passive.len() > r {
                return None;
            }
            let z = passive_least_squares(columns, &passive, b)?;
            if z.iter().all(|&v| v > 0.0) {
                for (&j, &zj) in passive.iter().zip(&z) {
                    x[j] = zj;
                }
                settled = true;
                break;
            }
            // The newest column enters with a positive coefficient in exact arithmetic; if it
            // does not, round-off rules and no decision is made.
            if passive
                .iter()
                .zip(&z)
                .any(|(&j, &zj)| j == newest && zj <= 0.0)
                && x[newest] == 0.0
            {
                return None;
            }
            let alpha = passive
                .iter()
                .zip(&z)
                .filter(|(_, &zj)| zj <= 0.0)
                .map(|(&j, &zj)| x[j] / (x[j] - zj))
                .fold(f64::INFINITY, f64::min);
            for (&j, &zj) in passive.iter().zip(&z) {
                x[j] += alpha * (zj - x[j]);
            }
            passive.retain(|&j| {
                if x[j] <= 1e-15 {
                    x[j] = 0.0;
                    false
                } else {
                    true
                }
            });
        }
        if !settled {
            return None;
        }
    }
    None
}

/// The least-squares coefficients of `b` on the `passive` columns, from the normal equations
/// by Cholesky; `None` when the columns are (numerically) dependent.
fn passive_least_squares(columns: &[Vec<f64>], passive: &[usize], b: &[f64]) -> Option<Vec<f64>> {
    let k = passive.len();
    let mut g = vec![vec![0.0; k]; k];
    let mut c = vec![0.0; k];
    for (p, &i) in passive.iter().enumerate() {
        c[p] = dot(&columns[i], b);
        for (q, &j) in passive.iter().enumerate() {
            g[p][q] = dot(&columns[i], &columns[j]);
        }
    }
    // Cholesky G = L Lᵀ in place (lower triangle).
    for j in 0..k {
        let mut d = g[j][j];
        for l in 0..j {
            d -= g[j][l] * g[j][l];
        }
        if d <= 1e-12 {
            return None;
        }
        let d = d.sqrt();
        g[j][j] = d;
        for i in j + 1..k {
            let mut s = g[i][j];
            for l in 0..j {
                s -= g[i][l] * g[j][l];
            }
            g[i][j] = s / d;
        }
    }
    // Forward then backward substitution.
    let mut y = vec![0.0; k];
    for i in 0..k {
        let mut s = c[i];
        for l in 0..i {
            s -= g[i][l] * y[l];
        }
        y[i] = s / g[i][i];
    }
    let mut z = vec![0.0; k];
    for i in (0..k).rev() {
        let mut s = y[i];
        for l in i + 1..k {
            s -= g[l][i] * z[l];
        }
        z[i] = s / g[i][i];
    }
    Some(z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_line_and_plane_cones() {
        let gens = vec![vec![-1.0], vec![-0.3]];
        assert_eq!(cone_membership(&gens, &[-2.0]), Membership::Inside);
        assert_eq!(cone_membership(&gens, &[1.0]), Membership::Outside);
        assert_eq!(spans_every_direction(&gens, 1), Membership::Outside);
        let both = vec![vec![-1.0], vec![0.5]];
        assert_eq!(spans_every_direction(&both, 1), Membership::Inside);
        // A quarter plane: (1, 1) inside, (-1, 0) outside.
        let quarter = vec![vec![1.0, 0.0], vec![0.0, 2.0]];
        assert_eq!(cone_membership(&quarter, &[1.0, 1.0]), Membership::Inside);
        assert_eq!(cone_membership(&quarter, &[-1.0, 0.0]), Membership::Outside);
        assert_eq!(cone_membership(&quarter, &[0.0, 0.0]), Membership::Inside);
        // Three directions at 120° span the plane.
        let s = 3.0_f64.sqrt() / 2.0;
        let tri = vec![vec![1.0, 0.0], vec![-0.5, s], vec![-0.5, -s]];
        assert_eq!(spans_every_direction(&tri, 2), Membership::Inside);
        assert_eq!(spans_every_direction(&[], 2), Membership::Outside);
    }

    #[test]
    fn many_redundant_generators() {
        // 40 generators in the upper half plane (y > 0): (0, -1) is outside, (0.3, 1) inside.
        let gens: Vec<Vec<f64>> = (1..41)
            .map(|k| {
                let a = std::f64::consts::PI * k as f64 / 41.0;
                vec![a.cos(), a.sin()]
            })
            .collect();
        assert_eq!(cone_membership(&gens, &[0.3, 1.0]), Membership::Inside);
        assert_eq!(cone_membership(&gens, &[0.0, -1.0]), Membership::Outside);
        assert_eq!(spans_every_direction(&gens, 2), Membership::Outside);
    }
}
