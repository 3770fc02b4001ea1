//! Validation of the contact set: every `[[contacts]]` entry (DOFs, frame, Jenkins law) and
//! every `[[contact_patches]]` entry of an FE mesh built into [`ContactPoint`]s, grouped into
//! the [`DamperSide`]s they belong to.

use crate::contact::{ContactPoint, DamperSide, JenkinsLaw, SecondTangent};
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::fe_input::{self, FeStructure};
use crate::scene::schema::{ContactSpec, Scene};

/// The contact points of the scene, `[[contacts]]` first and then the points of each
/// `[[contact_patches]]` entry, with their damper sides in order of first appearance.
/// `stiffness_scale` (N/m, the largest diagonal entry of K) bounds every kₜ and kₙ (see
/// [`Checker::contact_stiffness`]).
pub(super) fn contact_set(
    scene: &Scene,
    ck: &Checker,
    dofs: &DofNames,
    fe: Option<&FeStructure>,
    stiffness_scale: f64,
) -> Result<(Vec<ContactPoint>, Vec<DamperSide>), SceneError> {
    if scene.contacts.is_empty() && scene.contact_patches.is_empty() {
        return Err(ck.err(
            "contacts",
            "the contact set is empty: a friction analysis needs at least one [[contacts]] \
             entry or [[contact_patches]] entry",
        ));
    }
    let mut contacts = Vec::new();
    let mut sides: Vec<DamperSide> = Vec::new();
    for (ci, c) in scene.contacts.iter().enumerate() {
        let point = contact_point(
            ck,
            ci,
            c,
            &scene.contacts[..ci],
            dofs,
            &mut sides,
            stiffness_scale,
        )?;
        contacts.push(point);
    }

    for (pi, p) in scene.contact_patches.iter().enumerate() {
        let f = |name: &str| format!("contact_patches[{pi}].{name}");
        ck.name(&f("side"), &p.side)?;
        ck.contact_stiffness(&f("kt"), p.kt, stiffness_scale)?;
        ck.contact_stiffness(&f("kn"), p.kn, stiffness_scale)?;
        ck.friction(&f("mu"), p.mu)?;
        ck.finite(&f("gap"), p.gap)?;
        ck.positive(&f("tolerance"), p.tolerance)?;
        ck.initial_state(&f("initial_state"), p.initial_state)?;
        ck.finite(&f("initial_state2"), p.initial_state2)?;
        if !p.law.is_2d() && p.initial_state2 != 0.0 {
            return Err(ck.err(
                f("initial_state2"),
                "only a `law = \"jenkins-2d\"` patch has a second initial-state component",
            ));
        }
        check_in_disc(ck, &f("initial_state2"), p.initial_state, p.initial_state2)?;
        let Some(structure) = fe else {
            return Err(ck.err(
                format!("contact_patches[{pi}]"),
                "contact patches need an FE mesh (`model.mesh`)",
            ));
        };
        let side = side_index(&mut sides, &p.side);
        let points = fe_input::patch_contacts(
            ck.file,
            &format!("contact_patches[{pi}]"),
            structure,
            p,
            side,
        )?;
        for point in points {
            if contacts.iter().any(|c: &ContactPoint| c.name == point.name) {
                return Err(ck.err(
                    f("side"),
                    format!("contact point name `{}` is already used", point.name),
                ));
            }
            sides[side].contacts.push(contacts.len());
            contacts.push(point);
        }
    }
    Ok((contacts, sides))
}

