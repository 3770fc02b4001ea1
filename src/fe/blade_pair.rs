//! Parametric mesh of two clamped blades with platforms and a wedge damper between them: the
//! FE counterpart of the lumped system of Ferhatoglu & Zucca (JSV 2021, Figs. 10-11).
//!
//! # Geometry (x circumferential, y radial outward, z axial; metres)
//! - `blade1` occupies x ∈ [0, b], y ∈ [0, L]; `blade2` is its mirror image about the plane
//!   x = x_c between them. Both roots (y = 0) form the group `clamp`.
//! - Each blade carries a platform on the side facing the other blade, from its face to
//!   within δ of x_c. The platform's underside is inclined by the damper base angle
//!   α = (180° − β)/2, rising towards x_c; its top is flat at y_top.
//! - The damper is an isosceles triangle of base width w_d and apical angle β, apex up, base
//!   at the bottom, its two upper faces against the two platform undersides: the outer
//!   three quarters of each face (from the base corner) touch the platform, the top quarter
//!   sticks into the gap of 2δ between the platform tips. The pre-load (the centrifugal force
//!   of a real under-platform damper) acts on the damper along +y and presses both faces
//!   against the platforms. This is the paper's Fig. 11 mirrored in y (the paper's F0 acts
//!   along −y on an apex-down wedge).
//! - Damper and blades are separate bodies: each contact face carries its own nodes, coincident
//!   node by node with the other face (`damper_left` ↔ `platform_left` on blade 1,
//!   `damper_right` ↔ `platform_right` on blade 2).
//! - `excitation`: the mid-chord tip node of blade 1; `response`: that of blade 2 (at
//!   mid-thickness in 3D).
//!
//! 2D meshes are 4-node quadrangles (plane stress is the intended assumption, with the
//! out-of-plane thickness `thickness`); `three_d` extrudes every quadrangle along z over
//! `thickness` into 8-node hexahedra (faces become quadrangles, points stay at mid-thickness).
//!
//! # Mesh size
//! The element size is h = b / (5 · refine). With the default dimensions (b = 10 mm,
//! L = 100 mm, thickness 10 mm) the models have these DOF counts (before clamping):
//!
//! | model | `--refine` | DOFs |
//! | --- | --- | --- |
//! | 2D | 1 | 1 586 |
//! | 2D | 2 | 5 046 |
//! | 2D | 3 | 11 474 (≈ 10 k) |
//! | 2D | 10 | 114 158 (≈ 100 k) |
//! | 2D | 30 | 1 008 794 (≈ 1 M) |
//! | 3D | 1 | 16 653 (≈ 10 k) |
//! | 3D | 2 | 83 259 (≈ 100 k) |
//! | 3D | 5 | 1 212 327 (≈ 1 M) |
//!
//! In 2D each contact face carries 3·refine·contact_refine + 1 node pairs: `contact_refine`
//! refines the contact faces and the damper alone, for many contact points on coarse blades.
//! `contact_pairs` sets the count directly instead (any count from 2, e.g. for the few-point
//! end of a contact ladder): each damper face is then split at the contact end rather than
//! at its midpoint, with `contact_pairs − 1` divisions below and about a third of that above.
//!
//! `fricbound mesh blade-pair --refine N [--3d]` prints the counts of any mesh; a test checks
//! the small ones.

use super::contact_patch::PatchSpec;
use super::mesh::{ElementKind, Mesh, MeshBuilder};

/// Share of each damper face (from the base corner) that touches the platform.
pub const CONTACT_FRACTION: f64 = 0.75;

