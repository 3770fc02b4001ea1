//! Validation of how every body of the structure is held in the static state. A body is a
//! connected component of the stiffness and mass coupling with all contacts removed, the DOFs
//! of one contact point's damper (or body) side counted as joined (they move one material
//! point, and its friction law couples them); a free
//! body (K alone leaves it rigid-body modes, like the paper's wedge damper) is held only by
//! its contacts, and they hold it only when something presses it onto them. Two refusals
//! follow, both exact consequences of the contact law (N ≥ 0 with lift-off, |T| ≤ μN):
//!
//! * **nothing presses the body onto its contacts**: no static load on the body or on the
//!   bodies it touches through contacts, and no interference (every gap ≥ 0). The static state
//!   then has every contact at zero normal load, the friction limit μN is zero, and the body
//!   can move away from all its contacts: its static position is undetermined and the
//!   harmonic balance (which solves for it, with the 0th harmonic coupled) is singular;
//! * **the static load cannot be carried by the body's contacts** (it pulls the body off them,
//!   or pushes it along them harder than friction holds): on the body's rigid-body modes R
//!   the static balance reads Rᵀf = Σ Rᵀ(aₙ N̄ + aₜ T̄) over its contacts, with period means
//!   N̄ ≥ 0 and |T̄| ≤ μN̄; when Rᵀf lies outside that cone no steady state exists.
//!
//! Both checks apply with lift-off (the default): bilateral normal springs
//! (`effects.liftoff = false`) hold a body without pre-load. The first one also needs the 0th
//! harmonic coupled (the default): with uncoupled statics the static pre-solve from rest fixes
//! an unloaded body's position. The second one holds for the static pre-solve as well.
//!
//! Both refusals are one-sided: a body is refused only when the condition is shown (an
//! interference, a load on a neighbouring body, a self-equilibrated load on the body, or an
//! inconclusive cone test lets it through), so no scene that could be solved is refused.

use std::collections::HashMap;

use faer::prelude::Solve;
use faer::Mat;

use crate::fe::Mesh;
use crate::model::{Coupling, FeOrigin, Problem};
use crate::scene::check_model::stiffness_scale;
use crate::scene::checker::Checker;
use crate::scene::cone::{cone_membership, spans_every_direction, Membership};
use crate::scene::error::SceneError;

/// Largest body (DOFs) whose rigid-body modes are found by a dense eigen-decomposition of K on
/// the body when the model has no mesh to give them geometrically; larger bodies of models
/// without a mesh are not checked.
const DENSE_BODY_LIMIT: usize = 1000;

/// An eigenvalue of K on a body at or below this fraction of the model's stiffness scale (the
/// largest diagonal entry of K) is a rigid-body mode.
const RIGID_TOLERANCE: f64 = 1e-10;

/// A static load at or below this fraction of the largest static load counts as none (the
/// round-off of loads shared over a group's nodes); with no static load at all, every DOF is
/// unloaded.
const LOAD_TOLERANCE: f64 = 1e-12;

/// On FE meshes, an interference at most this fraction of the mesh's extent (largest side of
/// its bounding box) is round-off of the node coordinates in the meshed gap, not a pre-load.
const GAP_TOLERANCE: f64 = 1e-12;

/// Most DOF names listed in a message.
const LISTED_DOFS: usize = 6;