/// Contact `ci` of `[[contacts]]` (the `earlier` ones are checked for a name clash), added to
/// its damper side in `sides`; its kₜ and kₙ are bounded by `stiffness_scale` (N/m).
fn contact_point(
    ck: &Checker,
    ci: usize,
    c: &ContactSpec,
    earlier: &[ContactSpec],
    dofs: &DofNames,
    sides: &mut Vec<DamperSide>,
    stiffness_scale: f64,
) -> Result<ContactPoint, SceneError> {
    let f = |name: &str| format!("contacts[{ci}].{name}");
    ck.name(&f("name"), &c.name)?;
    if earlier.iter().any(|o| o.name == c.name) {
        return Err(ck.err(f("name"), format!("duplicate contact name `{}`", c.name)));
    }
    if c.side.as_deref().is_some_and(|s| s.trim().is_empty()) {
        return Err(ck.err(
            f("side"),
            "must not be empty (omit it to use the contact name)",
        ));
    }
    let dim = c.damper.len();
    if dim == 0 {
        return Err(ck.err(f("damper"), "must list the damper point's DOFs"));
    }
    if !c.body.is_empty() && c.body.len() != dim {
        return Err(ck.err(
            f("body"),
            format!("has {} DOFs but `damper` has {dim}", c.body.len()),
        ));
    }
    // The rows of the DOFs listed in `damper` or `body`.
    let rows = |list: &str, names: &[String]| -> Result<Vec<usize>, SceneError> {
        names
            .iter()
            .enumerate()
            .map(|(i, d)| ck.dof(&format!("contacts[{ci}].{list}[{i}]"), d, dofs))
            .collect()
    };
    let damper_idx = rows("damper", &c.damper)?;
    let body_idx = rows("body", &c.body)?;
    for (list, idx) in [("damper", &damper_idx), ("body", &body_idx)] {
        for (i, d) in idx.iter().enumerate() {
            if idx[..i].contains(d) {
                return Err(ck.err(
                    format!("contacts[{ci}].{list}[{i}]"),
                    format!("DOF `{}` is listed twice in the same point", dofs[*d]),
                ));
            }
        }
    }
    if let Some(i) = body_idx.iter().position(|b| damper_idx.contains(b)) {
        return Err(ck.err(
            format!("contacts[{ci}].body[{i}]"),
            format!(
                "DOF `{}` is also a DOF of the damper point; the damper and the body \
                 must use distinct DOFs",
                dofs[body_idx[i]]
            ),
        ));
    }
    let (t, nv) = frame(ck, ci, c, dim)?;
    let kt = ck.contact_stiffness(&f("kt"), c.kt, stiffness_scale)?;
    let kn = ck.contact_stiffness(&f("kn"), c.kn, stiffness_scale)?;
    let mu = ck.friction(&f("mu"), c.mu)?;
    let gap = ck.finite(&f("gap"), c.gap)?;
    let m = ck.initial_state(&f("initial_state"), c.initial_state)?;
    let second = second_tangent(ck, ci, c, &t, &nv)?;
    let mut tangential = Vec::new();
    let mut normal = Vec::new();
    let mut tangential2 = Vec::new();
    for d in 0..dim {
        push_coefficient(&mut tangential, damper_idx[d], t[d]);
        push_coefficient(&mut normal, damper_idx[d], nv[d]);
        if let Some(t2) = &second {
            push_coefficient(&mut tangential2, damper_idx[d], t2[d]);
        }
        if let Some(&b) = body_idx.get(d) {
            push_coefficient(&mut tangential, b, -t[d]);
            push_coefficient(&mut normal, b, -nv[d]);
            if let Some(t2) = &second {
                push_coefficient(&mut tangential2, b, -t2[d]);
            }
        }
    }
    let side = side_index(sides, &c.side_name());
    sides[side].contacts.push(ci);
    Ok(ContactPoint {
        name: c.name.clone(),
        side,
        tangential,
        normal,
        gap,
        law: JenkinsLaw {
            kt,
            kn,
            mu,
            initial_state: m,
        },
        second_tangent: second.map(|_| SecondTangent {
            row: tangential2,
            initial_state: c.initial_state2,
        }),
        resolution: c.law.time_resolution(),
    })
}