/// Parameters of the blade pair (SI units; angles in degrees).
#[derive(Debug, Clone, PartialEq)]
pub struct BladePairParams {
    /// Refinement: element size = blade_width / (5 · refine). ≥ 1.
    pub refine: usize,
    /// Extra refinement of the contact faces and the damper (≥ 1): their divisions are
    /// multiplied by it, so a coarse blade can carry many contact pairs per side (the platform
    /// elements under the contact become slender along the face).
    pub contact_refine: usize,
    /// Node pairs per contact face (≥ 2), instead of the count the refinement gives; needs
    /// `contact_refine` = 1. The damper faces are then split at the contact end (see the
    /// module doc).
    pub contact_pairs: Option<usize>,
    /// Apical angle β of the damper (degrees), in [30, 170].
    pub beta_deg: f64,
    /// Blade length L, root to tip (m).
    pub blade_length: f64,
    /// Blade width b along x (m).
    pub blade_width: f64,
    /// Platform width: extent of each platform along x from the blade face (m).
    pub platform_width: f64,
    /// Platform thickness at its tip (m).
    pub platform_thickness: f64,
    /// Height y of the platform underside at the blade face (m).
    pub platform_height: f64,
    /// Damper base width w_d (m).
    pub damper_width: f64,
    /// Out-of-plane thickness (2D) or extrusion depth along z (3D) (m).
    pub thickness: f64,
    /// Extrude to 3D hexahedra.
    pub three_d: bool,
}

impl Default for BladePairParams {
    fn default() -> Self {
        BladePairParams {
            refine: 1,
            contact_refine: 1,
            contact_pairs: None,
            beta_deg: 120.0,
            blade_length: 0.1,
            blade_width: 0.01,
            platform_width: 0.01,
            platform_thickness: 0.003,
            platform_height: 0.03,
            damper_width: 0.012,
            thickness: 0.01,
            three_d: false,
        }
    }
}

/// Element divisions derived from the parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Divisions {
    /// Across the blade width (even, so the tip has a mid-chord node).
    pub blade_x: usize,
    /// Along the blade: below the platform, along the platform root, above it.
    pub blade_y: [usize; 3],
    /// Along the free part of the platform underside.
    pub platform_free: usize,
    /// Along each contact face (pairs per side = contact + 1).
    pub contact: usize,
    /// Along each damper face: from the base corner to the face's split node, and from there
    /// to the apex. The damper is three quadrangular sub-patches around its centroid, whose
    /// edges carry these counts (the base halves and the spokes to the split nodes the
    /// second, the spoke to the base midpoint the first).
    pub damper: [usize; 2],
    /// The split node of each damper face is the contact end (`contact_pairs` given), else
    /// the face midpoint.
    pub split_at_contact_end: bool,
    /// Through the thickness (3D only; even).
    pub layers: usize,
}

/// Bad generator parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("blade-pair parameters: {0}")]
pub struct BladePairError(pub String);

/// Points of the 2D geometry (see the module doc).
#[derive(Debug, Clone, Copy)]
struct Geometry {
    alpha: f64,
    b: f64,
    l: f64,
    x_c: f64,
    /// Damper base corners and apex.
    base_left: [f64; 2],
    base_right: [f64; 2],
    apex: [f64; 2],
    /// End of the left contact (platform 1 tip, underside).
    contact_end: [f64; 2],
    /// Platform 1 underside at the blade face.
    platform_root: [f64; 2],
    y_top: f64,
}