/// Refuses a free body that nothing presses onto its contacts, or that its static load pulls
/// off them (see the module documentation). `problem` is the unreduced problem; `points`
/// holds the DOFs of each contact point's damper side and body side (joined within a body);
/// `load_dofs` holds the DOFs of each `[[static_loads]]` entry, to name the entry that sets a
/// body's load.
pub(super) fn check_held_bodies(
    ck: &Checker,
    problem: &Problem,
    points: &[Vec<usize>],
    load_dofs: &[Vec<usize>],
) -> Result<(), SceneError> {
    if !problem.effects.contact.liftoff {
        return Ok(());
    }
    let coupled = problem.effects.coupling == Coupling::Coupled;
    let n = problem.model.n_dofs();
    let body_of = components(n, |f| {
        problem.model.stiffness.for_each_nonzero(|i, j, _| f(i, j));
        problem.model.mass.for_each_nonzero(|i, j, _| f(i, j));
        for point in points {
            for w in point.windows(2) {
                f(w[0], w[1]);
            }
        }
    });
    let n_bodies = body_of.iter().copied().max().map_or(0, |b| b + 1);
    let mut body_dofs: Vec<Vec<usize>> = vec![Vec::new(); n_bodies];
    for (d, &b) in body_of.iter().enumerate() {
        body_dofs[b].push(d);
    }
    // The bodies each contact touches, and the contacts touching each body.
    let mut contacts_of: Vec<Vec<usize>> = vec![Vec::new(); n_bodies];
    let mut touched: Vec<Vec<usize>> = Vec::with_capacity(problem.contacts.len());
    for (c, contact) in problem.contacts.iter().enumerate() {
        let mut bodies: Vec<usize> = contact.row_entries().map(|&(d, _)| body_of[d]).collect();
        bodies.sort_unstable();
        bodies.dedup();
        for &b in &bodies {
            contacts_of[b].push(c);
        }
        touched.push(bodies);
    }
    // Clusters: bodies joined through contacts. A cluster is pressed when a static load acts
    // on one of its DOFs or one of its contacts has an interference.
    let cluster_of = components(n_bodies, |f| {
        for bodies in &touched {
            for w in bodies.windows(2) {
                f(w[0], w[1]);
            }
        }
    });
    let load_scale = problem
        .static_load
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    let load_tol = LOAD_TOLERANCE * load_scale;
    let n_clusters = cluster_of.iter().copied().max().map_or(0, |c| c + 1);
    let mut pressed = vec![false; n_clusters];
    for (d, &f) in problem.static_load.iter().enumerate() {
        if f.abs() > load_tol {
            pressed[cluster_of[body_of[d]]] = true;
        }
    }
    // Meshed gaps carry the round-off of the node coordinates.
    let gap_tol = problem
        .fe
        .as_deref()
        .map_or(0.0, |fe| GAP_TOLERANCE * extent(&fe.mesh));
    for (contact, bodies) in problem.contacts.iter().zip(&touched) {
        if contact.gap < -gap_tol {
            if let Some(&b) = bodies.first() {
                pressed[cluster_of[b]] = true;
            }
        }
    }

    let k_scale = stiffness_scale(&problem.model);
    for (b, dofs) in body_dofs.iter().enumerate() {
        let contacts = &contacts_of[b];
        if contacts.is_empty() {
            // A free body without contacts is refused by the stuck-structure check.
            continue;
        }
        let loaded = dofs
            .iter()
            .any(|&d| problem.static_load[d].abs() > load_tol);
        let unpressed = coupled && !pressed[cluster_of[b]];
        if !loaded && !unpressed {
            continue;
        }
        let Some(modes) = rigid_modes(problem, dofs, RIGID_TOLERANCE * k_scale) else {
            continue;
        };
        if modes.is_empty() {
            continue;
        }
        // Each rigid-body mode's share of a row (contact displacement or load) on the body.
        let local: HashMap<usize, usize> = dofs.iter().enumerate().map(|(k, &d)| (d, k)).collect();
        let project = |row: &mut dyn Iterator<Item = (usize, f64)>| -> Vec<f64> {
            let mut p = vec![0.0; modes.len()];
            for (d, a) in row {
                if let Some(&k) = local.get(&d) {
                    for (pi, mode) in p.iter_mut().zip(&modes) {
                        *pi += mode[k] * a;
                    }
                }
            }
            p
        };
        let normal: Vec<Vec<f64>> = contacts
            .iter()
            .map(|&c| project(&mut problem.contacts[c].normal.iter().copied()))
            .collect();
        let body = BodyName::new(problem, dofs, contacts);
        if loaded {
            let resultant = project(&mut dofs.iter().map(|&d| (d, problem.static_load[d])));
            if resultant.iter().map(|v| v * v).sum::<f64>().sqrt() > load_tol {
                // What the contacts can transmit: N ≥ 0 with T = ±μN (for a 2D point, the
                // square pyramid around its friction cone, so that a load outside it is surely
                // outside the cone).
                let mut generators = Vec::with_capacity(4 * contacts.len());
                for (k, &c) in contacts.iter().enumerate() {
                    let tangents: Vec<Vec<f64>> = problem.contacts[c]
                        .tangential_rows()
                        .map(|row| project(&mut row.iter().copied()))
                        .collect();
                    let mu = problem.contacts[c].law.mu;
                    for t in friction_edges(&tangents) {
                        generators.push(
                            normal[k]
                                .iter()
                                .zip(&t)
                                .map(|(a, b)| a + mu * b)
                                .collect::<Vec<f64>>(),
                        );
                    }
                }
                if cone_membership(&generators, &resultant) == Membership::Outside {
                    return Err(ck.err(
                        load_field(load_dofs, |d| body_of[d] == b, |_| false),
                        format!(
                            "the static load on {body} cannot be carried by its contacts {}: no \
                             normal forces N ≥ 0 with tangential forces |T| ≤ μN balance it on \
                             the body's rigid-body motion (it pulls the body off its contacts, or \
                             pushes it along them harder than friction holds), so no static \
                             state exists; check the sign of the static loads, and that each \
                             contact normal points from the damper into the body",
                            body.contacts
                        ),
                    ));
                }
            }
        }
        if unpressed && spans_every_direction(&normal, modes.len()) == Membership::Outside {
            return Err(ck.err(
                load_field(
                    load_dofs,
                    |d| body_of[d] == b,
                    |d| cluster_of[body_of[d]] == cluster_of[b],
                ),
                format!(
                    "{body} is held only by its contacts {} (K alone leaves it {} rigid-body \
                     mode{}), and nothing presses it onto them: with no static load on it or on \
                     the bodies it touches, and no interference (every gap ≥ 0), every contact \
                     carries zero normal load, the friction limit μN is zero and the body is \
                     free to move off its contacts; give it a pre-load that presses it onto \
                     them (static_loads), or an interference (contacts.*.gap < 0) between \
                     contacts that clamp it",
                    body.contacts,
                    modes.len(),
                    if modes.len() == 1 { "" } else { "s" }
                ),
            ));
        }
    }
    check_static_contacts(ck, problem, load_dofs, &body_of, &body_dofs, &contacts_of)
}

