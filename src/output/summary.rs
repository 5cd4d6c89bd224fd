//! `summary.json`: the run's totals, extremes, timings and solver facts.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::energy::Ledger;
use crate::error::{Error, Result};

/// Extremes of one probe's vertical displacement.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ProbeSummary {
    /// `max |u_y|`.
    pub max_abs_uy: f64,
    /// `min u_y`.
    pub min_uy: f64,
    /// `max u_y`.
    pub max_uy: f64,
}

impl Default for ProbeSummary {
    fn default() -> Self {
        ProbeSummary {
            max_abs_uy: 0.0,
            min_uy: f64::INFINITY,
            max_uy: f64::NEG_INFINITY,
        }
    }
}

impl ProbeSummary {
    /// Takes one sample. A NaN sample makes every extreme NaN (`f64::max` would
    /// drop it and report the extremes of the other samples as if nothing happened).
    pub fn sample(&mut self, uy: f64) {
        if uy.is_nan() || self.max_abs_uy.is_nan() {
            *self = ProbeSummary {
                max_abs_uy: f64::NAN,
                min_uy: f64::NAN,
                max_uy: f64::NAN,
            };
            return;
        }
        self.max_abs_uy = self.max_abs_uy.max(uy.abs());
        self.min_uy = self.min_uy.min(uy);
        self.max_uy = self.max_uy.max(uy);
    }
}

/// One contact pair over a run.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct ContactSummary {
    /// Largest total normal force (N).
    pub max_force: f64,
    /// Largest penetration (m).
    pub max_penetration: f64,
    /// Largest number of active constraints.
    pub max_active: usize,
    /// Impulse `∫ F dt` (N s), the force of each step times its length.
    pub impulse: f64,
    /// Largest total magnitude of the friction forces `Σ |λ_T|` (N).
    pub max_tangential_force: f64,
    /// Tangential impulse `∫ Σ λ_T dt` (N s), along the rows' tangents.
    pub tangential_impulse: f64,
    /// The longest slip path of a pressed node (m).
    pub slip: f64,
}

impl ContactSummary {
    /// Takes one step's record of length `dt`.
    pub fn sample(&mut self, p: &crate::contact::PairRecord, dt: f64) {
        let nan = p.force.is_nan() || p.penetration.is_nan();
        self.max_force = if nan {
            f64::NAN
        } else {
            self.max_force.max(p.force)
        };
        self.max_penetration = if nan {
            f64::NAN
        } else {
            self.max_penetration.max(p.penetration)
        };
        self.max_active = self.max_active.max(p.active);
        self.impulse += p.force * dt;
        self.max_tangential_force = self.max_tangential_force.max(p.tangential_magnitude);
        self.tangential_impulse += p.tangential_force * dt;
        self.slip = self.slip.max(p.max_slip);
    }
}

/// Energy totals.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct EnergySummary {
    /// Initial kinetic energy.
    pub kinetic_0: f64,
    /// Final kinetic energy.
    pub kinetic: f64,
    /// Work of internal forces.
    pub internal: f64,
    /// Work of external forces.
    pub external_work: f64,
    /// Stored elastic energy.
    pub elastic: f64,
    /// The scheme's stored energy at the end (generalized-α's modified energy less
    /// `E_kin + E_el`; zero for the other schemes).
    pub algorithmic: f64,
    /// The same at the start.
    pub algorithmic_0: f64,
    /// Dissipation by mechanism.
    pub dissipated: crate::energy::Dissipation,
    /// Final balance residual.
    pub balance_residual: f64,
    /// Largest `|residual|` over the run relative to the largest energy.
    pub balance_residual_rel: f64,
}

impl From<&Ledger> for EnergySummary {
    fn from(l: &Ledger) -> Self {
        EnergySummary {
            kinetic_0: l.kinetic_0(),
            kinetic: l.kinetic(),
            internal: l.internal(),
            external_work: l.external_work(),
            elastic: l.elastic(),
            algorithmic: l.algorithmic(),
            algorithmic_0: l.algorithmic_0(),
            dissipated: *l.dissipated(),
            balance_residual: l.residual(),
            balance_residual_rel: l.relative_residual(),
        }
    }
}

/// Timings in seconds.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct TimingSummary {
    /// Assembly.
    pub assembly_s: f64,
    /// Symbolic + numeric factorisation.
    pub factorization_s: f64,
    /// Triangular solves.
    pub solve_s: f64,
    /// Wall clock of the whole run.
    pub total_s: f64,
}

impl TimingSummary {
    /// All zero.
    pub fn zero() -> Self {
        TimingSummary {
            assembly_s: 0.0,
            factorization_s: 0.0,
            solve_s: 0.0,
            total_s: 0.0,
        }
    }
}

