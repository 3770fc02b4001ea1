//! The response envelope: at each frequency, the largest and smallest first-harmonic amplitude
//! of every output DOF over all admissible initial tangential states m ∈ [−1, 1]^k, with k one
//! m per damper side (`sides`) or per contact point (`points`).
//!
//! # 2D friction: the disc
//!
//! A group (side or point) with a 2D-friction point (`jenkins-2d`) has a vector m = (m₁, m₂) in
//! the unit disc (T(0) = μN(0)·m along t₁, t₂): two variables. The box search runs on
//! s ∈ [−1, 1]² mapped onto the disc by the elliptical grid map
//! m₁ = s₁ √(1 − s₂²/2), m₂ = s₂ √(1 − s₁²/2) ([`square_to_disc`]: smooth, one-to-one, the
//! square's edges onto the circle, s = (±1, 0) onto the limit states m = (±1, 0)), with the
//! gradient by the chain rule through it, and the moves to effective initial states mapped
//! back ([`disc_to_square`]). The starts of a 2D group are those of a 1D one placed on t₁
//! (m = (±1, 0) for the corners, the limit curves' states), plus, per 2D group, the two points
//! m = (0, ±1) on t₂ with every other group at 0. The 1D points of a group with 2D points share
//! its m₁ only. Cost: a 2D group adds one variable (one more sensitivity solve per evaluation
//! where it acts) and two starts per bound.
//!
//! The two-point method (paper §3.3, Eqs. 14-15) solves only the corners m = ±1 on every
//! side; the paper leaves the general search open (§3.3, §5). Here each bound is a box-
//! constrained optimisation ([`minimise_in_box`]: projected quasi-Newton) of A(m), where every
//! evaluation is a Newton solve of the harmonic balance at the frequency with that m, and the
//! gradient dA/dm comes from the implicit-function theorem ([`amplitude_sensitivity`]: one
//! extra solve with the Jacobian per acting group). Contacts that slip or separate somewhere in
//! the period forget their m (their gradient is exactly 0), so their m is not moved: the
//! search runs, in effect, over the sides or points that stick at the current iterate.
//!
//! A contact's m acts only within the range where the contact, started at T(0) = mμN(0), stays
//! stuck: beyond it the contact slips in the first periods of the march and then sticks with
//! its slider set by that slip, the same state as the march started at the range's edge
//! (T(0)/μN(0) of the steady state, [`AmplitudeSensitivity::effective`]). Such a state is
//! re-solved at that edge m, where the gradient is the one-sided derivative into the range, and
//! the optimiser takes the edge as the bound of that m ([`minimise_in_box`] moves to the point
//! an evaluation stands for). The limit curves m = ±1 are such states: the two-point method
//! takes the two ends of the stuck side's range.
//!
//! A(m) is only piecewise smooth (flat in the m of a contact once it slips) and can have several
//! local extrema, so each bound is sought from several starts: the corners of the box (all 2^k
//! of them up to k = 4, the two uniform corners beyond; with one m per point also the corners of
//! the sides' box, each side uniformly at ±1), the two limit curves' solutions, the
//! best and worst scanned cases of the bound scan at that frequency, and the optimum of the
//! previous grid frequency, and the centre m = 0 (warm start along the grid; the grid is cut into [`CHUNKS`]
//! stretches solved in parallel, so results do not depend on the thread count). Every state
//! solved on the way is a steady state of the structure, so the reported bound is the best
//! amplitude among all of them. Newton for a new m starts from the solved state with the
//! nearest m, and walks there in [`HOMOTOPY_STEPS`] steps of m when the direct solve fails.
//!
//! Cost: one point solver is built per stretch of the grid and per peak, and reused for every
//! evaluation there: only the contacts' initial states change between Newton solves
//! ([`HbmSystem::set_initial_states`](crate::hbm::HbmSystem::set_initial_states)), so the
//! operator, its Jacobian pattern and symbolic factorisation, the AFT plans and the arc-length
//! scaling (42 linear solves over the range) are built once, not once per evaluation. Each
//! evaluation costs one Newton solve and one extra solve per acting group.

use rayon::prelude::*;

use crate::analysis::frf::{FrfPoint, PointSolver};
use crate::contact::ContactState;
use crate::model::Problem;
use crate::numerics::box_minimize::{minimise_in_box, BoxSettings};

use super::case::LimitCase;
use super::grid::{GridPoint, GridSolution};
use super::peak::Peak;
use super::sensitivity::{amplitude_sensitivity_of, AmplitudeSensitivity, StateVariable};

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

/// Stretches of the grid solved in parallel (each warm-started along itself).
pub const CHUNKS: usize = 8;