/// Largest model (DOFs) on which [`check_static_contacts`] solves the static balance densely;
/// larger models are not checked.
const STATIC_DENSE_LIMIT: usize = 2000;

/// Static normal forces of this magnitude or less, relative to the static force scale (the
/// largest static load or interference force kₙ·|gap|), count as zero.
const NORMAL_TOLERANCE: f64 = 1e-9;

/// Refuses a free body that the static pre-load or the interferences push off every contact.
///
/// The static balance is solved with every contact closed and stuck (normal and tangential
/// springs kₙ, kₜ, N = kₙ(aₙ·q − gap)); the contacts left in tension (N < 0: the load pulls
/// the damper off them, or an interference on the other side pushes it away) are opened and
/// the balance solved again, until no closed contact is in tension. A free body (K alone
/// leaves it rigid-body modes) whose contacts then all carry no compression is held by
/// nothing: N = 0 on every contact, so μN = 0 and no static state exists (the harmonic
/// balance would fail with a singular matrix at its first point). Stuck tangential springs
/// hold more than friction can (|T| ≤ μN is not imposed), so a body released here is free in
/// the real problem too; a balance that does not settle is let through. Checked with lift-off
/// (the default) on models of at most [`STATIC_DENSE_LIMIT`] DOFs without open gaps.
fn check_static_contacts(
    ck: &Checker,
    problem: &Problem,
    load_dofs: &[Vec<usize>],
    body_of: &[usize],
    body_dofs: &[Vec<usize>],
    contacts_of: &[Vec<usize>],
) -> Result<(), SceneError> {
    let n = problem.model.n_dofs();
    let contacts = &problem.contacts;
    let interference = |c: usize| contacts[c].gap < 0.0;
    let load_scale = problem
        .static_load
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    let gap_scale = contacts
        .iter()
        .fold(0.0_f64, |a, c| a.max(c.law.kn * c.gap.abs()));
    let force_scale = load_scale.max(gap_scale);
    // An open gap (gap > 0) must close by the body moving onto the contact, which the stuck
    // tangential springs of this balance resist (they are anchored at the unloaded position):
    // they would hold the body off a contact it really falls onto and slides into. Not
    // checked then.
    let open_gap = contacts.iter().any(|c| c.gap > 0.0);
    if n > STATIC_DENSE_LIMIT || force_scale == 0.0 || contacts.is_empty() || open_gap {
        return Ok(());
    }
    let k_structure = {
        let mut k = Mat::<f64>::zeros(n, n);
        for (i, j, v) in problem.model.stiffness.triplets() {
            k[(i, j)] += v;
        }
        k
    };
    let tol = NORMAL_TOLERANCE * force_scale;
    let mut closed = vec![true; contacts.len()];
    let mut normal = vec![0.0; contacts.len()];
    for _ in 0..=contacts.len() {
        let mut k = k_structure.clone();
        let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| problem.static_load[i]);
        for (_, contact) in contacts.iter().enumerate().filter(|(c, _)| closed[*c]) {
            let tangential = contact.tangential_rows().map(|row| (row, contact.law.kt));
            for (rows, stiffness) in [(contact.normal.as_slice(), contact.law.kn)]
                .into_iter()
                .chain(tangential)
            {
                for &(p, ap) in rows {
                    for &(q, aq) in rows {
                        k[(p, q)] += stiffness * ap * aq;
                    }
                }
            }
            for &(p, ap) in &contact.normal {
                rhs[(p, 0)] += contact.law.kn * contact.gap * ap;
            }
        }
        // Singular: a body lost every contact (the structure is positive definite with all of
        // them stuck, checked before).
        let q = k.llt(faer::Side::Lower).ok().map(|llt| llt.solve(&rhs));
        let mut opened = false;
        for (c, contact) in contacts.iter().enumerate() {
            normal[c] = match &q {
                Some(q) if closed[c] => {
                    let v: f64 = contact.normal.iter().map(|&(d, a)| a * q[(d, 0)]).sum();
                    contact.law.kn * (v - contact.gap)
                }
                _ => 0.0,
            };
            if closed[c] && normal[c] < -tol {
                closed[c] = false;
                opened = true;
            }
        }
        if q.is_none() || !opened {
            break;
        }
    }
    let k_scale = stiffness_scale(&problem.model);
    for (b, dofs) in body_dofs.iter().enumerate() {
        let touching = &contacts_of[b];
        let pressed: Vec<usize> = touching
            .iter()
            .copied()
            .filter(|&c| closed[c] && normal[c] > tol)
            .collect();
        let body_loaded = dofs
            .iter()
            .any(|&d| problem.static_load[d].abs() > LOAD_TOLERANCE * load_scale);
        // A loaded body with pressed contacts is left to the cone test of the caller; a body
        // that only loads on other bodies press (or release) is not judged here: the stuck
        // balance cannot show that they do not squeeze it.
        if touching.is_empty()
            || (!pressed.is_empty() && body_loaded)
            || (!body_loaded && load_scale > 0.0)
        {
            continue;
        }
        let Some(modes) = rigid_modes(problem, dofs, RIGID_TOLERANCE * k_scale) else {
            continue;
        };
        if modes.is_empty() {
            continue;
        }
        if !pressed.is_empty() {
            // Unloaded body: its pressed contacts must balance each other on its rigid-body
            // motion, some N > 0 with |T| ≤ μN summing to zero; otherwise friction cannot keep
            // the interference from pushing the body out.
            let local: HashMap<usize, usize> =
                dofs.iter().enumerate().map(|(k, &d)| (d, k)).collect();
            let project = |rows: &[(usize, f64)]| -> Vec<f64> {
                modes
                    .iter()
                    .map(|mode| {
                        rows.iter()
                            .filter_map(|&(d, a)| local.get(&d).map(|&k| mode[k] * a))
                            .sum()
                    })
                    .collect()
            };
            let mut generators: Vec<Vec<f64>> = Vec::new();
            for &c in &pressed {
                let nn = project(&contacts[c].normal);
                let tangents: Vec<Vec<f64>> = contacts[c].tangential_rows().map(project).collect();
                for tt in friction_edges(&tangents) {
                    generators.push(
                        nn.iter()
                            .zip(&tt)
                            .map(|(a, t)| a + contacts[c].law.mu * t)
                            .collect(),
                    );
                }
            }
            let balanced = (0..generators.len()).any(|k| {
                let others: Vec<Vec<f64>> = generators
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != k)
                    .map(|(_, g)| g.clone())
                    .collect();
                let target: Vec<f64> = generators[k].iter().map(|v| -v).collect();
                cone_membership(&others, &target) != Membership::Outside
            });
            if balanced {
                continue;
            }
        }
        let body = BodyName::new(problem, dofs, touching);
        let loaded = body_loaded;
        let field = if loaded {
            load_field(load_dofs, |d| body_of[d] == b, |_| true)
        } else {
            touching
                .iter()
                .chain(&(0..contacts.len()).collect::<Vec<_>>())
                .find(|&&c| interference(c))
                .map_or_else(|| "contacts".to_string(), |&c| format!("contacts[{c}].gap"))
        };
        let cause = if loaded {
            "the static load pulls it off them"
        } else {
            "the interferences (gap < 0) push it off them and nothing presses it back"
        };
        return Err(ck.err(
            field,
            format!(
                "{body} is held only by its contacts {} and {cause}: with the contacts closed \
                 and stuck the static balance puts them in tension (N < 0), and with those \
                 contacts opened none is left pressed, so μN = 0 everywhere and no static state \
                 exists; a pre-load must press the body onto its contacts (check the sign of \
                 the static loads and that each contact normal points from the damper into the \
                 body), or interferences must clamp it from opposite sides",
                body.contacts
            ),
        ));
    }
    Ok(())
}

