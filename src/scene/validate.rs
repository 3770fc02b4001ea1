//! Validation at the door: a parsed [`Scene`] checked table by table, in a fixed order (model,
//! contacts, loads, harmonics, analysis and its frequency bound, output, limits, sweep table,
//! how every free body is held, reduction, stuck structure, formulation, and last the scene
//! at every sweep point), and built into a checked [`Problem`] plus the limit-analysis
//! settings the scene asks for. The first bad value is reported with the file, its dotted
//! field path and the reason.

use std::path::Path;

use crate::analysis::limits::LimitSettings;
use crate::contact::aft::MarchSettings;
use crate::contact::ContactEffects;
use crate::hbm::formulation::check_relative_coordinates;
use crate::model::reduce::ReductionSettings;
use crate::model::{Effects, FeOrigin, Formulation, Problem};
use crate::scene::check_analysis::{
    analysis, check_stability, error_estimate, frequency_bound, outputs,
};
use crate::scene::check_bodies::check_held_bodies;
use crate::scene::check_contacts::{check_gap_scale, contact_set};
use crate::scene::check_limits::limit_settings;
use crate::scene::check_loads::{harmonic_loads, harmonic_set, static_load};
use crate::scene::check_model::{
    build_model, check_stuck_structure, reduce_problem, reduction_settings, stiffness_scale,
};
use crate::scene::check_modes::{mode_analysis, mode_range};
use crate::scene::check_sweep::{check_sweep, check_sweep_points};
use crate::scene::checker::{Checker, DofNames};
use crate::scene::error::SceneError;
use crate::scene::overrides::load;
use crate::scene::schema::Scene;

impl Scene {
    /// Checks every value and builds the problem. `file` names the scene in errors.
    pub fn validate(&self, file: &str) -> Result<Problem, SceneError> {
        self.validate_with_limits(file).map(|(problem, _)| problem)
    }

    /// Checks every value and builds the problem and, when the scene has a `[limits]` table,
    /// the settings of its limit analysis. `file` names the scene in errors. A scene with a
    /// `[sweep]` table is also checked at every sweep point.
    pub fn validate_with_limits(
        &self,
        file: &str,
    ) -> Result<(Problem, Option<LimitSettings>), SceneError> {
        let checked = self.validate_scene(file)?;
        check_sweep_points(self, &Checker { file }, &|point: &Scene| {
            point.validate_scene(file).map(|_| ())
        })?;
        Ok(checked)
    }

    /// Checks every value of this scene (not the scene at its sweep points) and builds the
    /// full problem, before any reduction, with the reduction settings of its `[reduction]`
    /// table: for the commands that reduce themselves and compare the full model with the
    /// reduced one (`modes`, `reduce`). The full problem with contacts stuck must be held.
    pub fn validate_unreduced(
        &self,
        file: &str,
    ) -> Result<(Problem, Option<ReductionSettings>), SceneError> {
        let ck = Checker { file };
        let (problem, _, reduction, held) = self.unreduced(&ck)?;
        check_stuck_structure(&ck, &problem)?;
        held?;
        Ok((problem, reduction))
    }

    /// Checks every value of this scene (the `[sweep]` table's own fields, not the scene at
    /// its points) and builds the problem and the limit settings.
    fn validate_scene(&self, file: &str) -> Result<(Problem, Option<LimitSettings>), SceneError> {
        let ck = Checker { file };
        let (problem, limits, reduction, held) = self.unreduced(&ck)?;
        let problem = reduce_problem(reduction.as_ref(), &ck, problem)?;
        check_stuck_structure(&ck, &problem)?;
        held?;
        let mut problem = problem;
        problem.analysis.nonlinear_modes = mode_analysis(self, &ck, &problem, limits.as_ref())?;
        mode_range(self, &ck, &mut problem)?;
        if matches!(
            problem.analysis.formulation,
            Formulation::Schur | Formulation::SchurLowRank
        ) {
            check_relative_coordinates(&problem)
                .map_err(|e| ck.err("analysis.formulation", e.to_string()))?;
        }
        check_stability(&ck, &problem)?;
        Ok((problem, limits))
    }

