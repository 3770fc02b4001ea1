//! Validation of the `[limits]` table into the [`LimitSettings`] of the limit analysis:
//! intermediate m values and cases per damper side or contact (named without clashes), the
//! bound scan, the frequency grid, the peak window and the hysteresis loops to write.

use crate::analysis::limits::{signed, CaseSpec, HysteresisRequest, LimitSettings};
use crate::contact::{ContactPoint, DamperSide};
use crate::scene::checker::Checker;
use crate::scene::error::SceneError;
use crate::scene::schema::Scene;

/// Most initial states (damper sides or contact points) the envelope optimises over.
pub const MAX_ENVELOPE_GROUPS: usize = 64;

/// The limit-analysis settings of the scene's `[limits]` table; `None` without one. The
/// frequency range of `[analysis]` bounds the peak window and the loop frequencies.
///
/// Sides and points are those of the built contact set (`contacts`, `sides`), so that a case
/// may name a contact patch's side and its points (`<side>-<k>`, numbered from 1 as the
/// matching made them) as well as the `[[contacts]]`.
pub(super) fn limit_settings(
    scene: &Scene,
    ck: &Checker,
    (contacts, sides): (&[ContactPoint], &[DamperSide]),
) -> Result<Option<LimitSettings>, SceneError> {
    let Some(l) = &scene.limits else {
        return Ok(None);
    };
    let check_m = |field: String, m: f64| -> Result<f64, SceneError> {
        ck.finite(&field, m)?;
        if !(-1.0..=1.0).contains(&m) {
            return Err(ck.err(
                field,
                format!("an initial state m must lie in [-1, 1], got {m}"),
            ));
        }
        Ok(m)
    };
    for (name, list) in [
        ("intermediate", &l.intermediate),
        ("bound_scan", &l.bound_scan),
    ] {
        for (i, m) in list.iter().enumerate() {
            check_m(format!("limits.{name}[{i}]"), *m)?;
        }
    }
    if !(2..=100_000).contains(&l.grid_points) {
        return Err(ck.err(
            "limits.grid_points",
            format!("must be in 2..=100000, got {}", l.grid_points),
        ));
    }
    let side_names: Vec<String> = sides.iter().map(|s| s.name.clone()).collect();
    let side_count = side_names.len();
    let combinations = (l.bound_scan.len() as f64).powi(side_count as i32);
    if combinations > 4096.0 {
        return Err(ck.err(
            "limits.bound_scan",
            format!(
                "{} values on {side_count} sides make {combinations} curves; at most 4096",
                l.bound_scan.len()
            ),
        ));
    }

    // The envelope's search holds a dense k × k curvature estimate and solves k sensitivities
    // per state: k = sides or contact points is kept to what that serves.
    if let Some(mode) = l.envelope {
        // A group with 2D-friction points searches its m = (m₁, m₂) in the unit disc: two
        // variables.
        let two_d_sides = sides
            .iter()
            .filter(|side| {
                side.contacts
                    .iter()
                    .any(|&c| contacts[c].second_tangent.is_some())
            })
            .count();
        let two_d_points = contacts
            .iter()
            .filter(|c| c.second_tangent.is_some())
            .count();
        let k = match mode {
            crate::analysis::limits::EnvelopeMode::Sides => side_count + two_d_sides,
            crate::analysis::limits::EnvelopeMode::Points => contacts.len() + two_d_points,
        };
        if k > MAX_ENVELOPE_GROUPS {
            return Err(ck.err(
                "limits.envelope",
                format!(
                    "{k} initial states to optimise (one per {}); at most \
                     {MAX_ENVELOPE_GROUPS}: use `sides`",
                    if side_count == k {
                        "side"
                    } else {
                        "contact point"
                    }
                ),
            ));
        }
    }

    // Intermediate cases per side or point; names must not clash with the uniform ones.
    let mut names: Vec<String> = [1.0, -1.0]
        .iter()
        .chain(&l.intermediate)
        .map(|&m| format!("m{}", signed(m)))
        .collect();
    let contact_index = |name: &str| contacts.iter().position(|k| k.name == name);
    let mut cases = Vec::new();
    for (i, c) in l.cases.iter().enumerate() {
        let f = |name: &str| format!("limits.cases[{i}].{name}");
        if c.sides.is_empty()
            && c.contacts.is_empty()
            && c.sides2.is_empty()
            && c.contacts2.is_empty()
        {
            return Err(ck.err(
                format!("limits.cases[{i}]"),
                "give m for at least one damper side (`sides`) or contact (`contacts`)",
            ));
        }
        let side_index = |field: &str, name: &str| {
            side_names.iter().position(|s| s == name).ok_or_else(|| {
                ck.err(
                    field,
                    format!(
                        "unknown damper side `{name}` (the scene has {})",
                        side_names.join(", ")
                    ),
                )
            })
        };
        let mut side_states = Vec::new();
        for (name, &m) in &c.sides {
            let field = format!("{}.{name}", f("sides"));
            let side = side_index(&field, name)?;
            side_states.push((side, check_m(field, m)?));
        }
        let mut contact_states = Vec::new();
        for (name, &m) in &c.contacts {
            let field = format!("{}.{name}", f("contacts"));
            let contact = contact_index(name)
                .ok_or_else(|| ck.err(field.clone(), unknown_contact(name, contacts, sides)))?;
            contact_states.push((contact, check_m(field, m)?));
        }
        // m₂ of 2D points: per side (for its `jenkins-2d` points) and per `jenkins-2d` contact,
        // each (m₁, m₂) in the unit disc.
        let mut side_states2 = Vec::new();
        for (name, &m2) in &c.sides2 {
            let field = format!("{}.{name}", f("sides2"));
            let side = side_index(&field, name)?;
            let m2 = check_m(field.clone(), m2)?;
            // m₁ of each 2D point of the side: the case's for the side, or the point's own.
            let mut firsts: Vec<f64> = scene
                .contacts
                .iter()
                .filter(|k| k.law.is_2d() && &k.side_name() == name)
                .map(|k| {
                    c.contacts
                        .get(&k.name)
                        .or(c.sides.get(name))
                        .copied()
                        .unwrap_or(k.initial_state)
                })
                .collect();
            firsts.extend(
                scene
                    .contact_patches
                    .iter()
                    .filter(|p| p.law.is_2d() && &p.side == name)
                    .map(|p| c.sides.get(name).copied().unwrap_or(p.initial_state)),
            );
            if firsts.is_empty() {
                return Err(ck.err(
                    field,
                    format!("side `{name}` has no `jenkins-2d` point: m₂ needs 2D friction"),
                ));
            }
            if let Some(m1) = firsts.iter().find(|m1| m1.hypot(m2) > 1.0) {
                return Err(ck.err(
                    field,
                    format!("(m₁, m₂) = ({m1}, {m2}) lies outside the unit disc (T(0) = μN(0)·m)"),
                ));
            }
            side_states2.push((side, m2));
        }
        let mut contact_states2 = Vec::new();
        for (name, &m2) in &c.contacts2 {
            let field = format!("{}.{name}", f("contacts2"));
            let Some(contact) = contact_index(name) else {
                return Err(ck.err(field, unknown_contact(name, contacts, sides)));
            };
            let k = &contacts[contact];
            if k.second_tangent.is_none() {
                return Err(ck.err(
                    field,
                    format!("contact `{name}` is not `jenkins-2d`: m₂ needs 2D friction"),
                ));
            }
            let m2 = check_m(field.clone(), m2)?;
            let m1 = c
                .contacts
                .get(name)
                .or(c.sides.get(&sides[k.side].name))
                .copied()
                .unwrap_or(k.law.initial_state);
            if m1.hypot(m2) > 1.0 {
                return Err(ck.err(
                    field,
                    format!("(m₁, m₂) = ({m1}, {m2}) lies outside the unit disc (T(0) = μN(0)·m)"),
                ));
            }
            contact_states2.push((contact, m2));
        }
        let name = match &c.name {
            Some(n) => {
                ck.name(&f("name"), n)?;
                n.clone()
            }
            None => c
                .sides
                .iter()
                .chain(&c.contacts)
                .map(|(k, m)| format!("{k}{}", signed(*m)))
                .chain(
                    c.sides2
                        .iter()
                        .chain(&c.contacts2)
                        .map(|(k, m)| format!("{k}_m2{}", signed(*m))),
                )
                .collect::<Vec<_>>()
                .join("_"),
        };
        if names.contains(&name) {
            return Err(ck.err(
                f("name"),
                format!("case name `{name}` is already used by another curve"),
            ));
        }
        names.push(name.clone());
        cases.push(CaseSpec {
            name,
            sides: side_states,
            contacts: contact_states,
            sides2: side_states2,
            contacts2: contact_states2,
        });
    }

    let (f_lo, f_hi) = (
        scene.analysis.freq_start_hz.unwrap_or(0.0),
        scene.analysis.freq_end_hz.unwrap_or(f64::INFINITY),
    );
    let peak_window_hz = match l.peak_window_hz {
        None => None,
        Some([lo, hi]) => {
            ck.finite("limits.peak_window_hz[0]", lo)?;
            ck.finite("limits.peak_window_hz[1]", hi)?;
            if lo >= hi {
                return Err(ck.err(
                    "limits.peak_window_hz",
                    format!("the window is reversed or empty: {lo} .. {hi} Hz"),
                ));
            }
            if hi <= f_lo || lo >= f_hi {
                return Err(ck.err(
                    "limits.peak_window_hz",
                    format!(
                        "the window {lo} .. {hi} Hz lies outside the analysis range \
                         {f_lo} .. {f_hi} Hz"
                    ),
                ));
            }
            Some((lo, hi))
        }
    };
    let hysteresis = match &l.hysteresis {
        None => HysteresisRequest::default(),
        Some(h) => {
            for (i, &f) in h.freqs_hz.iter().enumerate() {
                let field = format!("limits.hysteresis.freqs_hz[{i}]");
                ck.finite(&field, f)?;
                if f < f_lo || f > f_hi {
                    return Err(ck.err(
                        field,
                        format!("{f} Hz lies outside the analysis range {f_lo} .. {f_hi} Hz"),
                    ));
                }
            }
            HysteresisRequest {
                at_peaks: h.at_peaks,
                freqs_hz: h.freqs_hz.clone(),
            }
        }
    };
    Ok(Some(LimitSettings {
        intermediate: l.intermediate.clone(),
        cases,
        grid_points: l.grid_points,
        bound_scan: l.bound_scan.clone(),
        peak_window_hz,
        hysteresis,
        envelope: l.envelope,
    }))
}

/// Why `name` names no contact point: the `[[contacts]]` names, and each contact patch's
/// points as a range (`left-1 … left-7`).
fn unknown_contact(name: &str, contacts: &[ContactPoint], sides: &[DamperSide]) -> String {
    let mut known: Vec<String> = Vec::new();
    for side in sides {
        let patch_points = |k: usize| format!("{}-{k}", side.name);
        let points: Vec<&str> = side
            .contacts
            .iter()
            .map(|&c| contacts[c].name.as_str())
            .collect();
        let n = points.len();
        if n > 2 && (1..=n).all(|k| points.contains(&patch_points(k).as_str())) {
            known.push(format!("{} … {}", patch_points(1), patch_points(n)));
        } else {
            known.extend(points.iter().map(|p| p.to_string()));
        }
    }
    format!(
        "unknown contact `{name}` (the scene has {})",
        known.join(", ")
    )
}