/// A body as named in messages: its DOFs (the first few of a large one) and its contacts.
struct BodyName {
    /// "the body with DOFs xD, yD" or "the body of 412 DOFs (1.x, 1.y, ...)".
    dofs: String,
    /// "`left`, `right`" (the first few of many).
    contacts: String,
}

impl BodyName {
    /// The name of the body with `dofs`, touched by `contacts`.
    fn new(problem: &Problem, dofs: &[usize], contacts: &[usize]) -> Self {
        let names = &problem.model.dof_names;
        let dof_list = |k: usize| {
            dofs.iter()
                .take(k)
                .map(|&d| names[d].as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let dofs = if dofs.len() <= LISTED_DOFS {
            format!("the body with DOFs {}", dof_list(LISTED_DOFS))
        } else {
            format!(
                "the body of {} DOFs ({}, ...)",
                dofs.len(),
                dof_list(LISTED_DOFS)
            )
        };
        let mut listed: Vec<String> = contacts
            .iter()
            .take(LISTED_DOFS)
            .map(|&c| format!("`{}`", problem.contacts[c].name))
            .collect();
        if contacts.len() > LISTED_DOFS {
            listed.push(format!("... ({} points)", contacts.len()));
        }
        BodyName {
            dofs,
            contacts: listed.join(", "),
        }
    }
}

impl std::fmt::Display for BodyName {
    /// The DOF part of the name.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.dofs)
    }
}

/// The field blamed for a body's static load: the first `[[static_loads]]` entry (DOFs
/// `load_dofs[i]`) on a DOF of the body (`on_body`) as `static_loads[i].value`, else the first
/// on a DOF for which `near` holds (the bodies it touches), else `static_loads`.
fn load_field(
    load_dofs: &[Vec<usize>],
    on_body: impl Fn(usize) -> bool,
    near: impl Fn(usize) -> bool,
) -> String {
    load_dofs
        .iter()
        .position(|entry| entry.iter().any(|&d| on_body(d)))
        .or_else(|| {
            load_dofs
                .iter()
                .position(|entry| entry.iter().any(|&d| near(d)))
        })
        .map_or_else(
            || "static_loads".to_string(),
            |i| format!("static_loads[{i}].value"),
        )
}

/// The largest side (m) of the bounding box of a mesh's nodes.
fn extent(mesh: &Mesh) -> f64 {
    (0..3)
        .map(|a| {
            let (lo, hi) = mesh
                .nodes
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), n| {
                    (lo.min(n.coords[a]), hi.max(n.coords[a]))
                });
            if hi >= lo {
                hi - lo
            } else {
                0.0
            }
        })
        .fold(0.0_f64, f64::max)
}

