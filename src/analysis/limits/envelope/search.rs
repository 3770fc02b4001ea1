//! The search at one frequency: the layout of the initial states (a square per side, or a disc
//! per 2D group), corners and edges, and the evaluator that solves a state by homotopy.

use crate::analysis::frf::{FrfPoint, PointSolver};
use crate::model::Problem;
use crate::numerics::box_minimize::BoxSettings;

use crate::analysis::limits::sensitivity::{
    amplitude_sensitivity_of, AmplitudeSensitivity, StateVariable,
};

/// How far inside the range of a contact's stuck initial states a state found beyond it is
/// re-solved (units of m): the edge itself touches μN, where the march's slip test sits at
/// rounding level and Newton's tolerance can tip it over; the amplitude moves by O(10⁻⁶).
pub const EDGE_INSET: f64 = 1e-6;

/// The search settings of the envelope: steps of at most 0.1 in m, so that Newton from the
/// previous state stays on its branch (several branches of steady states exist at one m, e.g.
/// both sides stuck, with an amplitude flat in m, next to one side slipping; a long step lands
/// on whichever Newton reaches and can leave the branch that holds the extreme).
pub fn search_settings() -> BoxSettings {
    BoxSettings {
        max_iterations: 60,
        max_evaluations: 150,
        max_step: 0.1,
        ..BoxSettings::default()
    }
}

/// Steps of m in which a state is walked to a new m when Newton from the nearest solved state
/// fails.
pub const HOMOTOPY_STEPS: usize = 4;

/// The elliptical grid map of the square s ∈ [−1, 1]² onto the unit disc:
/// m = (s₁ √(1 − s₂²/2), s₂ √(1 − s₁²/2)), and its Jacobian ∂m/∂s (row-major 2×2). Smooth and
/// one-to-one; the square's edges go onto the unit circle.
pub fn square_to_disc(s: [f64; 2]) -> ([f64; 2], [f64; 4]) {
    let (r1, r2) = (
        (1.0 - 0.5 * s[0] * s[0]).sqrt(),
        (1.0 - 0.5 * s[1] * s[1]).sqrt(),
    );
    (
        [s[0] * r2, s[1] * r1],
        [r2, -0.5 * s[0] * s[1] / r2, -0.5 * s[0] * s[1] / r1, r1],
    )
}

/// The inverse of [`square_to_disc`] (m in the unit disc; a point just outside it, by rounding,
/// is first brought onto the circle).
pub fn disc_to_square(m: [f64; 2]) -> [f64; 2] {
    let radius = m[0].hypot(m[1]);
    let (u, v) = if radius > 1.0 {
        (m[0] / radius, m[1] / radius)
    } else {
        (m[0], m[1])
    };
    let root = |x: f64| x.max(0.0).sqrt();
    let w = 2.0 * std::f64::consts::SQRT_2;
    let (a, b) = (2.0 + u * u - v * v, 2.0 - u * u + v * v);
    [
        (0.5 * (root(a + w * u) - root(a - w * u))).clamp(-1.0, 1.0),
        (0.5 * (root(b + w * v) - root(b - w * v))).clamp(-1.0, 1.0),
    ]
}

/// The envelope's search variables for groups of contacts: one m₁ per group, and an m₂ for
/// each group with a 2D-friction point, searched on the square of [`square_to_disc`].
#[derive(Debug, Clone, PartialEq)]
pub struct SearchLayout {
    /// The initial-state variables, group by group (m₁, then m₂ for a 2D group).
    pub variables: Vec<StateVariable>,
    /// Per group: its first variable, and whether it has a second one (2D).
    pub(super) groups: Vec<(usize, bool)>,
}

