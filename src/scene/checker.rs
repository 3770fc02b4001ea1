//! The validation toolkit shared by every check of a scene: a [`Checker`] that names the file
//! in its errors and checks single values (finite, positive, names, DOFs, matrices, friction
//! laws), and [`DofNames`], the model's DOF names with a look-up index.

use std::collections::HashMap;

use faer::Mat;

use crate::scene::error::SceneError;
use crate::scene::fe_input::{self, FeStructure};

/// Largest magnitude of any real number in a scene (SI units): far beyond every physical
/// stiffness, mass, force, length or frequency, and small enough that products and squares of
/// a few scene values stay finite in double precision.
pub const MAX_MAGNITUDE: f64 = 1e50;

/// Largest ratio of a contact stiffness kₜ or kₙ (N/m) to the model's stiffness scale (the
/// largest diagonal entry of K): above it the stuck structure's stiffness matrix
/// K + kₜ t tᵀ + kₙ n nᵀ has a condition number above 10¹², and the structure is lost in
/// round-off next to the contact spring.
pub const MAX_CONTACT_STIFFNESS_RATIO: f64 = 1e12;

/// Validation context: file name for messages.
pub(super) struct Checker<'a> {
    /// Scene file, as named in messages.
    pub(super) file: &'a str,
}

impl Checker<'_> {
    /// The error for a bad value of `field` (dotted path).
    pub(super) fn err(&self, field: impl Into<String>, reason: impl Into<String>) -> SceneError {
        SceneError::invalid(self.file, field, reason)
    }

    /// `v`, if it is finite and of magnitude at most [`MAX_MAGNITUDE`] (no quantity of a
    /// scene comes near it in SI units, and it keeps products and squares of scene values far
    /// from overflow).
    pub(super) fn finite(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        if !v.is_finite() {
            return Err(self.err(field, format!("must be a finite number, got {v}")));
        }
        if v.abs() > MAX_MAGNITUDE {
            return Err(self.err(
                field,
                format!(
                    "{v:e} is out of range: scene values must have magnitude ≤ {MAX_MAGNITUDE:e} \
                     (SI units; larger values overflow in the solver's products and norms)"
                ),
            ));
        }
        Ok(v)
    }

    /// `v`, if it is finite and > 0.
    pub(super) fn positive(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        self.finite(field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(field, format!("must be > 0, got {v}")))
        }
    }

    /// `v`, if it is finite and ≥ 0.
    pub(super) fn non_negative(&self, field: &str, v: f64) -> Result<f64, SceneError> {
        self.finite(field, v)?;
        if v < 0.0 {
            return Err(self.err(field, format!("must be ≥ 0, got {v}")));
        }
        Ok(v)
    }

    /// An n × n symmetric matrix of finite entries from its rows.
    pub(super) fn matrix(
        &self,
        field: &str,
        rows: &[Vec<f64>],
        n: usize,
    ) -> Result<Mat<f64>, SceneError> {
        if rows.len() != n {
            return Err(self.err(
                field,
                format!("has {} rows but the model has {n} DOFs", rows.len()),
            ));
        }
        for (i, r) in rows.iter().enumerate() {
            if r.len() != n {
                return Err(self.err(
                    format!("{field}[{i}]"),
                    format!("has {} entries but the model has {n} DOFs", r.len()),
                ));
            }
            for (j, v) in r.iter().enumerate() {
                self.finite(&format!("{field}[{i}][{j}]"), *v)?;
            }
        }
        let m = Mat::from_fn(n, n, |i, j| rows[i][j]);
        let scale = rows
            .iter()
            .flatten()
            .fold(0.0_f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for i in 0..n {
            for j in 0..i {
                if (m[(i, j)] - m[(j, i)]).abs() > 1e-12 * scale {
                    return Err(self.err(
                        field,
                        format!(
                            "is not symmetric: [{i}][{j}] = {} but [{j}][{i}] = {}",
                            m[(i, j)],
                            m[(j, i)]
                        ),
                    ));
                }
            }
        }
        Ok(m)
    }

    /// Checks that a symmetric matrix has no negative eigenvalue (to round-off).
    pub(super) fn semidefinite(&self, field: &str, m: &Mat<f64>) -> Result<(), SceneError> {
        if m.nrows() == 0 {
            return Ok(());
        }
        let (min, max) = self.eigen_range(field, m)?;
        if min < -1e-10 * max {
            return Err(self.err(
                field,
                format!(
                    "is indefinite (smallest eigenvalue {min:.4e}, largest magnitude {max:.4e})"
                ),
            ));
        }
        Ok(())
    }

    /// The smallest eigenvalue and the largest eigenvalue magnitude of a symmetric matrix
    /// (+∞ and 0 for an empty one); `field` names it when they cannot be computed.
    pub(super) fn eigen_range(&self, field: &str, m: &Mat<f64>) -> Result<(f64, f64), SceneError> {
        let eig = m
            .self_adjoint_eigenvalues(faer::Side::Lower)
            .map_err(|_| self.err(field, "eigenvalues could not be computed"))?;
        let max = eig.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let min = eig.iter().cloned().fold(f64::INFINITY, f64::min);
        Ok((min, max))
    }

    /// A contact stiffness `k` (N/m, kₜ or kₙ): finite, > 0, and no larger than
    /// [`MAX_CONTACT_STIFFNESS_RATIO`] times `model_scale`, the largest diagonal entry of K
    /// (N/m); a model without stiffness (`model_scale` = 0) sets no such bound. The ratio is
    /// checked before [`MAX_MAGNITUDE`] so that an absurd stiffness is explained by the
    /// structure it would swamp.
    pub(super) fn contact_stiffness(
        &self,
        field: &str,
        k: f64,
        model_scale: f64,
    ) -> Result<f64, SceneError> {
        let limit = MAX_CONTACT_STIFFNESS_RATIO * model_scale;
        if k.is_finite() && model_scale > 0.0 && k > limit {
            return Err(self.err(
                field,
                format!(
                    "{k:e} N/m is more than {MAX_CONTACT_STIFFNESS_RATIO:e} times the model's \
                     stiffness scale (largest diagonal entry of K, {model_scale:e} N/m): the \
                     stuck structure's stiffness matrix would lose the structure in round-off; \
                     a contact that stiff is rigid, use at most {limit:e} N/m"
                ),
            ));
        }
        self.positive(field, k)
    }

    /// A friction coefficient μ (–): finite and ≥ 0.
    pub(super) fn friction(&self, field: &str, mu: f64) -> Result<f64, SceneError> {
        self.finite(field, mu)?;
        if mu < 0.0 {
            return Err(self.err(field, format!("friction coefficient must be ≥ 0, got {mu}")));
        }
        Ok(mu)
    }

    /// The initial tangential state m ∈ [−1, 1] of a contact point (T(0) = m·μN(0)).
    pub(super) fn initial_state(&self, field: &str, m: f64) -> Result<f64, SceneError> {
        self.finite(field, m)?;
        if !(-1.0..=1.0).contains(&m) {
            return Err(self.err(
                field,
                format!("must lie in [-1, 1] (T(0) = m·μN(0)), got {m}"),
            ));
        }
        Ok(m)
    }

    /// DOF and contact names become CSV column names and parts of file names.
    pub(super) fn name(&self, field: &str, name: &str) -> Result<(), SceneError> {
        if name.trim().is_empty() {
            return Err(self.err(field, "must not be empty"));
        }
        if let Some(bad) = name
            .chars()
            .find(|c| matches!(c, ',' | '"' | '/' | '\\') || c.is_control())
        {
            return Err(self.err(
                field,
                format!(
                    "`{}` contains {bad:?}, which cannot appear in CSV column or file names",
                    name.escape_debug()
                ),
            ));
        }
        Ok(())
    }

    /// The row of DOF `name`; unknown names list the model's DOFs.
    pub(super) fn dof(
        &self,
        field: &str,
        name: &str,
        dofs: &DofNames,
    ) -> Result<usize, SceneError> {
        dofs.index.get(name).copied().ok_or_else(|| {
            let listed = if dofs.names.len() <= 24 {
                dofs.names.join(", ")
            } else {
                format!(
                    "{} DOFs named <node>.<direction>, e.g. {}, ...",
                    dofs.names.len(),
                    dofs.names[..3].join(", ")
                )
            };
            self.err(
                field,
                format!("unknown DOF `{name}` (the model has {listed})"),
            )
        })
    }

    /// The DOFs and weights of a load given by `dof` or by `group` and `direction`.
    pub(super) fn load_targets(
        &self,
        field: &str,
        dof: Option<&str>,
        group: Option<&str>,
        direction: Option<&str>,
        dofs: &DofNames,
        fe: Option<&FeStructure>,
    ) -> Result<Vec<(usize, f64)>, SceneError> {
        match (dof, group, direction) {
            (Some(d), None, None) => Ok(vec![(self.dof(&format!("{field}.dof"), d, dofs)?, 1.0)]),
            (None, Some(g), Some(dir)) => match fe {
                Some(fe) => fe_input::group_load(self.file, field, fe, g, dir),
                None => Err(self.err(
                    format!("{field}.group"),
                    "loads on groups need an FE mesh (`model.mesh`)",
                )),
            },
            _ => Err(self.err(field, "give either `dof`, or `group` and `direction`")),
        }
    }
}

/// DOF names with a look-up index.
pub(super) struct DofNames<'a> {
    /// Names in matrix order.
    names: &'a [String],
    /// Row of each name.
    index: HashMap<&'a str, usize>,
}

impl<'a> DofNames<'a> {
    /// The index of `names` (in matrix order).
    pub(super) fn new(names: &'a [String]) -> Self {
        Self {
            names,
            index: names
                .iter()
                .enumerate()
                .map(|(i, s)| (s.as_str(), i))
                .collect(),
        }
    }
}

impl std::ops::Index<usize> for DofNames<'_> {
    type Output = String;
    /// The name of DOF `i`.
    fn index(&self, i: usize) -> &String {
        &self.names[i]
    }
}