/// Connected components of `n` nodes joined by the edges `edges` reports (called once with a
/// sink `f(i, j)`); the component of each node, numbered in order of first node.
fn components(n: usize, edges: impl FnOnce(&mut dyn FnMut(usize, usize))) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    edges(&mut |i, j| {
        let (a, b) = (root(&mut parent, i), root(&mut parent, j));
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    });
    let mut label = vec![usize::MAX; n];
    let mut next = 0;
    let mut out = vec![0; n];
    for i in 0..n {
        let r = root(&mut parent, i);
        if label[r] == usize::MAX {
            label[r] = next;
            next += 1;
        }
        out[i] = label[r];
    }
    out
}

/// An orthonormal basis of the rigid-body modes of the body with `dofs` (each mode one value
/// per body DOF, in `dofs` order): the null space of K on the body, eigenvalues at or below
/// `tol` (N/m). From the mesh geometry (translations and rotations, kept where K does not
/// resist them) for FE models with a mesh, else from a dense eigen-decomposition of K on the
/// body up to [`DENSE_BODY_LIMIT`] DOFs; `None` when neither applies or the eigen solver
/// fails (the body is then not checked).
fn rigid_modes(problem: &Problem, dofs: &[usize], tol: f64) -> Option<Vec<Vec<f64>>> {
    let k = &problem.model.stiffness;
    if let Some(fe) = problem.fe.as_deref().filter(|fe| !fe.reduced) {
        let candidates = geometric_modes(fe, dofs)?;
        if candidates.is_empty() {
            return Some(Vec::new());
        }
        // G = Cᵀ K C on the candidates; its null space gives the rigid combinations.
        let n = problem.model.n_dofs();
        let kc: Vec<Vec<f64>> = candidates
            .iter()
            .map(|c| {
                let mut x = vec![0.0; n];
                for (&d, &v) in dofs.iter().zip(c) {
                    x[d] = v;
                }
                let mut y = vec![0.0; n];
                k.mul_add(1.0, &x, &mut y);
                dofs.iter().map(|&d| y[d]).collect()
            })
            .collect();
        let g = Mat::from_fn(candidates.len(), candidates.len(), |i, j| {
            candidates[i].iter().zip(&kc[j]).map(|(a, b)| a * b).sum()
        });
        let (values, vectors) = sym_eigen(&g)?;
        return Some(
            values
                .iter()
                .enumerate()
                .filter(|(_, &v)| v <= tol)
                .map(|(m, _)| {
                    (0..dofs.len())
                        .map(|r| {
                            candidates
                                .iter()
                                .enumerate()
                                .map(|(c, cand)| cand[r] * vectors[(c, m)])
                                .sum()
                        })
                        .collect()
                })
                .collect(),
        );
    }
    if dofs.len() > DENSE_BODY_LIMIT {
        return None;
    }
    let kb = k.submatrix(dofs).to_dense();
    // A Cholesky factorisation of K − tol·I on the body proves it held, at a fraction of the
    // cost of the eigen-decomposition.
    let shifted = Mat::from_fn(kb.nrows(), kb.ncols(), |i, j| {
        kb[(i, j)] - if i == j { tol } else { 0.0 }
    });
    if shifted.llt(faer::Side::Lower).is_ok() {
        return Some(Vec::new());
    }
    let (values, vectors) = sym_eigen(&kb)?;
    Some(
        values
            .iter()
            .enumerate()
            .filter(|(_, &v)| v <= tol)
            .map(|(m, _)| (0..dofs.len()).map(|r| vectors[(r, m)]).collect())
            .collect(),
    )
}