/// The unit second tangent t₂ of a `jenkins-2d` contact `ci` with unit tangent `t` and normal
/// `nv` (3 components each): `tangent2` normalised, or n × t; None for a `jenkins-1d` point.
/// Refuses a 2D law on a point without 3 DOFs, a zero or non-perpendicular t₂, a zero normal
/// with no `tangent2`, and an initial state (m₁, m₂) outside the unit disc.
fn second_tangent(
    ck: &Checker,
    ci: usize,
    c: &ContactSpec,
    t: &[f64],
    nv: &[f64],
) -> Result<Option<Vec<f64>>, SceneError> {
    let f = |name: &str| format!("contacts[{ci}].{name}");
    if !c.law.is_2d() {
        if c.tangent2.is_some() {
            return Err(ck.err(
                f("tangent2"),
                "only a `law = \"jenkins-2d\"` point has a second tangent",
            ));
        }
        if c.initial_state2 != 0.0 {
            return Err(ck.err(
                f("initial_state2"),
                "only a `law = \"jenkins-2d\"` point has a second initial-state component",
            ));
        }
        return Ok(None);
    }
    if t.len() != 3 {
        return Err(ck.err(
            f("law"),
            format!(
                "`jenkins-2d` friction needs a 3D point (3 DOFs in `damper`), this point has {}: \
                 a planar model uses `jenkins-1d`",
                t.len()
            ),
        ));
    }
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let t2 = match &c.tangent2 {
        Some(t2) => {
            if t2.len() != 3 {
                return Err(ck.err(
                    f("tangent2"),
                    format!("has {} components but the point has 3 DOFs", t2.len()),
                ));
            }
            for (i, x) in t2.iter().enumerate() {
                ck.finite(&format!("contacts[{ci}].tangent2[{i}]"), *x)?;
            }
            let len = norm(t2);
            if len == 0.0 {
                return Err(ck.err(f("tangent2"), "must not be the zero vector"));
            }
            let t2: Vec<f64> = t2.iter().map(|x| x / len).collect();
            for (name, other) in [("tangent", t), ("normal", nv)] {
                let d = dot(&t2, other);
                if d.abs() > 1e-9 {
                    return Err(ck.err(
                        f("tangent2"),
                        format!("must be perpendicular to `{name}` (t₂·{name} = {d:.3e})"),
                    ));
                }
            }
            t2
        }
        None => {
            if norm(nv) == 0.0 {
                return Err(ck.err(
                    f("tangent2"),
                    "is needed when `normal` is the zero vector (the default t₂ = n × t needs a normal)",
                ));
            }
            vec![
                nv[1] * t[2] - nv[2] * t[1],
                nv[2] * t[0] - nv[0] * t[2],
                nv[0] * t[1] - nv[1] * t[0],
            ]
        }
    };
    ck.finite(&f("initial_state2"), c.initial_state2)?;
    check_in_disc(ck, &f("initial_state2"), c.initial_state, c.initial_state2)?;
    Ok(Some(t2))
}

/// The unit tangent and normal (one component per point DOF, `dim` of them) of contact `ci`,
/// given by `angle_deg` (2D) or by `tangent` and `normal` (normalised here, must be
/// perpendicular).
fn frame(
    ck: &Checker,
    ci: usize,
    c: &ContactSpec,
    dim: usize,
) -> Result<(Vec<f64>, Vec<f64>), SceneError> {
    let f = |name: &str| format!("contacts[{ci}].{name}");
    match (c.angle_deg, &c.tangent, &c.normal) {
        (Some(a), None, None) => {
            ck.finite(&f("angle_deg"), a)?;
            if dim != 2 {
                return Err(ck.err(
                    f("angle_deg"),
                    format!("a frame by angle needs 2 DOFs per point, this point has {dim}"),
                ));
            }
            let r = a.to_radians();
            Ok((vec![r.cos(), r.sin()], vec![-r.sin(), r.cos()]))
        }
        (None, Some(t), Some(nn)) => {
            for (name, v) in [("tangent", t), ("normal", nn)] {
                if v.len() != dim {
                    return Err(ck.err(
                        f(name),
                        format!("has {} components but the point has {dim} DOFs", v.len()),
                    ));
                }
                for (i, x) in v.iter().enumerate() {
                    ck.finite(&format!("contacts[{ci}].{name}[{i}]"), *x)?;
                }
            }
            let tn = t.iter().map(|x| x * x).sum::<f64>().sqrt();
            if tn == 0.0 {
                return Err(ck.err(f("tangent"), "must not be the zero vector"));
            }
            let nn_norm = nn.iter().map(|x| x * x).sum::<f64>().sqrt();
            let t: Vec<f64> = t.iter().map(|x| x / tn).collect();
            let nn: Vec<f64> = if nn_norm > 0.0 {
                nn.iter().map(|x| x / nn_norm).collect()
            } else {
                nn.clone()
            };
            let dot: f64 = t.iter().zip(&nn).map(|(a, b)| a * b).sum();
            if dot.abs() > 1e-9 {
                return Err(ck.err(
                    f("normal"),
                    format!("must be perpendicular to `tangent` (t·n = {dot:.3e})"),
                ));
            }
            Ok((t, nn))
        }
        _ => Err(ck.err(
            f("angle_deg"),
            "give the frame either by `angle_deg` or by both `tangent` and `normal`",
        )),
    }
}