/// Steps of m in which a state is walked to a new m when Newton from the nearest solved state
/// fails.
pub const HOMOTOPY_STEPS: usize = 4;

/// Which initial states the envelope varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvelopeMode {
    /// One m per damper side (every point of a side shares it).
    Sides,
    /// One m per contact point.
    Points,
}

impl EnvelopeMode {
    /// The groups of contacts sharing one m: names and contact indices.
    pub fn groups(self, problem: &Problem) -> (Vec<String>, Vec<Vec<usize>>) {
        match self {
            EnvelopeMode::Sides => problem
                .sides
                .iter()
                .map(|s| (s.name.clone(), s.contacts.clone()))
                .unzip(),
            EnvelopeMode::Points => problem
                .contacts
                .iter()
                .enumerate()
                .map(|(c, k)| (k.name.clone(), vec![c]))
                .unzip(),
        }
    }
}

/// One bound of the envelope: the amplitude and the state attaining it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeBound {
    /// First-harmonic amplitude (m).
    pub amplitude: f64,
    /// m of each search variable attaining it: one per group (side or point), two (m₁, m₂)
    /// for a group with 2D-friction points ([`Envelope::groups`] names them).
    pub m: Vec<f64>,
    /// Contact states there.
    pub states: Vec<ContactState>,
    /// Full Fourier coefficients of that state (not written to files).
    #[serde(skip)]
    pub coefficients: Vec<f64>,
}

/// The envelope at one frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopePoint {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Smallest amplitude of each output DOF (`None`: no state could be solved).
    pub min: Vec<Option<EnvelopeBound>>,
    /// Largest amplitude of each output DOF.
    pub max: Vec<Option<EnvelopeBound>>,
    /// Whether each variable's m acted at some state solved here (stuck over the whole period);
    /// variables that never did were dropped from the search at this frequency.
    pub acting: Vec<bool>,
    /// Newton solves (each with its sensitivity) spent here.
    pub solves: usize,
}

/// The envelope at a limit curve's resonance peak.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeAtPeak {
    /// Limit curve whose peak frequency this is.
    pub case: String,
    /// The limit curve's peak amplitude (m).
    pub limit_amplitude: f64,
    /// The envelope there.
    pub point: EnvelopePoint,
}

/// Where and by how much the two limit curves fail to bound the envelope (first output DOF).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EnvelopeCheck {
    /// Grid frequencies compared (band and envelope both exist).
    pub compared: usize,
    /// Largest (envelope max − upper limit) / upper limit over the grid (≥ 0).
    pub max_excess_above: f64,
    /// Frequency (Hz) and m of that excess.
    pub above_at: Option<(f64, Vec<f64>)>,
    /// Largest (lower limit − envelope min) / lower limit (≥ 0).
    pub max_excess_below: f64,
    /// Frequency (Hz) and m of that excess.
    pub below_at: Option<(f64, Vec<f64>)>,
    /// Grid frequencies where the envelope max exceeds the upper limit by more than 10⁻⁶.
    pub points_above: usize,
    /// Grid frequencies where the envelope min lies below the lower limit by more than 10⁻⁶.
    pub points_below: usize,
    /// Largest envelope max at the limit peaks relative to the larger limit peak, minus 1.
    pub peak_excess_above: f64,
}

/// The envelope over the grid and at the limit peaks.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Envelope {
    /// Sides or points.
    pub mode: EnvelopeMode,
    /// Name of each search variable, the order of every `m` vector: the group's (side or
    /// contact) name for m₁, `<group>_m2` for the second component of a group with 2D points.
    pub groups: Vec<String>,
    /// One point per grid frequency.
    pub points: Vec<EnvelopePoint>,
    /// At each limit curve's peak.
    pub peaks: Vec<EnvelopeAtPeak>,
    /// How the band of the limit curves compares.
    pub check: EnvelopeCheck,
    /// Newton solves in all.
    pub solves: usize,
    /// Grid frequencies where no state could be solved (no bound).
    pub unsolved: usize,
    /// Wall time (s).
    pub elapsed_s: f64,
}

/// What the envelope search starts from at one frequency.
#[derive(Debug, Clone, Default)]
pub struct EnvelopeSeeds {
    /// (m per group or per search variable, full coefficients): states solved at this
    /// frequency, or guesses from a neighbouring frequency, each corrected by Newton first.
    pub states: Vec<(Vec<f64>, Vec<f64>)>,
    /// Further starting m vectors.
    pub starts: Vec<Vec<f64>>,
}