    /// The tables checked up to the reduction: the full problem, the limit settings, the
    /// reduction settings and the outcome of the held-body check (reported after the
    /// stuck-structure check, which names a body that even stuck contacts cannot hold).
    #[allow(clippy::type_complexity)]
    fn unreduced(
        &self,
        ck: &Checker,
    ) -> Result<
        (
            Problem,
            Option<LimitSettings>,
            Option<ReductionSettings>,
            Result<(), SceneError>,
        ),
        SceneError,
    > {
        let (model, fe) = build_model(&self.model, ck)?;
        let k_scale = stiffness_scale(&model);
        let dofs = DofNames::new(&model.dof_names);
        let dofs = &dofs;
        let n = model.n_dofs();

        let (contacts, sides) = contact_set(self, ck, dofs, fe.as_ref(), k_scale)?;
        let (static_load, load_dofs) = static_load(&self.static_loads, ck, dofs, fe.as_ref(), n)?;
        let harmonics = harmonic_set(&self.harmonics, ck)?;
        let harmonic_loads =
            harmonic_loads(&self.harmonic_loads, ck, dofs, fe.as_ref(), &harmonics)?;
        frequency_bound(&self.analysis, &harmonics, &model, &contacts, ck)?;
        let mut analysis = analysis(&self.analysis, ck)?;
        analysis.error_estimate = error_estimate(&self.accuracy, ck)?;
        let outputs = outputs(&self.output, ck, dofs, fe.as_ref())?;
        let reduction =
            reduction_settings(self.reduction.as_ref(), &self.model, ck, dofs, fe.as_ref())?;

        let limits = limit_settings(self, ck, (&contacts, &sides))?;
        let problem = Problem {
            model,
            contacts,
            sides,
            static_load,
            harmonic_loads,
            harmonics,
            samples: self.harmonics.samples,
            effects: Effects {
                contact: ContactEffects {
                    normal_load: self.effects.normal_load,
                    liftoff: self.effects.liftoff,
                },
                coupling: self.effects.coupling,
            },
            march: MarchSettings {
                max_periods: self.harmonics.max_periods,
                ..MarchSettings::default()
            },
            analysis,
            outputs,
            fe: fe.as_ref().and_then(|f| {
                f.mesh.as_ref().map(|mesh| {
                    std::sync::Arc::new(FeOrigin {
                        mesh: mesh.clone(),
                        dofs: f.dofs.clone(),
                        recovery: None,
                        reduced: false,
                    })
                })
            }),
        };
        check_sweep(self, ck)?;
        // Inline contacts only (patch gaps come from the mesh's geometry).
        if self.contacts.len() == problem.contacts.len() {
            let fields: Vec<String> = (0..self.contacts.len())
                .map(|i| format!("contacts[{i}].gap"))
                .collect();
            check_gap_scale(ck, &problem, &fields)?;
        }
        // On the full model, before reduction; reported after the stuck-structure check, which
        // names a body that even stuck contacts cannot hold.
        let points: Vec<Vec<usize>> = self
            .contacts
            .iter()
            .flat_map(|c| [&c.damper, &c.body])
            .map(|names| {
                names
                    .iter()
                    .filter_map(|name| problem.model.dof_index(name))
                    .collect()
            })
            .collect();
        let held = check_held_bodies(ck, &problem, &points, &load_dofs);
        Ok((problem, limits, reduction, held))
    }
}

/// Loads and validates a scene in one go; returns the scene (for echoing) and the problem.
pub fn load_problem(path: &Path, overrides: &[String]) -> Result<(Scene, Problem), SceneError> {
    let scene = load(path, overrides)?;
    let problem = scene.validate(&path.display().to_string())?;
    Ok((scene, problem))
}