/// The index of damper side `name` in `sides`, appending it (with no contact yet) when new.
fn side_index(sides: &mut Vec<DamperSide>, name: &str) -> usize {
    match sides.iter().position(|s| s.name == name) {
        Some(s) => s,
        None => {
            sides.push(DamperSide {
                name: name.to_string(),
                contacts: Vec::new(),
            });
            sides.len() - 1
        }
    }
}

/// Adds `value` on `dof` to a sparse coefficient row (merging repeated DOFs, skipping zeros).
fn push_coefficient(row: &mut Vec<(usize, f64)>, dof: usize, value: f64) {
    if value == 0.0 {
        return;
    }
    match row.iter_mut().find(|(d, _)| *d == dof) {
        Some((_, v)) => *v += value,
        None => row.push((dof, value)),
    }
}

/// Largest |gap| relative to the model's displacement scale, the largest load (static or
/// harmonic amplitude, N) over the stiffness scale (largest diagonal entry of K, N/m): a gap
/// that much larger than any displacement the loads can cause never closes (or, as an
/// interference, swamps every other force).
pub const MAX_GAP_RATIO: f64 = 1e6;

/// Refuses a contact gap out of proportion to the model's displacement scale (see
/// [`MAX_GAP_RATIO`]); models without loads or stiffness set no bound.
pub(super) fn check_gap_scale(
    ck: &Checker,
    problem: &crate::model::Problem,
    fields: &[String],
) -> Result<(), SceneError> {
    let force = problem
        .static_load
        .iter()
        .map(|f| f.abs())
        .chain(problem.harmonic_loads.iter().map(|h| h.cos.hypot(h.sin)))
        .fold(0.0_f64, f64::max);
    let k = crate::scene::check_model::stiffness_scale(&problem.model);
    if force == 0.0 || k == 0.0 {
        return Ok(());
    }
    let scale = force / k;
    for (c, contact) in problem.contacts.iter().enumerate() {
        if contact.gap.abs() > MAX_GAP_RATIO * scale {
            return Err(ck.err(
                fields
                    .get(c)
                    .cloned()
                    .unwrap_or_else(|| "contacts".to_string()),
                format!(
                    "{:e} m is more than {MAX_GAP_RATIO:e} times the model's displacement scale \
                     ({scale:e} m: the largest load over the largest diagonal entry of K): such \
                     a gap never closes, and such an interference swamps every other force; \
                     check the units (m)",
                    contact.gap
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a 2D initial state (m₁, m₂) outside the unit disc (T(0) = μN(0)·m), naming `field`.
fn check_in_disc(ck: &Checker, field: &str, m1: f64, m2: f64) -> Result<(), SceneError> {
    let radius = m1.hypot(m2);
    if radius > 1.0 {
        return Err(ck.err(
            field,
            format!(
                "the initial state (initial_state, initial_state2) = ({m1}, {m2}) has length \
                 {radius:.6} > 1: it must lie in the unit disc (T(0) = μN(0)·m)"
            ),
        ));
    }
    Ok(())
}