impl BladePairParams {
    fn geometry(&self) -> Result<Geometry, BladePairError> {
        let bad = |m: String| Err(BladePairError(m));
        let positive = [
            ("blade_length", self.blade_length),
            ("blade_width", self.blade_width),
            ("platform_width", self.platform_width),
            ("platform_thickness", self.platform_thickness),
            ("platform_height", self.platform_height),
            ("damper_width", self.damper_width),
            ("thickness", self.thickness),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{name} = {v} m must be finite and > 0"));
            }
        }
        if self.refine == 0 || self.refine > 1000 {
            return bad(format!("refine = {} must lie in 1..=1000", self.refine));
        }
        if self.contact_refine == 0 || self.contact_refine > 1000 {
            return bad(format!(
                "contact_refine = {} must lie in 1..=1000",
                self.contact_refine
            ));
        }
        if let Some(pairs) = self.contact_pairs {
            if !(2..=3001).contains(&pairs) {
                return bad(format!("contact_pairs = {pairs} must lie in 2..=3001"));
            }
            if self.contact_refine != 1 {
                return bad(format!(
                    "contact_pairs = {pairs} sets the contact divisions itself: contact_refine \
                     must be 1, not {}",
                    self.contact_refine
                ));
            }
        }
        if !(self.beta_deg.is_finite() && (30.0..=170.0).contains(&self.beta_deg)) {
            return bad(format!(
                "beta = {} degrees must lie in [30, 170] (the damper degenerates towards 180)",
                self.beta_deg
            ));
        }
        let alpha = (180.0 - self.beta_deg).to_radians() / 2.0;
        let half = self.damper_width / 2.0;
        let delta = half * (1.0 - CONTACT_FRACTION);
        let b = self.blade_width;
        let x_c = b + self.platform_width + delta;
        let free = x_c - half - b;
        if free <= 0.0 {
            return bad(format!(
                "platform_width = {} m must exceed {} m (3/4 of half the damper width) so the \
                 damper's base corners lie under the platforms",
                self.platform_width,
                CONTACT_FRACTION * half
            ));
        }
        let y_root = self.platform_height;
        let y_base = y_root + free * alpha.tan();
        let h_d = half * alpha.tan();
        let base_left = [x_c - half, y_base];
        let base_right = [x_c + half, y_base];
        let apex = [x_c, y_base + h_d];
        let contact_end = [
            base_left[0] + CONTACT_FRACTION * (apex[0] - base_left[0]),
            base_left[1] + CONTACT_FRACTION * (apex[1] - base_left[1]),
        ];
        let y_top = contact_end[1] + self.platform_thickness;
        if y_top >= 0.95 * self.blade_length {
            return bad(format!(
                "the platform top y = {y_top:.4} m must stay below 95 % of blade_length = {} m",
                self.blade_length
            ));
        }
        Ok(Geometry {
            alpha,
            b,
            l: self.blade_length,
            x_c,
            base_left,
            base_right,
            apex,
            contact_end,
            platform_root: [b, y_root],
            y_top,
        })
    }

    /// Element size h = blade_width / (5 · refine) (m).
    pub fn element_size(&self) -> f64 {
        self.blade_width / (5.0 * self.refine as f64)
    }

    /// The element divisions these parameters give.
    pub fn divisions(&self) -> Result<Divisions, BladePairError> {
        let g = self.geometry()?;
        let h = self.element_size();
        let count = |len: f64, min: usize| ((len / h).round() as usize).max(min);
        let face = dist(g.base_left, g.apex);
        // Contact divisions 3k with the whole face 4k, so nodes fall on the contact end; or
        // the contact divisions asked for, and about a third of them above the contact end.
        let k =
            ((CONTACT_FRACTION * face / (3.0 * h)).round() as usize).max(1) * self.contact_refine;
        let (contact, damper, split_at_contact_end) = match self.contact_pairs {
            Some(pairs) => {
                let c = pairs - 1;
                (c, [c, ((c as f64 / 3.0).round() as usize).max(1)], true)
            }
            None => (3 * k, [2 * k, 2 * k], false),
        };
        let blade_x = count(g.b, 2).next_multiple_of(2);
        Ok(Divisions {
            blade_x,
            blade_y: [
                count(g.platform_root[1], 1),
                count(g.y_top - g.platform_root[1], 2),
                count(g.l - g.y_top, 1),
            ],
            platform_free: count(g.base_left[0] - g.b, 1),
            contact,
            damper,
            split_at_contact_end,
            layers: count(self.thickness, 2).next_multiple_of(2),
        })
    }

    /// Contact patch specifications of the two damper sides (`left`: damper_left ↔
    /// platform_left on blade 1, `right`: damper_right ↔ platform_right on blade 2), with a
    /// pairing tolerance of 1e-6 of the element size, the 2D thickness, and in 3D the
    /// in-plane tangent (the 2D edge direction, so 2D and 3D frames agree).
    pub fn patch_specs(&self) -> Result<[PatchSpec; 2], BladePairError> {
        let g = self.geometry()?;
        let (c, s) = (g.alpha.cos(), g.alpha.sin());
        let tol = 1e-6 * self.element_size();
        let spec = |side: &str, tangent: [f64; 3]| PatchSpec {
            side: side.to_string(),
            damper_group: format!("damper_{side}"),
            body_group: format!("platform_{side}"),
            tolerance: tol,
            tangent: Some(tangent),
            thickness: self.thickness,
        };
        Ok([spec("left", [c, s, 0.0]), spec("right", [c, -s, 0.0])])
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// A body under construction: 2D nodes and named element lists (local node indices).
#[derive(Debug, Clone, Default)]
struct Part {
    nodes: Vec<[f64; 2]>,
    groups: Vec<(String, ElementKind, Vec<Vec<usize>>)>,
}

impl Part {
    fn node(&mut self, p: [f64; 2]) -> usize {
        self.nodes.push(p);
        self.nodes.len() - 1
    }

    /// Nodes from `from` to `to` (existing nodes) in `n` equal steps, both ends included.
    fn edge(&mut self, from: usize, to: usize, n: usize) -> Vec<usize> {
        let (a, b) = (self.nodes[from], self.nodes[to]);
        let mut out = vec![from];
        for i in 1..n {
            let t = i as f64 / n as f64;
            out.push(self.node([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]));
        }
        out.push(to);
        out
    }

    /// Transfinite (Coons) patch of quadrangles from four boundary node lists: `bottom` and
    /// `top` left to right, `left` and `right` bottom to top, sharing corners. Returns the
    /// node grid `[row j][column i]` and adds the quadrangles (counter-clockwise) to `group`.
    fn patch(
        &mut self,
        group: &str,
        bottom: &[usize],
        right: &[usize],
        top: &[usize],
        left: &[usize],
    ) -> Vec<Vec<usize>> {
        let (n, m) = (bottom.len() - 1, left.len() - 1);
        debug_assert!(top.len() == n + 1 && right.len() == m + 1);
        debug_assert!(bottom[0] == left[0] && bottom[n] == right[0]);
        debug_assert!(top[0] == left[m] && top[n] == right[m]);
        let p = |k: usize, nodes: &[[f64; 2]]| nodes[k];
        let (c00, c10, c01, c11) = (
            p(bottom[0], &self.nodes),
            p(bottom[n], &self.nodes),
            p(top[0], &self.nodes),
            p(top[n], &self.nodes),
        );
        let mut grid = vec![vec![0usize; n + 1]; m + 1];
        for j in 0..=m {
            for i in 0..=n {
                grid[j][i] = if j == 0 {
                    bottom[i]
                } else if j == m {
                    top[i]
                } else if i == 0 {
                    left[j]
                } else if i == n {
                    right[j]
                } else {
                    let (u, v) = (i as f64 / n as f64, j as f64 / m as f64);
                    let (bt, tp, lf, rt) = (
                        self.nodes[bottom[i]],
                        self.nodes[top[i]],
                        self.nodes[left[j]],
                        self.nodes[right[j]],
                    );
                    let mut q = [0.0; 2];
                    for c in 0..2 {
                        q[c] = (1.0 - v) * bt[c] + v * tp[c] + (1.0 - u) * lf[c] + u * rt[c]
                            - ((1.0 - u) * (1.0 - v) * c00[c]
                                + u * (1.0 - v) * c10[c]
                                + (1.0 - u) * v * c01[c]
                                + u * v * c11[c]);
                    }
                    self.node(q)
                };
            }
        }
        let quads = (0..m)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| {
                vec![
                    grid[j][i],
                    grid[j][i + 1],
                    grid[j + 1][i + 1],
                    grid[j + 1][i],
                ]
            })
            .collect();
        self.add(group, ElementKind::Quad4, quads);
        grid
    }

    fn add(&mut self, group: &str, kind: ElementKind, elements: Vec<Vec<usize>>) {
        self.groups.push((group.to_string(), kind, elements));
    }

    /// Line elements along a node chain.
    fn lines(&mut self, group: &str, chain: &[usize]) {
        let lines = chain.windows(2).map(|w| vec![w[0], w[1]]).collect();
        self.add(group, ElementKind::Line2, lines);
    }

    /// Mirror image about x = x_c with groups renamed; quadrangles re-ordered to stay
    /// counter-clockwise.
    fn mirrored(&self, x_c: f64, rename: &[(&str, &str)]) -> Part {
        let nodes = self
            .nodes
            .iter()
            .map(|p| [2.0 * x_c - p[0], p[1]])
            .collect();
        let groups = self
            .groups
            .iter()
            .map(|(name, kind, elements)| {
                let name = rename
                    .iter()
                    .find(|(from, _)| from == name)
                    .map(|(_, to)| to.to_string())
                    .unwrap_or_else(|| name.clone());
                let elements = elements
                    .iter()
                    .map(|e| match kind {
                        ElementKind::Quad4 => vec![e[0], e[3], e[2], e[1]],
                        _ => e.clone(),
                    })
                    .collect();
                (name, *kind, elements)
            })
            .collect();
        Part { nodes, groups }
    }
}