/// The rigid motions of the body's nodes (three translations and three rotations about the
/// body's centroid, on translation and rotation DOFs alike), orthonormalised, those that vanish
/// on the body's DOFs left out; `None` when a DOF has no node in the mesh.
fn geometric_modes(fe: &FeOrigin, dofs: &[usize]) -> Option<Vec<Vec<f64>>> {
    let coords: HashMap<u64, [f64; 3]> = fe.mesh.nodes.iter().map(|n| (n.id, n.coords)).collect();
    let mut points = Vec::with_capacity(dofs.len());
    for &d in dofs {
        let dof = fe.dofs.dof(d)?;
        points.push((dof.direction, *coords.get(&dof.node)?));
    }
    let mut centroid = [0.0; 3];
    for (_, x) in &points {
        for a in 0..3 {
            centroid[a] += x[a] / points.len() as f64;
        }
    }
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for candidate in 0..6 {
        let axis = candidate % 3;
        let rotation = candidate >= 3;
        let mut v: Vec<f64> = points
            .iter()
            .map(|(direction, x)| {
                let k = direction.axis();
                match (rotation, direction.is_translation()) {
                    (false, true) => f64::from(u8::from(k == axis)),
                    (false, false) => 0.0,
                    (true, true) => {
                        // (e_axis × (x − centroid))_k
                        let r = [x[0] - centroid[0], x[1] - centroid[1], x[2] - centroid[2]];
                        let e = |i: usize| f64::from(u8::from(i == axis));
                        let cross = [
                            e(1) * r[2] - e(2) * r[1],
                            e(2) * r[0] - e(0) * r[2],
                            e(0) * r[1] - e(1) * r[0],
                        ];
                        cross[k]
                    }
                    (true, false) => f64::from(u8::from(k == axis)),
                }
            })
            .collect();
        let original: f64 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if original == 0.0 {
            continue;
        }
        for _ in 0..2 {
            for b in &basis {
                let p: f64 = b.iter().zip(&v).map(|(a, c)| a * c).sum();
                for (vi, bi) in v.iter_mut().zip(b) {
                    *vi -= p * bi;
                }
            }
        }
        let left: f64 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if left > 1e-8 * original {
            basis.push(v.iter().map(|x| x / left).collect());
        }
    }
    Some(basis)
}

