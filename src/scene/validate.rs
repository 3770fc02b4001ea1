//! Validation at the door: a parsed [`Scene`] checked table by table, in a fixed order (model,
//! contacts, loads, harmonics, analysis, output, limits, sweep, reduction, stuck structure),
//! and built into a checked [`Problem`] plus the limit-analysis settings the scene asks for.
//! The first bad value is reported with the file, its dotted field path and the reason.

use std::path::Path;

use crate::analysis::limits::LimitSettings;
use crate::contact::aft::MarchSettings;
use crate::contact::ContactEffects;
use crate::hbm::formulation::check_relative_coordinates;
use crate::model::{Effects, FeOrigin, Formulation, Problem};
use crate::scene::check_analysis::{analysis, outputs};
use crate::scene::check_contacts::contact_set;
use crate::scene::check_limits::limit_settings;
use crate::scene::check_loads::{harmonic_loads, harmonic_set, static_load};
use crate::scene::check_model::{build_model, check_stuck_structure, reduce_problem};
use crate::scene::check_sweep::check_sweep;
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
    /// the settings of its limit analysis. `file` names the scene in errors.
    pub fn validate_with_limits(
        &self,
        file: &str,
    ) -> Result<(Problem, Option<LimitSettings>), SceneError> {
        let ck = Checker { file };
        let (model, fe) = build_model(&self.model, &ck)?;
        let dofs = DofNames::new(&model.dof_names);
        let dofs = &dofs;
        let n = model.n_dofs();

        let (contacts, sides) = contact_set(self, &ck, dofs, fe.as_ref())?;
        let static_load = static_load(&self.static_loads, &ck, dofs, fe.as_ref(), n)?;
        let harmonics = harmonic_set(&self.harmonics, &ck)?;
        let harmonic_loads =
            harmonic_loads(&self.harmonic_loads, &ck, dofs, fe.as_ref(), &harmonics)?;
        let analysis = analysis(&self.analysis, &ck)?;
        let outputs = outputs(&self.output, &ck, dofs, fe.as_ref())?;

        let limits = limit_settings(self, &ck)?;
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
        check_sweep(self, &ck)?;
        let problem = reduce_problem(self.reduction.as_ref(), &self.model, &ck, problem)?;
        check_stuck_structure(&ck, &problem)?;
        if problem.analysis.formulation == Formulation::Schur {
            check_relative_coordinates(&problem)
                .map_err(|e| ck.err("analysis.formulation", e.to_string()))?;
        }
        Ok((problem, limits))
    }
}

/// Loads and validates a scene in one go; returns the scene (for echoing) and the problem.
pub fn load_problem(path: &Path, overrides: &[String]) -> Result<(Scene, Problem), SceneError> {
    let scene = load(path, overrides)?;
    let problem = scene.validate(&path.display().to_string())?;
    Ok((scene, problem))
}