/// Blade 1 with its platform.
fn blade(g: &Geometry, d: &Divisions) -> Part {
    let mut p = Part::default();
    let [n1, nt, n3] = d.blade_y;
    let r0 = p.node([0.0, 0.0]);
    let r1 = p.node([g.b, 0.0]);
    let w0 = p.node([0.0, g.platform_root[1]]);
    let w1 = p.node([0.0, g.y_top]);
    let e0 = p.node(g.platform_root);
    let e1 = p.node([g.b, g.y_top]);
    let t0 = p.node([0.0, g.l]);
    let t1 = p.node([g.b, g.l]);
    let bottom = p.edge(r0, r1, d.blade_x);
    let top = p.edge(t0, t1, d.blade_x);
    let mut left = p.edge(r0, w0, n1);
    left.extend(&p.edge(w0, w1, nt)[1..]);
    left.extend(&p.edge(w1, t0, n3)[1..]);
    let right_low = p.edge(r1, e0, n1);
    let root = p.edge(e0, e1, nt);
    let right_high = p.edge(e1, t1, n3);
    let mut right = right_low.clone();
    right.extend(&root[1..]);
    right.extend(&right_high[1..]);
    p.patch("blade1", &bottom, &right, &top, &left);
    p.lines("clamp", &bottom);
    p.add(
        "excitation",
        ElementKind::Point,
        vec![vec![top[d.blade_x / 2]]],
    );

    // Platform: underside (free part, then contact), tip edge, flat top.
    let corner = p.node(g.base_left);
    let tip_low = p.node(g.contact_end);
    let top_mid = p.node([g.base_left[0], g.y_top]);
    let tip_high = p.node([g.contact_end[0], g.y_top]);
    let mut underside = p.edge(e0, corner, d.platform_free);
    let contact = p.edge(corner, tip_low, d.contact);
    underside.extend(&contact[1..]);
    let mut upper = p.edge(e1, top_mid, d.platform_free);
    upper.extend(&p.edge(top_mid, tip_high, d.contact)[1..]);
    let tip = p.edge(tip_low, tip_high, nt);
    p.patch("blade1", &underside, &tip, &upper, &root);
    p.lines("platform_left", &contact);
    p
}