/// Eigen-decomposition of a small dense symmetric matrix (lower triangle read): eigenvalues
/// ascending and orthonormal eigenvectors (columns), by faer's tridiagonal QR algorithm at
/// every size (its divide-and-conquer path loses accuracy in the eigenvectors); `None` if the
/// solver fails.
fn sym_eigen(a: &Mat<f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::{
        self_adjoint_evd, self_adjoint_evd_scratch, ComputeEigenvectors, SelfAdjointEvdParams,
    };
    let n = a.nrows();
    let mut params: faer::Spec<SelfAdjointEvdParams, f64> = Default::default();
    params.config.recursion_threshold = usize::MAX;
    let req = self_adjoint_evd_scratch::<f64>(n, ComputeEigenvectors::Yes, faer::Par::Seq, params);
    let mut mem = MemBuffer::try_new(req).ok()?;
    let mut s = faer::diag::Diag::<f64>::zeros(n);
    let mut u = Mat::<f64>::zeros(n, n);
    self_adjoint_evd(
        a.as_ref(),
        s.as_mut(),
        Some(u.as_mut()),
        faer::Par::Seq,
        MemStack::new(&mut mem),
        params,
    )
    .ok()?;
    let sv = s.column_vector();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| sv[x].total_cmp(&sv[y]));
    let values = order.iter().map(|&i| sv[i]).collect();
    let vectors = Mat::from_fn(n, n, |i, c| u[(i, order[c])]);
    Some((values, vectors))
}

/// The tangential edge directions of a contact's friction pyramid, from its projected tangent
/// rows: ±t for a 1D point; the four corners ±t₁ ± t₂ of the square around the friction circle
/// for a 2D point (a pyramid that contains the cone, so a load it cannot carry no cone can).
fn friction_edges(tangents: &[Vec<f64>]) -> Vec<Vec<f64>> {
    match tangents {
        [t] => vec![t.clone(), t.iter().map(|v| -v).collect()],
        [t1, t2] => [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
            .iter()
            .map(|&(a, b)| t1.iter().zip(t2).map(|(x, y)| a * x + b * y).collect())
            .collect(),
        _ => Vec::new(),
    }
}
