//! The cases of a limit analysis: the initial tangential state m of every contact point, as the
//! two-point method's limit pair, as uniform, per-side or per-point intermediate cases, and as
//! the per-side combinations of the bound scan.

use crate::model::Problem;

/// An intermediate case as the scene gives it, with names resolved to indices: m per damper
/// side and per contact point. Points not named (directly or through their side) keep the
/// scene's `initial_state`; a point's own value wins over its side's.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CaseSpec {
    /// Name used in file names, column headers and legends.
    pub name: String,
    /// (side index, m) pairs.
    pub sides: Vec<(usize, f64)>,
    /// (contact index, m) pairs.
    pub contacts: Vec<(usize, f64)>,
    /// (side index, m₂) pairs: the second component of the side's 2D points.
    pub sides2: Vec<(usize, f64)>,
    /// (contact index, m₂) pairs for 2D points (a point's own value wins over its side's).
    pub contacts2: Vec<(usize, f64)>,
}

/// Initial tangential state of every contact point.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct LimitCase {
    /// Name used in file names and column headers (e.g. `m+1`, `m-0.5`, `left+0.5_right-0.5`).
    pub name: String,
    /// m ∈ [−1, 1] of each contact point, in the problem's contact order (m₁ along t₁ for a
    /// 2D point).
    pub contact_states: Vec<f64>,
    /// m₂ of each contact point (0 on 1D points) when the case sets it (`sides2`,
    /// `contacts2` of a scene's case); `None`: a 2D point starts at (m₁, 0) where the case
    /// changes its m₁ and keeps the scene's m₂ otherwise ([`Self::apply`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub second_states: Option<Vec<f64>>,
}

impl LimitCase {
    /// The same m on every contact point.
    pub fn uniform(problem: &Problem, m: f64) -> Self {
        Self {
            name: format!("m{}", signed(m)),
            contact_states: vec![m; problem.contacts.len()],
            second_states: None,
        }
    }

    /// One m per damper side (in the problem's side order), named after the sides.
    pub fn per_side(problem: &Problem, side_states: &[f64]) -> Self {
        let name = problem
            .sides
            .iter()
            .zip(side_states)
            .map(|(s, m)| format!("{}{}", s.name, signed(*m)))
            .collect::<Vec<_>>()
            .join("_");
        Self {
            name,
            contact_states: problem
                .contacts
                .iter()
                .map(|c| side_states[c.side])
                .collect(),
            second_states: None,
        }
    }

    /// The case a scene's `[[limits.cases]]` entry describes.
    pub fn from_spec(problem: &Problem, spec: &CaseSpec) -> Self {
        let mut states: Vec<f64> = problem
            .contacts
            .iter()
            .map(|c| c.law.initial_state)
            .collect();
        for &(side, m) in &spec.sides {
            for &c in &problem.sides[side].contacts {
                states[c] = m;
            }
        }
        for &(c, m) in &spec.contacts {
            states[c] = m;
        }
        let second_states = (!spec.sides2.is_empty() || !spec.contacts2.is_empty()).then(|| {
            // The rule of `apply` first, then the case's m₂ on the 2D points.
            let mut second: Vec<f64> = problem
                .contacts
                .iter()
                .zip(&states)
                .map(|(c, &m)| match &c.second_tangent {
                    Some(s) if c.law.initial_state == m => s.initial_state,
                    _ => 0.0,
                })
                .collect();
            for &(side, m2) in &spec.sides2 {
                for &c in &problem.sides[side].contacts {
                    if problem.contacts[c].second_tangent.is_some() {
                        second[c] = m2;
                    }
                }
            }
            for &(c, m2) in &spec.contacts2 {
                second[c] = m2;
            }
            second
        });
        Self {
            name: spec.name.clone(),
            contact_states: states,
            second_states,
        }
    }

    /// The m shared by every point of side `side`, or `None` if its points differ.
    pub fn side_state(&self, problem: &Problem, side: usize) -> Option<f64> {
        let mut ms = problem.sides[side]
            .contacts
            .iter()
            .map(|&c| self.contact_states[c]);
        let first = ms.next()?;
        ms.all(|m| m == first).then_some(first)
    }

    /// The problem with every contact's initial state set from the case. The case's m is
    /// along the first tangent: a 2D-friction point whose m₁ the case changes starts at
    /// m = (m, 0) (m = ±1: T(0) on the friction circle at ±t₁), unless the case sets m₂
    /// ([`Self::second_states`]).
    pub fn apply(&self, problem: &Problem) -> Problem {
        let mut p = problem.clone();
        for (i, (c, m)) in p.contacts.iter_mut().zip(&self.contact_states).enumerate() {
            if let Some(second) = &mut c.second_tangent {
                match &self.second_states {
                    Some(s) => second.initial_state = s[i],
                    None if c.law.initial_state != *m => second.initial_state = 0.0,
                    None => {}
                }
            }
            c.law.initial_state = *m;
        }
        p
    }
}

/// m as it appears in case names: `+0.5`, `-1`, `0`.
pub fn signed(m: f64) -> String {
    if m == 0.0 {
        "0".to_string()
    } else {
        format!("{m:+}")
    }
}

/// The two-point method's cases: m = +1 and m = −1 on every side.
pub fn two_point_cases(problem: &Problem) -> Vec<LimitCase> {
    vec![
        LimitCase::uniform(problem, 1.0),
        LimitCase::uniform(problem, -1.0),
    ]
}

/// Every combination of the given m values over the damper sides (values^sides cases).
pub fn scan_cases(problem: &Problem, values: &[f64]) -> Vec<LimitCase> {
    let sides = problem.sides.len();
    let mut cases = Vec::new();
    if values.is_empty() || sides == 0 {
        return cases;
    }
    let total = values.len().pow(sides as u32);
    for mut code in 0..total {
        let mut side_states = Vec::with_capacity(sides);
        for _ in 0..sides {
            side_states.push(values[code % values.len()]);
            code /= values.len();
        }
        cases.push(LimitCase::per_side(problem, &side_states));
    }
    cases
}