/// Solver facts.
#[derive(Clone, Debug, Serialize)]
pub struct SolverSummary {
    /// Backend name.
    pub backend: String,
    /// Numeric factorisations.
    pub factorizations: usize,
    /// Refactorisations asked for and spared because the assembled tangent had not
    /// changed (every Gauss point elastic or on an unchanged state).
    #[serde(default)]
    pub reused_factors: usize,
    /// Whether damage and plasticity iterate on a kept factor (`analysis.keep_factor`).
    pub keep_factor: bool,
    /// Steps whose iterations on a kept factor failed and were redone refactorising
    /// at every changed tangent.
    pub fallbacks: usize,
    /// Generalized-α's steps that changed which slaves are held, taken by the
    /// trapezoidal rule (impact steps, `theory/trapezoidal.md`).
    pub impact_steps: usize,
    /// Impact steps whose trapezoidal step did not converge, taken by
    /// generalized-α instead (`checks.no_energy_created` says what they did).
    pub impact_fallbacks: usize,
    /// Linear solves (iterations) over the run.
    pub iterations: usize,
    /// Iterations per accepted step: mean and largest.
    pub iterations_per_step: f64,
    /// The most iterations an accepted step took.
    pub max_step_iterations: usize,
    /// Steps cut back (halved) after non-convergence.
    pub step_cuts: usize,
    /// Nonzeros of the Cholesky factor.
    pub factor_nnz: Option<usize>,
}

/// What a run used of one material: its model and, for softening models, how it is
/// regularised (`local`, `crack_band` or `nonlocal`, with the radius or the fracture
/// energy), and where identified parameters came from.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct MaterialSummary {
    /// `elastic`, `kelvin_voigt`, `sls`, `maxwell`, `mazars` or `rankine_hill`.
    pub model: String,
    /// The regularisation of a softening model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regularisation: Option<String>,
    /// The nonlocal interaction radius (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// The crack band's fracture energy (N/m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fracture_energy: Option<f64>,
    /// The identification the parameters came from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identified_from: Option<String>,
}

impl MaterialSummary {
    /// The summary of `m`.
    pub fn of(m: &crate::material::Material) -> Self {
        use crate::material::{Hardening, Law, Regularisation};
        let fracture_energy = match &m.law {
            Law::Mazars(p) => match p.regularisation {
                Regularisation::CrackBand { fracture_energy } => Some(fracture_energy),
                _ => None,
            },
            Law::RankineHill(p) => match p.tension {
                Hardening::LinearSoftening {
                    fracture_energy, ..
                } => Some(fracture_energy),
                _ => None,
            },
            _ => None,
        };
        MaterialSummary {
            model: m.model_name().into(),
            regularisation: m.regularisation().map(String::from),
            radius: m.nonlocal_radius(),
            fracture_energy,
            identified_from: m.identified_from.clone(),
        }
    }
}

/// Where a run stands, as `summary.json` says it (`"running"`, `"completed"`,
/// `"stopped"`, `"failed"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunStatus {
    /// The run is going, or was killed before it could say otherwise.
    Running,
    /// The run reached its end time.
    Completed,
    /// The run stopped with an error (`error` says which; an interruption is one).
    Failed,
    /// The caller's observer (a progress callback) stopped the run before its end
    /// time; what it wrote up to there is valid.
    Stopped,
}

impl RunStatus {
    /// The word `summary.json` holds.
    pub fn as_str(self) -> &'static str {
        match self {
            RunStatus::Running => "running",
            RunStatus::Completed => "completed",
            RunStatus::Failed => "failed",
            RunStatus::Stopped => "stopped",
        }
    }

    /// The status of a `summary.json` value's word, if it is one.
    pub fn parse(word: &str) -> Option<RunStatus> {
        [
            RunStatus::Running,
            RunStatus::Completed,
            RunStatus::Failed,
            RunStatus::Stopped,
        ]
        .into_iter()
        .find(|s| s.as_str() == word)
    }
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The whole summary.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Where the run stands.
    pub status: RunStatus,
    /// The error, when failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the scenario gives that the analysis did not read ([`crate::model::Model::warnings`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Number of dofs.
    pub dofs: usize,
    /// Number of elements.
    pub elements: usize,
    /// Steps taken.
    pub steps: usize,
    /// Time reached.
    pub t_end: f64,
    /// Step size (an error-controlled run: the first step).
    pub dt: f64,
    /// An error-controlled run's account of its steps (`steps_accepted`,
    /// `steps_rejected`, `dt_min_used`, `dt_max_used`, …), flattened into the
    /// summary; absent for fixed steps.
    #[serde(flatten)]
    pub adaptive: Option<crate::time::adaptive::AdaptiveReport>,
    /// The time scheme of a dynamic run (`backward_euler`, `trapezoidal`,
    /// `generalized_alpha`, `central_difference`); absent in statics.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scheme: Option<crate::model::TimeScheme>,
    /// Generalized-α's spectral radius at infinity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rho_inf: Option<f64>,
    /// `stabilised` when the contact-stabilised predictor ran (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_predictor: Option<crate::model::ContactPredictor>,
    /// The materials by name: model and regularisation.
    pub materials: BTreeMap<String, MaterialSummary>,
    /// Probe extremes.
    pub probes: BTreeMap<String, ProbeSummary>,
    /// Contact pairs: forces, penetration, active constraints, impulse.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub contact: BTreeMap<String, ContactSummary>,
    /// Energies.
    pub energy: EnergySummary,
    /// The paper's energy checks with their values.
    pub checks: super::checks::Checks,
    /// Timings.
    pub timing: TimingSummary,
    /// Solver facts.
    pub solver: SolverSummary,
}

impl Summary {
    /// Writes pretty JSON to `path`, atomically (a temporary file renamed over it),
    /// so a reader never sees half a summary.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::io(path, std::io::Error::other(e.to_string())))?;
        let tmp = path.with_extension("json.tmp");
        let _hold = super::interrupt::hold();
        std::fs::write(&tmp, text).map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
    }
}