/// The wedge damper: three quadrangular sub-patches around the centroid.
fn damper(g: &Geometry, d: &Divisions) -> Part {
    let mut p = Part::default();
    // Opposite edges of each sub-quadrangle need equal counts: with x below the face split
    // nodes and y above them, the base halves and the spokes to the face split nodes carry
    // y and the spoke to the base midpoint x.
    let [x, y] = d.damper;
    let split = if d.split_at_contact_end {
        CONTACT_FRACTION
    } else {
        0.5
    };
    let along =
        |a: [f64; 2], b: [f64; 2], t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    let (bl, br, ap) = (g.base_left, g.base_right, g.apex);
    let b = p.node(bl);
    let c = p.node(br);
    let a = p.node(ap);
    let m_bc = p.node(along(bl, br, 0.5));
    let m_ca = p.node(along(br, ap, split));
    let m_ab = p.node(along(bl, ap, split));
    let centre = p.node([(bl[0] + br[0] + ap[0]) / 3.0, (bl[1] + br[1] + ap[1]) / 3.0]);
    let rev = |v: Vec<usize>| v.into_iter().rev().collect::<Vec<_>>();
    let b_mab = p.edge(b, m_ab, x);
    let mab_a = p.edge(m_ab, a, y);
    let a_mca = p.edge(a, m_ca, y);
    let mca_c = p.edge(m_ca, c, x);
    let c_mbc = p.edge(c, m_bc, y);
    let mbc_b = p.edge(m_bc, b, y);
    let g_mab = p.edge(centre, m_ab, y);
    let g_mbc = p.edge(centre, m_bc, x);
    let g_mca = p.edge(centre, m_ca, y);
    p.patch(
        "damper",
        &rev(mbc_b.clone()),
        &rev(g_mbc.clone()),
        &rev(g_mab.clone()),
        &b_mab,
    );
    p.patch(
        "damper",
        &rev(mca_c.clone()),
        &rev(g_mca.clone()),
        &rev(g_mbc),
        &c_mbc,
    );
    p.patch(
        "damper",
        &rev(mab_a.clone()),
        &rev(g_mab),
        &rev(g_mca),
        &a_mca,
    );
    let mut left_face = b_mab;
    left_face.extend(&mab_a[1..]);
    let mut right_face = rev(mca_c);
    right_face.extend(&rev(a_mca)[1..]);
    p.lines("damper_left", &left_face[..=d.contact]);
    p.lines("damper_right", &right_face[..=d.contact]);
    p
}