impl EnvelopePoint {
    /// The point at `freq_hz` where no state could be solved (k groups, `outputs` output DOFs).
    pub fn unsolved(freq_hz: f64, k: usize, outputs: usize) -> Self {
        Self {
            freq_hz,
            min: vec![None; outputs],
            max: vec![None; outputs],
            acting: vec![false; k],
            solves: 0,
        }
    }
}

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
    groups: Vec<(usize, bool)>,
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
    fn search_coordinates(&self, m: &[f64]) -> Vec<f64> {
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
    fn chain(&self, y: &[f64], gradient_m: &[f64]) -> Vec<f64> {
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
    fn second_tangent_starts(&self) -> Vec<Vec<f64>> {
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
struct Solved {
    /// Search coordinates.
    y: Vec<f64>,
    /// m per variable.
    m: Vec<f64>,
    point: FrfPoint,
    sensitivity: AmplitudeSensitivity,
}

/// Solves states at one frequency for given search coordinates y (m per variable through
/// [`SearchLayout`]), from the nearest state solved so far, with one point solver whose initial
/// states are set per evaluation.
struct Evaluator<'s, 'p> {
    solver: &'s mut PointSolver<'p>,
    layout: &'s SearchLayout,
    freq_hz: f64,
    solved: Vec<Solved>,
    /// y values whose state was kept under its effective y: (y, index in `solved`).
    aliases: Vec<(Vec<f64>, usize)>,
    solves: usize,
}

impl<'s, 'p> Evaluator<'s, 'p> {
    fn new(solver: &'s mut PointSolver<'p>, layout: &'s SearchLayout, freq_hz: f64) -> Self {
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
    fn contact_states(&mut self, m: &[f64]) -> Vec<[f64; 2]> {
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
    fn solve_from(&mut self, y: &[f64], x0: &[f64]) -> Option<usize> {
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
    fn at(&mut self, y: &[f64]) -> Option<usize> {
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
    fn extreme(&self, o: usize, sense: f64) -> Option<&Solved> {
        self.solved.iter().max_by(|a, b| {
            (sense * a.sensitivity.amplitudes[o]).total_cmp(&(sense * b.sensitivity.amplitudes[o]))
        })
    }
}

/// Corners of [−1, 1]^k: all 2^k up to k = 4, the two uniform ones beyond. (The centre is
/// added as a start too.)
fn corners(k: usize) -> Vec<Vec<f64>> {
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
fn side_corners(problem: &Problem, groups: &[Vec<usize>]) -> Vec<Vec<f64>> {
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

/// The envelope at one frequency: for every output DOF, the largest and smallest amplitude over
/// m ∈ [−1, 1]^k (k = groups; the unit disc for the m = (m₁, m₂) of a group with 2D points),
/// sought from the seeds' states and starts and the box corners. Seeds and starts give m per
/// group (along t₁: m₂ = 0 for 2D groups) or per search variable ([`SearchLayout`]).
/// Builds one point solver for `problem` and sets its initial states per evaluation (see
/// [`envelope_at_with`]); a problem whose solver cannot be built has no bound.
pub fn envelope_at(
    problem: &Problem,
    groups: &[Vec<usize>],
    freq_hz: f64,
    seeds: &EnvelopeSeeds,
    search: &BoxSettings,
) -> EnvelopePoint {
    match PointSolver::new(problem) {
        Ok(mut solver) => envelope_at_with(&mut solver, groups, freq_hz, seeds, search),
        Err(_) => EnvelopePoint::unsolved(
            freq_hz,
            SearchLayout::new(problem, groups).len(),
            problem.outputs.len(),
        ),
    }
}

/// [`envelope_at`] with a point solver already built for the problem (`solver`), reused for
/// every evaluation: only the initial states of its contacts change between Newton solves
/// ([`HbmSystem::set_initial_states`]), so its Jacobian pattern, symbolic factorisation,
/// arc-length scaling and AFT plans are built once. The results are those of a solver built
/// afresh for the problem with each m (tested). The solver's initial states are left at the
/// last evaluation's.
///
/// [`HbmSystem::set_initial_states`]: crate::hbm::HbmSystem::set_initial_states
pub fn envelope_at_with(
    solver: &mut PointSolver<'_>,
    groups: &[Vec<usize>],
    freq_hz: f64,
    seeds: &EnvelopeSeeds,
    search: &BoxSettings,
) -> EnvelopePoint {
    let problem = solver.system().problem();
    let layout = SearchLayout::new(problem, groups);
    let k = layout.len();
    let outputs = problem.outputs.len();
    // Seeds and starts: m per group (along t₁) or per variable, into search coordinates.
    let to_y = |m: &[f64]| layout.expand(m).map(|m| layout.search_coordinates(&m));
    let mut ev = Evaluator::new(solver, &layout, freq_hz);
    for (m, x) in &seeds.states {
        if let Some(y) = to_y(m) {
            ev.solve_from(&y, x);
        }
    }
    let mut starts: Vec<Vec<f64>> = seeds.states.iter().map(|(m, _)| m.clone()).collect();
    starts.extend(seeds.starts.iter().cloned());
    starts.extend(side_corners(problem, groups));
    starts.extend(corners(groups.len()));
    starts.push(vec![0.0; groups.len()]);
    let mut unique: Vec<Vec<f64>> = Vec::new();
    for y in starts
        .iter()
        .filter_map(|m| to_y(m))
        .chain(layout.second_tangent_starts())
    {
        if !unique.contains(&y) {
            unique.push(y);
        }
    }
    let (lower, upper) = (vec![-1.0; k], vec![1.0; k]);
    if !ev.solved.is_empty() {
        for o in 0..outputs {
            for sense in [1.0, -1.0] {
                let reference = ev
                    .extreme(o, sense)
                    .map_or(1.0, |s| s.sensitivity.amplitudes[o])
                    .max(f64::MIN_POSITIVE);
                for start in &unique {
                    // f = −sense·A/A_ref: minimising it maximises (sense = 1) or minimises A.
                    minimise_in_box(start, &lower, &upper, search, |y| {
                        let i = ev.at(y)?;
                        let solved = &ev.solved[i];
                        let s = &solved.sensitivity;
                        let gradient = ev.layout.chain(&solved.y, &s.gradient[o]);
                        Some((
                            -sense * s.amplitudes[o] / reference,
                            gradient.iter().map(|g| -sense * g / reference).collect(),
                            solved.y.clone(),
                        ))
                    });
                }
            }
        }
    }
    let bound = |o: usize, sense: f64| {
        ev.extreme(o, sense).map(|s| EnvelopeBound {
            amplitude: s.sensitivity.amplitudes[o],
            m: s.m.clone(),
            states: s.point.states.clone(),
            coefficients: s.point.coefficients.clone(),
        })
    };
    let acting = (0..k)
        .map(|g| ev.solved.iter().any(|s| s.sensitivity.active[g]))
        .collect();
    EnvelopePoint {
        freq_hz,
        min: (0..outputs).map(|o| bound(o, -1.0)).collect(),
        max: (0..outputs).map(|o| bound(o, 1.0)).collect(),
        acting,
        solves: ev.solves,
    }
}

/// The m of each group in a case (the first contact's m where a group's points differ).
pub fn group_states(case: &LimitCase, groups: &[Vec<usize>]) -> Vec<f64> {
    groups
        .iter()
        .map(|g| g.first().map_or(0.0, |&c| case.contact_states[c]))
        .collect()
}

/// A solved state as a seed: m per group, full coefficients, first output's amplitude (m).
type Seed = (Vec<f64>, Vec<f64>, f64);

/// The states of solved curves at one grid frequency as seeds.
fn solved_seeds(
    cases: &[(&LimitCase, &[GridSolution])],
    g: usize,
    groups: &[Vec<usize>],
) -> Vec<Seed> {
    cases
        .iter()
        .filter_map(|(case, sols)| {
            sols.get(g).and_then(|s| s.as_ref()).map(|(p, _)| {
                (
                    group_states(case, groups),
                    p.coefficients.clone(),
                    p.amplitudes.first().copied().unwrap_or(f64::NAN),
                )
            })
        })
        .collect()
}

/// The solved curves an envelope starts from: the limit curves (and scanned cases) with their
/// grid solutions, and the limit curves' peaks.
pub struct EnvelopeInputs<'a> {
    /// The limit curves on the grid (their states are seeds at every grid frequency).
    pub limits: Vec<(&'a LimitCase, &'a [GridSolution])>,
    /// The scanned cases on the grid (the largest and smallest at each frequency are seeds).
    pub scanned: Vec<(&'a LimitCase, &'a [GridSolution])>,
    /// The limit curves' resonance peaks.
    pub peaks: Vec<(&'a LimitCase, &'a Peak)>,
}

/// The envelope over the grid and at the limit curves' peaks, and how the band of the limit
/// curves (`band`, first output DOF) compares with it.
pub fn envelope(
    problem: &Problem,
    mode: EnvelopeMode,
    band: &[GridPoint],
    inputs: &EnvelopeInputs<'_>,
    search: &BoxSettings,
) -> Envelope {
    let started = std::time::Instant::now();
    let (group_names, groups) = mode.groups(problem);
    let layout = SearchLayout::new(problem, &groups);
    let names = layout.names(&group_names);
    let n = band.len();
    let chunk = n.div_ceil(CHUNKS).max(1);
    let starts: Vec<usize> = (0..n).step_by(chunk).collect();
    let points: Vec<EnvelopePoint> = starts
        .par_iter()
        .flat_map_iter(|&first| {
            let mut out: Vec<EnvelopePoint> = Vec::new();
            // One solver per stretch, reused at every frequency of it.
            let mut solver = PointSolver::new(problem).ok();
            for g in first..(first + chunk).min(n) {
                let mut seeds = EnvelopeSeeds {
                    states: solved_seeds(&inputs.limits, g, &groups)
                        .into_iter()
                        .map(|(m, x, _)| (m, x))
                        .collect(),
                    starts: Vec::new(),
                };
                // The largest and smallest scanned states at this frequency.
                let scanned = solved_seeds(&inputs.scanned, g, &groups);
                let by_amp = |a: &&Seed, b: &&Seed| a.2.total_cmp(&b.2);
                for s in [scanned.iter().max_by(by_amp), scanned.iter().min_by(by_amp)]
                    .into_iter()
                    .flatten()
                {
                    seeds.states.push((s.0.clone(), s.1.clone()));
                }
                // Warm start: the states attaining the previous frequency's bounds.
                if let Some(previous) = out.last() {
                    for b in previous.max.iter().chain(&previous.min).flatten() {
                        seeds.states.push((b.m.clone(), b.coefficients.clone()));
                    }
                }
                let freq_hz = band[g].freq_hz;
                out.push(match solver.as_mut() {
                    Some(solver) => envelope_at_with(solver, &groups, freq_hz, &seeds, search),
                    None => EnvelopePoint::unsolved(freq_hz, layout.len(), problem.outputs.len()),
                });
            }
            out
        })
        .collect();
    let peaks: Vec<EnvelopeAtPeak> = inputs
        .peaks
        .par_iter()
        .map(|(case, peak)| {
            let seeds = EnvelopeSeeds {
                states: vec![(group_states(case, &groups), peak.coefficients.clone())],
                starts: Vec::new(),
            };
            EnvelopeAtPeak {
                case: case.name.clone(),
                limit_amplitude: peak.amplitude,
                point: envelope_at(problem, &groups, peak.freq_hz, &seeds, search),
            }
        })
        .collect();
    let check = compare(band, &points, &peaks);
    let solves = points.iter().map(|p| p.solves).sum::<usize>()
        + peaks.iter().map(|p| p.point.solves).sum::<usize>();
    let unsolved = points
        .iter()
        .filter(|p| p.max.iter().any(|b| b.is_none()))
        .count();
    Envelope {
        mode,
        groups: names,
        points,
        peaks,
        check,
        solves,
        unsolved,
        elapsed_s: started.elapsed().as_secs_f64(),
    }
}

/// How the band compares with the envelope (first output DOF).
fn compare(
    band: &[GridPoint],
    points: &[EnvelopePoint],
    peaks: &[EnvelopeAtPeak],
) -> EnvelopeCheck {
    let mut c = EnvelopeCheck {
        compared: 0,
        max_excess_above: 0.0,
        above_at: None,
        max_excess_below: 0.0,
        below_at: None,
        points_above: 0,
        points_below: 0,
        peak_excess_above: 0.0,
    };
    for (g, p) in band.iter().zip(points) {
        let (Some(Some(hi)), Some(Some(lo))) = (p.max.first(), p.min.first()) else {
            continue;
        };
        if !(g.upper.is_finite() && g.lower.is_finite()) {
            continue;
        }
        c.compared += 1;
        let above = (hi.amplitude - g.upper) / g.upper;
        let below = (g.lower - lo.amplitude) / g.lower;
        if above > 1e-6 {
            c.points_above += 1;
        }
        if below > 1e-6 {
            c.points_below += 1;
        }
        if above > c.max_excess_above {
            c.max_excess_above = above;
            c.above_at = Some((g.freq_hz, hi.m.clone()));
        }
        if below > c.max_excess_below {
            c.max_excess_below = below;
            c.below_at = Some((g.freq_hz, lo.m.clone()));
        }
    }
    let limit_peak = peaks
        .iter()
        .map(|p| p.limit_amplitude)
        .fold(f64::NEG_INFINITY, f64::max);
    for p in peaks {
        if let Some(Some(hi)) = p.point.max.first() {
            c.peak_excess_above = c.peak_excess_above.max(hi.amplitude / limit_peak - 1.0);
        }
    }
    c
}