impl SearchLayout {
    /// The layout of `groups` (contact indices) of `problem`.
    pub fn new(problem: &Problem, groups: &[Vec<usize>]) -> Self {
        let mut variables = Vec::new();
        let mut layout = Vec::new();
        for g in groups {
            let two_d = g
                .iter()
                .any(|&c| problem.contacts[c].second_tangent.is_some());
            layout.push((variables.len(), two_d));
            for component in 0..1 + usize::from(two_d) {
                variables.push(StateVariable {
                    contacts: g.clone(),
                    component,
                });
            }
        }
        Self {
            variables,
            groups: layout,
        }
    }

    /// Number of search variables.
    pub fn len(&self) -> usize {
        self.variables.len()
    }

    /// Whether there is no variable.
    pub fn is_empty(&self) -> bool {
        self.variables.is_empty()
    }

    /// m per variable at search coordinates y (with ∂m/∂y per 2D group, row-major).
    fn m_at(&self, y: &[f64]) -> (Vec<f64>, Vec<[f64; 4]>) {
        let mut m = y.to_vec();
        let mut jacobians = Vec::new();
        for &(i, two_d) in &self.groups {
            if two_d {
                let (d, j) = square_to_disc([y[i], y[i + 1]]);
                m[i] = d[0];
                m[i + 1] = d[1];
                jacobians.push(j);
            }
        }
        (m, jacobians)
    }

    /// Search coordinates of m per variable.
    pub(super) fn search_coordinates(&self, m: &[f64]) -> Vec<f64> {
        let mut y: Vec<f64> = m.iter().map(|v| v.clamp(-1.0, 1.0)).collect();
        for &(i, two_d) in &self.groups {
            if two_d {
                let s = disc_to_square([m[i], m[i + 1]]);
                y[i] = s[0];
                y[i + 1] = s[1];
            }
        }
        y
    }

    /// dA/dy from dA/dm at y.
    pub(super) fn chain(&self, y: &[f64], gradient_m: &[f64]) -> Vec<f64> {
        let (_, jacobians) = self.m_at(y);
        let mut g = gradient_m.to_vec();
        let mut next = jacobians.iter();
        for &(i, two_d) in &self.groups {
            if two_d {
                let j = next.next().expect("one Jacobian per 2D group");
                g[i] = gradient_m[i] * j[0] + gradient_m[i + 1] * j[2];
                g[i + 1] = gradient_m[i] * j[1] + gradient_m[i + 1] * j[3];
            }
        }
        g
    }

    /// m per variable from one value per group (m₁ = value, m₂ = 0: along t₁) or from one per
    /// variable (as is); `None` for another length.
    pub fn expand(&self, m: &[f64]) -> Option<Vec<f64>> {
        if m.len() == self.len() {
            return Some(m.to_vec());
        }
        if m.len() != self.groups.len() {
            return None;
        }
        let mut out = vec![0.0; self.len()];
        for (&(i, _), &v) in self.groups.iter().zip(m) {
            out[i] = v;
        }
        Some(out)
    }

    /// Search coordinates of the extra starts on the second tangents: per 2D group, m = (0, ±1)
    /// there and 0 elsewhere.
    pub(super) fn second_tangent_starts(&self) -> Vec<Vec<f64>> {
        let mut starts = Vec::new();
        for &(i, two_d) in &self.groups {
            if two_d {
                for sign in [1.0, -1.0] {
                    let mut y = vec![0.0; self.len()];
                    y[i + 1] = sign;
                    starts.push(y);
                }
            }
        }
        starts
    }

    /// The name of each variable: the group's for m₁, `<group>_m2` for m₂.
    pub fn names(&self, group_names: &[String]) -> Vec<String> {
        let mut names = Vec::with_capacity(self.len());
        for (&(_, two_d), name) in self.groups.iter().zip(group_names) {
            names.push(name.clone());
            if two_d {
                names.push(format!("{name}_m2"));
            }
        }
        names
    }
}

/// One solved state of the search.
pub(super) struct Solved {
    /// Search coordinates.
    pub(super) y: Vec<f64>,
    /// m per variable.
    pub(super) m: Vec<f64>,
    pub(super) point: FrfPoint,
    pub(super) sensitivity: AmplitudeSensitivity,
}