/// Adds a 2D part to the mesh builder (z = 0), or its extrusion in 3D.
fn add_part(builder: &mut MeshBuilder, part: &Part, layers: Option<(usize, f64)>) {
    let base = builder.node_count();
    let per_layer = part.nodes.len();
    match layers {
        None => {
            for p in &part.nodes {
                builder.add_node([p[0], p[1], 0.0]);
            }
        }
        Some((n, depth)) => {
            for k in 0..=n {
                let z = depth * k as f64 / n as f64;
                for p in &part.nodes {
                    builder.add_node([p[0], p[1], z]);
                }
            }
        }
    }
    let at = |node: usize, layer: usize| base + layer * per_layer + node;
    for (name, kind, elements) in &part.groups {
        match layers {
            None => {
                let global: Vec<Vec<usize>> = elements
                    .iter()
                    .map(|e| e.iter().map(|&v| base + v).collect())
                    .collect();
                builder.add_group(name, *kind, &global);
            }
            Some((n, _)) => {
                let (kind3, global): (ElementKind, Vec<Vec<usize>>) = match kind {
                    ElementKind::Quad4 => (
                        ElementKind::Hexahedron8,
                        (0..n)
                            .flat_map(|k| {
                                elements.iter().map(move |e| {
                                    let mut h: Vec<usize> = e.iter().map(|&v| at(v, k)).collect();
                                    h.extend(e.iter().map(|&v| at(v, k + 1)));
                                    h
                                })
                            })
                            .collect(),
                    ),
                    ElementKind::Line2 => (
                        ElementKind::Quad4,
                        (0..n)
                            .flat_map(|k| {
                                elements.iter().map(move |e| {
                                    vec![at(e[0], k), at(e[1], k), at(e[1], k + 1), at(e[0], k + 1)]
                                })
                            })
                            .collect(),
                    ),
                    _ => (
                        *kind,
                        elements
                            .iter()
                            .map(|e| e.iter().map(|&v| at(v, n / 2)).collect())
                            .collect(),
                    ),
                };
                builder.add_group(name, kind3, &global);
            }
        }
    }
}

/// Generates the blade-pair mesh (see the module doc).
pub fn generate(params: &BladePairParams) -> Result<Mesh, BladePairError> {
    let g = params.geometry()?;
    let d = params.divisions()?;
    let blade1 = blade(&g, &d);
    let blade2 = blade1.mirrored(
        g.x_c,
        &[
            ("blade1", "blade2"),
            ("platform_left", "platform_right"),
            ("excitation", "response"),
        ],
    );
    let wedge = damper(&g, &d);
    let name = if params.three_d {
        "blade-pair-3d"
    } else {
        "blade-pair-2d"
    };
    let title = match params.contact_pairs {
        Some(pairs) => format!(
            "{name} (refine {}, {pairs} contact pairs, beta {} deg)",
            params.refine, params.beta_deg
        ),
        None => format!(
            "{name} (refine {}, beta {} deg)",
            params.refine, params.beta_deg
        ),
    };
    let mut builder = MeshBuilder::new(&title);
    let layers = params.three_d.then_some((d.layers, params.thickness));
    add_part(&mut builder, &blade1, layers);
    add_part(&mut builder, &blade2, layers);
    add_part(&mut builder, &wedge, layers);
    let mesh = builder.finish();
    mesh.validate()
        .map_err(|e| BladePairError(format!("generated mesh is inconsistent: {e}")))?;
    Ok(mesh)
}