/// Solves states at one frequency for given search coordinates y (m per variable through
/// [`SearchLayout`]), from the nearest state solved so far, with one point solver whose initial
/// states are set per evaluation.
pub(super) struct Evaluator<'s, 'p> {
    pub(super) solver: &'s mut PointSolver<'p>,
    pub(super) layout: &'s SearchLayout,
    pub(super) freq_hz: f64,
    pub(super) solved: Vec<Solved>,
    /// y values whose state was kept under its effective y: (y, index in `solved`).
    aliases: Vec<(Vec<f64>, usize)>,
    pub(super) solves: usize,
}

impl<'s, 'p> Evaluator<'s, 'p> {
    pub(super) fn new(
        solver: &'s mut PointSolver<'p>,
        layout: &'s SearchLayout,
        freq_hz: f64,
    ) -> Self {
        Self {
            solver,
            layout,
            freq_hz,
            solved: Vec::new(),
            aliases: Vec::new(),
            solves: 0,
        }
    }

    /// The initial state (m₁, m₂) of every contact with m per variable (the scene's for
    /// contacts in no group).
    pub(super) fn contact_states(&mut self, m: &[f64]) -> Vec<[f64; 2]> {
        let mut states: Vec<[f64; 2]> = self
            .solver
            .system()
            .problem()
            .contacts
            .iter()
            .map(|c| {
                [
                    c.law.initial_state,
                    c.second_tangent.as_ref().map_or(0.0, |s| s.initial_state),
                ]
            })
            .collect();
        for (v, variable) in self.layout.variables.iter().enumerate() {
            for &c in &variable.contacts {
                states[c][variable.component] = m[v];
            }
        }
        states
    }

    /// Newton at y from `x0`, then, when some group's contacts are stuck with a slider set in
    /// the transient (m beyond the range where they stay stuck from the start), the same state
    /// at the effective m of those groups ([`AmplitudeSensitivity::effective`]), where the
    /// gradient is the one-sided derivative into the range. The state is kept under the
    /// effective y (and found again at y). Its index, or `None`.
    pub(super) fn solve_from(&mut self, y: &[f64], x0: &[f64]) -> Option<usize> {
        let i = self.solve_exactly(y, x0)?;
        let m = self.solved[i].m.clone();
        // The edge of the range, moved EDGE_INSET into it so that the re-solved state sticks
        // with a margin above the march's rounding test.
        let mut effective: Vec<f64> = self.solved[i]
            .sensitivity
            .effective
            .iter()
            .zip(&m)
            .map(|(e, &m)| match e {
                Some(e) if (e - m).abs() > 1e-9 => {
                    (e + EDGE_INSET * (e - m).signum()).clamp(-1.0, 1.0)
                }
                _ => m,
            })
            .collect();
        if effective.iter().zip(&m).all(|(e, m)| (e - m).abs() <= 1e-9) {
            return Some(i);
        }
        // A 2D group's effective m stays in the disc.
        for &(g, two_d) in &self.layout.groups {
            if two_d {
                let r = effective[g].hypot(effective[g + 1]);
                if r > 1.0 - EDGE_INSET {
                    effective[g] *= (1.0 - EDGE_INSET) / r;
                    effective[g + 1] *= (1.0 - EDGE_INSET) / r;
                }
            }
        }
        let y_effective = self.layout.search_coordinates(&effective);
        let x = self.solved[i].point.coefficients.clone();
        match self.solve_exactly(&y_effective, &x) {
            Some(j) => {
                self.aliases.push((y.to_vec(), j));
                Some(j)
            }
            None => Some(i),
        }
    }

    /// Newton at y from `x0`; the solved state is kept. Its index, or `None`.
    fn solve_exactly(&mut self, y: &[f64], x0: &[f64]) -> Option<usize> {
        self.solves += 1;
        let (m, _) = self.layout.m_at(y);
        let states = self.contact_states(&m);
        self.solver.system().set_initial_states_2d(&states);
        let point = self.solver.solve(x0, self.freq_hz).ok()?;
        let omega = 2.0 * std::f64::consts::PI * self.freq_hz;
        let sensitivity = amplitude_sensitivity_of(
            self.solver.system(),
            &point.coefficients,
            omega,
            &self.layout.variables,
        )
        .ok()?;
        if sensitivity
            .gradient
            .iter()
            .flatten()
            .any(|v| !v.is_finite())
        {
            return None;
        }
        self.solved.push(Solved {
            y: y.to_vec(),
            m,
            point,
            sensitivity,
        });
        Some(self.solved.len() - 1)
    }

    /// The state at y: one already solved there, Newton from the nearest solved y, or a walk
    /// from it in [`HOMOTOPY_STEPS`] steps.
    pub(super) fn at(&mut self, y: &[f64]) -> Option<usize> {
        if let Some(i) = self.solved.iter().position(|s| s.y == y) {
            return Some(i);
        }
        if let Some((_, i)) = self.aliases.iter().find(|(a, _)| a == y) {
            return Some(*i);
        }
        let distance = |s: &Solved| {
            s.y.iter()
                .zip(y)
                .fold(0.0_f64, |a, (p, q)| a.max((p - q).abs()))
        };
        let nearest = (0..self.solved.len())
            .min_by(|&i, &j| distance(&self.solved[i]).total_cmp(&distance(&self.solved[j])))?;
        let x0 = self.solved[nearest].point.coefficients.clone();
        if let Some(i) = self.solve_from(y, &x0) {
            return Some(i);
        }
        let y0 = self.solved[nearest].y.clone();
        let mut x = x0;
        let mut last = None;
        for step in 1..=HOMOTOPY_STEPS {
            let t = step as f64 / HOMOTOPY_STEPS as f64;
            let yi: Vec<f64> = y0.iter().zip(y).map(|(a, b)| a + t * (b - a)).collect();
            let i = self.solve_from(&yi, &x)?;
            x = self.solved[i].point.coefficients.clone();
            last = Some(i);
        }
        last
    }

    /// The state among those solved with the largest (`sense` = 1) or smallest (−1) amplitude
    /// of output `o`.
    pub(super) fn extreme(&self, o: usize, sense: f64) -> Option<&Solved> {
        self.solved.iter().max_by(|a, b| {
            (sense * a.sensitivity.amplitudes[o]).total_cmp(&(sense * b.sensitivity.amplitudes[o]))
        })
    }
}

/// Corners of [−1, 1]^k: all 2^k up to k = 4, the two uniform ones beyond. (The centre is
/// added as a start too.)
pub(super) fn corners(k: usize) -> Vec<Vec<f64>> {
    if k <= 4 {
        (0..1usize << k)
            .map(|code| {
                (0..k)
                    .map(|i| if code >> i & 1 == 1 { -1.0 } else { 1.0 })
                    .collect()
            })
            .collect()
    } else {
        vec![vec![1.0; k], vec![-1.0; k]]
    }
}

/// The corners of the damper sides' box [−1, 1]^sides (as [`corners`]) with every group given
/// its side's m: with one m per contact point, the states where each side is uniformly at +1 or
/// −1 (the two limit states and the mixed ones), which the corners of [−1, 1]^k leave out
/// beyond k = 4. Empty when some group's contacts lie on several sides.
pub(super) fn side_corners(problem: &Problem, groups: &[Vec<usize>]) -> Vec<Vec<f64>> {
    let side_of: Option<Vec<usize>> = groups
        .iter()
        .map(|g| {
            let side = problem.contacts[*g.first()?].side;
            g.iter()
                .all(|&c| problem.contacts[c].side == side)
                .then_some(side)
        })
        .collect();
    let Some(side_of) = side_of else {
        return Vec::new();
    };
    corners(problem.sides.len())
        .into_iter()
        .map(|corner| side_of.iter().map(|&s| corner[s]).collect())
        .collect()
}
