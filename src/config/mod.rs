//! Scenario files: the TOML a user writes ([`Scenario`]) and its validation into a
//! [`crate::model::Model`]. Unknown keys are rejected; every error names the field
//! (`materials.concrete.nu: ...`). Defaults say why they are what they are.
//!
//! Start with [`load`]; the format is documented in the README and `examples/`.

pub mod adaptive;
mod bodies;
pub mod exact;
mod location;
pub mod overrides;
mod validate;

pub use bodies::{
    BarSpec, BodySpec, Component, LoadSpec, MeshSpec, PrescribedSpec, ProbeSpec, SupportSpec,
};
pub use validate::{check_function, finite, material, positive, HUGE_STEPS};

/// How a scenario is loaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoadOptions {
    /// Refuse a model whose memory estimate exceeds this many bytes (`None`: no
    /// limit). Default: the memory available on this machine.
    pub memory_limit: Option<u64>,
    /// Accept an explicit step above the critical step (`--allow-unstable`, for
    /// stability studies). Default false: such a step is refused.
    pub allow_unstable: bool,
    /// The factor will be distributed over MPI ranks (`--backend mumps`): the
    /// checks while loading leave it out of this process's estimate, and the
    /// backend's own analysis checks it per node before the factorisation.
    pub distributed_factor: bool,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            memory_limit: crate::memory::available(),
            allow_unstable: false,
            distributed_factor: false,
        }
    }
}

impl LoadOptions {
    /// No memory limit (`--ignore-memory`).
    pub fn unlimited() -> Self {
        LoadOptions {
            memory_limit: None,
            allow_unstable: false,
            distributed_factor: false,
        }
    }
}

use std::collections::BTreeMap;
use std::path::Path;

pub use overrides::Overrides;

use serde::Deserialize;

use crate::error::{Error, Result};
use crate::fe::Idealisation;
use crate::model::{AnalysisKind, Model};
use location::{field_path, line_column, toml_error, within_material};

/// A whole scenario file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Time stepping, damping and output settings.
    pub analysis: AnalysisSpec,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Bodies (at least one).
    pub bodies: Vec<BodySpec>,
    /// Bar (rebar) lines embedded in bodies.
    #[serde(default)]
    pub bars: Vec<BarSpec>,
    /// Fixed displacement components.
    #[serde(default)]
    pub supports: Vec<SupportSpec>,
    /// Prescribed displacement histories.
    #[serde(default)]
    pub prescribed: Vec<PrescribedSpec>,
    /// Loads.
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// Output probes.
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// Contact pairs and unilateral supports.
    #[serde(default)]
    pub contact: Vec<ContactSpec>,
    /// Defaults of the generated meshes.
    #[serde(default)]
    pub meshing: MeshingSpec,
}

/// `[meshing]`: defaults of the generated (rectangle) meshes, so that one key sets the
/// mesh size of every body (`--set meshing.element_size=0.05`, `rothe study mesh`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshingSpec {
    /// Cell size (m) of every rectangle body that gives neither `divisions` nor its
    /// own `element_size`.
    #[serde(default)]
    pub element_size: Option<f64>,
}

/// `[[contact]]`: a slave node or edge set against a master edge set of another body
/// (mortar or node-to-segment, with Coulomb friction `mu`), or against a rigid line
/// (a unilateral support: it resists motion into it and lets the body lift off). In
/// a solid: a slave node or face set against a master face set (node to face) or a
/// rigid plane.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Name (column prefix `<name>_force`, `<name>_active` in `history.csv`).
    pub name: String,
    /// The slave side: a node set or an edge set (its nodes) of one body.
    pub slave: String,
    /// The master side ([`MasterTable`]): the name of an edge set of another body (a
    /// face set in a solid), short for `{ set = "..." }`, or a table naming a rigid
    /// master. `rigid_line` and `rigid_plane` may be given beside `slave` instead.
    #[serde(default, deserialize_with = "master_field")]
    pub master: Option<MasterTable>,
    /// A rigid line `[[x0, y0], [x1, y1]]` the slave nodes may not cross (a unilateral
    /// support), short for `master = { rigid_line = ... }`.
    #[serde(default, deserialize_with = "exact::option_segment")]
    pub rigid_line: Option<[[f64; 2]; 2]>,
    /// A solid's rigid plane, short for `master = { rigid_plane = ... }`.
    #[serde(default)]
    pub rigid_plane: Option<RigidPlaneSpec>,
    /// Also check the master's nodes against the slave's edges (the slave must be an
    /// edge set). Default false: slave nodes against master segments only.
    #[serde(default)]
    pub both_ways: bool,
    /// Central differences: the paper's friction interpolation `β` in `[0, 1]`
    /// between the frictionless (0, default) and the sticking (1) impact.
    #[serde(default)]
    pub friction: Option<f64>,
    /// Central differences: the paper's weight `w` in `[0, 1]` of the velocity before
    /// the impact in the position update over the time to impact. Default 0.5.
    #[serde(default)]
    pub position_weight: Option<f64>,
    /// Coulomb's friction coefficient `μ ≥ 0` (default 0, frictionless): the
    /// tangential force of a pressed node at most `μ` times its normal force.
    #[serde(default)]
    pub mu: Option<f64>,
    /// How a pair with a deformable master writes its gaps: `mortar` (default when
    /// the slave is an edge set: segment to segment, one weighted gap per slave node)
    /// or `node_to_segment`. Rigid lines and the explicit path are node to segment.
    #[serde(default)]
    pub formulation: Option<crate::model::Formulation>,
    /// A mortar pair's slave-side test functions: `standard` (default, the slave's
    /// shape functions) or `dual` (biorthogonal: each weighted gap holds one slave
    /// node). Read by mortar pairs only.
    #[serde(default)]
    pub mortar_basis: Option<crate::model::MortarBasis>,
}

/// `analysis.damping`: Rayleigh's pair from a damping ratio at two frequencies.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// The damping ratio `ξ` wanted at both frequencies (0.02: two percent).
    pub ratio: f64,
    /// The two frequencies (Hz).
    #[serde(default)]
    pub frequencies: Option<[f64; 2]>,
    /// The two modes (numbers from 1, the lowest first), computed.
    #[serde(default)]
    pub modes: Option<[usize; 2]>,
}

/// `contact.master`: what a pair's slaves may not cross, exactly one of its keys.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MasterTable {
    /// An edge set (plane) or face set (solid) of another body.
    #[serde(default)]
    pub set: Option<String>,
    /// A plane model's rigid line `[[x0, y0], [x1, y1]]`: a unilateral support of
    /// finite length; its side is the one the slave body lies on.
    #[serde(default, deserialize_with = "exact::option_segment")]
    pub rigid_line: Option<[[f64; 2]; 2]>,
    /// A solid's rigid plane (unbounded; its side is the one the slave body lies
    /// on).
    #[serde(default)]
    pub rigid_plane: Option<RigidPlaneSpec>,
}

/// Reads `contact.master`: a set's name or a [`MasterTable`].
fn master_field<'de, D>(d: D) -> std::result::Result<Option<MasterTable>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    struct Field;
    impl<'de> serde::de::Visitor<'de> for Field {
        type Value = MasterTable;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a set's name or a table with one of `set`, `rigid_line`, `rigid_plane`")
        }
        fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<MasterTable, E> {
            Ok(MasterTable {
                set: Some(v.to_string()),
                ..Default::default()
            })
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            map: A,
        ) -> std::result::Result<MasterTable, A::Error> {
            MasterTable::deserialize(serde::de::value::MapAccessDeserializer::new(map))
        }
    }
    d.deserialize_any(Field).map(Some)
}

/// What a pair's master is, from whichever keys the scenario gave.
#[derive(Clone, Copy, Debug)]
pub enum MasterSpec<'a> {
    /// An edge set (plane) or face set (solid) of another body, by name.
    Set(&'a str),
    /// A rigid line.
    RigidLine(&'a [[f64; 2]; 2]),
    /// A rigid plane.
    RigidPlane(&'a RigidPlaneSpec),
}

impl ContactSpec {
    /// The pair's master and the field that gave it (`contact[i].master`,
    /// `.master.rigid_line`, `.rigid_line`, ...): exactly one of `master` (a name, or
    /// a table with one key), `rigid_line` and `rigid_plane`. `field` is the pair's
    /// own (`contact[i]`).
    pub fn master_spec(&self, field: &str) -> Result<(MasterSpec<'_>, String)> {
        let mut given: Vec<(MasterSpec<'_>, String)> = Vec::new();
        if let Some(m) = &self.master {
            if let Some(set) = &m.set {
                given.push((MasterSpec::Set(set), format!("{field}.master")));
            }
            if let Some(l) = &m.rigid_line {
                given.push((
                    MasterSpec::RigidLine(l),
                    format!("{field}.master.rigid_line"),
                ));
            }
            if let Some(p) = &m.rigid_plane {
                given.push((
                    MasterSpec::RigidPlane(p),
                    format!("{field}.master.rigid_plane"),
                ));
            }
            if given.is_empty() {
                return Err(Error::config(
                    format!("{field}.master"),
                    "the table names no master: give one of `set`, `rigid_line`, `rigid_plane`",
                ));
            }
        }
        if let Some(l) = &self.rigid_line {
            given.push((MasterSpec::RigidLine(l), format!("{field}.rigid_line")));
        }
        if let Some(p) = &self.rigid_plane {
            given.push((MasterSpec::RigidPlane(p), format!("{field}.rigid_plane")));
        }
        match given.len() {
            1 => Ok(given.pop().expect("one")),
            0 => Err(Error::config(
                field,
                "no master: give `master` (an edge set, a face set in a solid), `rigid_line` \
                 (plane) or `rigid_plane` (solid)",
            )),
            _ => Err(Error::config(
                field,
                format!(
                    "give exactly one of `master`, `rigid_line` and `rigid_plane`; found {}",
                    given
                        .iter()
                        .map(|(_, f)| format!("`{f}`"))
                        .collect::<Vec<_>>()
                        .join(" and ")
                ),
            )),
        }
    }
}

/// `contact.rigid_plane`: a point of the plane and its normal (either sense: the
/// side of the slave body is kept).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidPlaneSpec {
    /// A point of the plane `[x, y, z]`.
    pub point: Vec<f64>,
    /// A normal of the plane `[x, y, z]` (any length but zero).
    pub normal: Vec<f64>,
}

fn default_vtk_every() -> usize {
    // Every 10th step keeps ParaView animations smooth without flooding the disk.
    10
}

/// `[analysis]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    /// `dynamic` (default) or `static`.
    #[serde(default)]
    pub kind: AnalysisKind,
    /// Time scheme of a dynamic analysis: `backward_euler` (default: the paper's Rothe
    /// scheme) or `central_difference` (explicit, lumped mass, the kinematic contact
    /// method).
    #[serde(default)]
    pub scheme: crate::model::TimeScheme,
    /// End time `T` (s).
    pub t_end: f64,
    /// Step `h` (s). Required for backward Euler and statics; central differences
    /// default it to `omega` times the critical step.
    #[serde(default)]
    pub dt: Option<f64>,
    /// Central differences: the fraction of the critical (CFL) step the default step
    /// takes (the paper's `ω`). Default 0.9.
    #[serde(default)]
    pub omega: Option<f64>,
    /// Central differences: how the stable step is bounded, `element` (default:
    /// `min_e 2/ω_e`, element by element) or `eigen` (the mesh's own `2/ω_max`, by
    /// Lanczos on `M_L⁻¹K`, shortened for the damping the scheme takes at the
    /// half-step velocity).
    #[serde(default)]
    pub critical_step: Option<crate::model::CriticalStepRule>,
    /// Generalized-α: the spectral radius at `ωh → ∞` in `[0, 1]` (1 damps nothing,
    /// 0 annihilates the highest modes in one step). Default 0.8.
    #[serde(default)]
    pub rho_inf: Option<f64>,
    /// The trapezoidal rule and generalized-α: `none` (default) or `stabilised`, the
    /// contact-stabilised predictor (an M-projection of the free flight onto the
    /// admissible set before each step; its loss booked as `D_predictor`).
    #[serde(default)]
    pub contact_predictor: Option<crate::model::ContactPredictor>,
    /// `stress` (default: the paper's walls) or `strain`; `solid` names what a
    /// three-dimensional mesh is anyway (a plane mesh refuses it).
    #[serde(default)]
    pub plane: Option<Idealisation>,
    /// `consistent` (default for the implicit schemes: the paper's Galerkin mass) or
    /// `lumped` (the only one central differences take, and their default).
    #[serde(default)]
    pub mass: Option<MassKind>,
    /// Mass damping `zeta` of eq. (4) (1/s). Default 0, as in the paper's examples.
    #[serde(default)]
    pub zeta: f64,
    /// Rayleigh coefficients `[a_m, a_k]`: `C += a_m M + a_k K`. Default none.
    #[serde(default)]
    #[serde(deserialize_with = "exact::array")]
    pub rayleigh: [f64; 2],
    /// Rayleigh damping from modal targets instead of `rayleigh`: the damping ratio
    /// `ratio` at two frequencies, given (`frequencies`, Hz) or computed
    /// (`modes`, by number, 1 the lowest; `theory/modal.md`).
    #[serde(default)]
    pub damping: Option<DampingSpec>,
    /// Gravity acceleration vector (m/s²; two components, three in a solid), applied
    /// from `t = 0`. Default none.
    #[serde(default, deserialize_with = "exact::option_vector")]
    pub gravity: Option<exact::Vector>,
    /// Write a VTK file every this many steps; 0 for none.
    #[serde(default = "default_vtk_every")]
    pub vtk_every: usize,
    /// Write a VTK file at every multiple of this time (s) instead of by steps: the
    /// steps of an error-controlled run land on those times; a fixed-step run writes
    /// the first step at or past each. Default none.
    #[serde(default)]
    pub vtk_every_time: Option<f64>,
    /// Error-controlled steps (the implicit schemes): `{ tolerance, dt_min, dt_max,
    /// norm, impact_steps }` (theory/adaptive.md). Absent: fixed steps of `dt`.
    #[serde(default)]
    pub adaptive: Option<adaptive::AdaptiveSpec>,
    /// Relative residual tolerance of the equilibrium iterations of materials with
    /// history. Default 1e-8: well below discretisation error, well above round-off.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Iteration limit per step. Default 30.
    #[serde(default = "default_max_iterations")]
    pub max_iterations: usize,
    /// Relative tolerance on the last displacement correction of nonlinear models.
    /// Default 1e-6.
    #[serde(default = "default_displacement_tolerance")]
    pub displacement_tolerance: f64,
    /// `newton` (default: refactorise every iteration) or `fixed` (factorise once
    /// per step).
    #[serde(default)]
    pub iteration: Option<crate::model::IterationMethod>,
    /// Keep the factor of the effective matrix while the iterations converge on it
    /// (modified Newton) instead of refactorising whenever the tangent of a damage
    /// or plasticity model changed: `true` (default for dynamics) or `false`
    /// (default for statics: full Newton with `iteration = "newton"`, a factor per
    /// step with `"fixed"`).
    #[serde(default)]
    pub keep_factor: Option<bool>,
    /// With a kept factor: the ratio of two successive relative residuals above
    /// which the next iterate refactorises with its tangent. Default 0.1.
    #[serde(default)]
    pub refactor_rate: Option<f64>,
    /// The smallest step a run may cut to (s): below it the run stops as stalled,
    /// naming what to try. Default `dt / 2²⁰` (about a millionth of the step).
    #[serde(default)]
    pub dt_min: Option<f64>,
    /// Step cuts (each halving `h`) allowed before the run stops. Default 8.
    #[serde(default = "default_max_cuts")]
    pub max_cuts: usize,
    /// Ordering of the faer backend: `auto` (default: nested dissection from 400k
    /// free dofs), `amd` or `nested_dissection`.
    #[serde(default)]
    pub ordering: crate::model::Ordering,
    /// Largest penetration a contact step accepts (m). Default: 1e-4 of the shortest
    /// master segment, far below the deformations contact produces.
    #[serde(default)]
    pub contact_tolerance: Option<f64>,
    /// How the contact QP is solved: `condensed` (default: the dual QP on the contact
    /// forces, `W = G K_eff⁻¹ Gᵀ` from the factor) or `full` (the primal QP over all
    /// free dofs, the reference).
    #[serde(default)]
    pub contact_qp: Option<crate::model::ContactQp>,
    /// Whether a frictional contact QP first tries the statuses (and in a solid the
    /// slip directions) the last one ended in, before the cone programs. Default
    /// true in the plane, false in a solid (theory/friction.md says why).
    #[serde(default)]
    pub friction_guess: Option<bool>,
    /// Where the implicit schemes keep the state of linear viscoelastic materials:
    /// `nodal` (default: nodal fields, a step of matrix-vector products) or `points`
    /// (the Gauss points, with each point's cumulative dissipation density in the
    /// VTK output).
    #[serde(default)]
    pub viscoelastic_state: Option<crate::model::ViscoelasticState>,
    /// The keys the `[analysis]` table gave (after variants and `--set`): a key the
    /// run will not read is a warning naming it, defaults or not.
    #[serde(skip)]
    pub given: std::collections::BTreeSet<String>,
}

fn default_displacement_tolerance() -> f64 {
    1e-6
}

fn default_max_cuts() -> usize {
    8
}

fn default_tolerance() -> f64 {
    1e-8
}

fn default_max_iterations() -> usize {
    30
}

/// Mass matrix kind.
#[derive(Clone, Copy, Debug, Deserialize, Default, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum MassKind {
    /// Consistent Galerkin mass.
    #[default]
    Consistent,
    /// Row-sum lumped mass.
    Lumped,
}

/// A material, tagged by `model`.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialSpec {
    /// Linear elasticity.
    Elastic {
        /// Young's modulus (Pa).
        #[serde(rename = "E")]
        e: f64,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
    },
    /// Kelvin-Voigt: `σ = C ε + α C ε̇` (give `alpha`, s) or `σ = C ε + β ε̇` (give
    /// `beta`, Pa·s, the paper's identity viscosity).
    KelvinVoigt {
        /// Young's modulus (Pa).
        #[serde(rename = "E")]
        e: f64,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// Stiffness-proportional viscosity time (s).
        #[serde(default)]
        alpha: Option<f64>,
        /// Identity viscosity (Pa·s).
        #[serde(default)]
        beta: Option<f64>,
    },
    /// Standard linear solid of eq. (10): parallel spring `C`, Maxwell branch with
    /// spring `α C` and dashpot `β C`.
    Sls {
        /// Young's modulus of the parallel spring (Pa).
        #[serde(rename = "E")]
        e: f64,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// Branch stiffness ratio (dimensionless).
        alpha: f64,
        /// Dashpot time (s).
        beta: f64,
    },
    /// Maxwell: spring `C` in series with dashpot `β C` (relaxation time `β`, s).
    Maxwell {
        /// Young's modulus of the spring (Pa).
        #[serde(rename = "E")]
        e: f64,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// Relaxation time (s).
        beta: f64,
    },
    /// Mazars damage (eqs. 11-13 of the paper, or the classic 1984 law): raw
    /// parameters, or `identify` with the concrete's data.
    Mazars {
        /// Young's modulus (Pa). Optional with `identify.class` (then `E_cm`).
        #[serde(rename = "E", default)]
        e: Option<f64>,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// `paper` (default) or `classic`.
        #[serde(default)]
        variant: crate::material::MazarsVariant,
        /// The concrete's data the parameters are identified from (instead of
        /// `eps_t0`, `eps_c0`, `A_t`, `B_t`, `A_c`, `B_c`).
        #[serde(default)]
        identify: Option<IdentifySpec>,
        /// Tensile threshold `ε_t^0` (classic: `κ_0`).
        #[serde(default)]
        eps_t0: Option<f64>,
        /// Compressive threshold `ε_c^0` (paper variant; default `eps_t0`).
        #[serde(default)]
        eps_c0: Option<f64>,
        /// `A_t`.
        #[serde(rename = "A_t", default)]
        a_t: Option<f64>,
        /// `B_t`.
        #[serde(rename = "B_t", default)]
        b_t: Option<f64>,
        /// `A_c`.
        #[serde(rename = "A_c", default)]
        a_c: Option<f64>,
        /// `B_c`.
        #[serde(rename = "B_c", default)]
        b_c: Option<f64>,
        /// Classic weight exponent `β` (default 1.06, the usual value).
        #[serde(default = "default_mazars_beta")]
        beta: f64,
        /// Damage cap (default 0.99999, as NOTES.md fixes).
        #[serde(default = "default_d_max")]
        d_max: f64,
        /// Fracture energy `G_f` (N/m): the crack-band variant (the tensile law
        /// softens to zero, `B_t` per element from `G_f` and the element size).
        #[serde(default)]
        fracture_energy: Option<f64>,
        /// Nonlocal averaging of the equivalent strains (local when absent).
        #[serde(default)]
        nonlocal: Option<NonlocalSpec>,
    },
    /// Rankine-Hill plasticity (plane stress): Rankine in tension, von Mises (Hill,
    /// isotropic) in compression. Give `tension` and `compression`, or `identify`.
    RankineHill {
        /// Young's modulus (Pa). Optional with `identify.class` (then `E_cm`).
        #[serde(rename = "E", default)]
        e: Option<f64>,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// Tension law.
        #[serde(default)]
        tension: Option<HardeningSpec>,
        /// Compression law.
        #[serde(default)]
        compression: Option<HardeningSpec>,
        /// The concrete's data the laws are identified from: linear tension
        /// softening by the fracture energy, Eurocode 2 in compression.
        #[serde(default)]
        identify: Option<IdentifySpec>,
    },
    /// Kelvin: the SLS without the branch spring, i.e. `σ = C ε + β C ε̇`.
    Kelvin {
        /// Young's modulus (Pa).
        #[serde(rename = "E")]
        e: f64,
        /// Poisson's ratio.
        nu: f64,
        /// Density (kg/m³).
        rho: f64,
        /// Dashpot time (s).
        beta: f64,
    },
}

fn default_mazars_beta() -> f64 {
    1.06
}

fn default_d_max() -> f64 {
    0.99999
}

/// `identify = { ... }`: a concrete's data, from which a damage or plasticity
/// material's parameters are identified (`material::identify`). Give `class`, or
/// `f_ct`, `f_cm` and `eps_c1`.
#[derive(Clone, Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct IdentifySpec {
    /// A Eurocode 2 strength class (`"C30/37"`): `f_cm`, `f_ctm`, `ε_c1`, `ε_cu1`
    /// and (when `E` is not given) `E_cm` from EN 1992-1-1 Table 3.1.
    #[serde(default)]
    pub class: Option<String>,
    /// Tensile strength (Pa).
    #[serde(default)]
    pub f_ct: Option<f64>,
    /// Mean compressive strength (Pa).
    #[serde(default)]
    pub f_cm: Option<f64>,
    /// Strain at the compressive peak.
    #[serde(default)]
    pub eps_c1: Option<f64>,
    /// Ultimate compressive strain (Rankine-Hill; default EC2's for `f_cm`).
    #[serde(default)]
    pub eps_cu1: Option<f64>,
    /// Fracture energy (N/m; Rankine-Hill; default fib Model Code 2010's
    /// `73 f_cm^0.18`).
    #[serde(default)]
    pub fracture_energy: Option<f64>,
}

/// `nonlocal = { radius = R }`: nonlocal averaging of a damage model's equivalent
/// strains over the Gauss points of its body within `R`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NonlocalSpec {
    /// Interaction radius (m).
    pub radius: f64,
}

/// A strength law of one yield surface.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case", deny_unknown_fields)]
pub enum HardeningSpec {
    /// Yield at `strength`, post-yield modulus `post_yield_modulus` (Pa) in the
    /// uniaxial diagram.
    Bilinear {
        /// Yield stress (Pa, positive).
        strength: f64,
        /// Post-yield modulus (Pa), below `E`.
        post_yield_modulus: f64,
    },
    /// Eurocode 2 compression curve.
    Ec2 {
        /// Mean compressive strength (Pa).
        f_cm: f64,
        /// Strain at peak (positive).
        eps_c1: f64,
        /// Ultimate strain (positive).
        eps_cu1: f64,
    },
    /// Linear tension softening by fracture energy over the element size.
    LinearSoftening {
        /// Tensile strength (Pa).
        strength: f64,
        /// Fracture energy (N/m).
        fracture_energy: f64,
    },
}

/// Reads, parses and validates a scenario file (refusing a model that would not
/// fit in the memory available).
pub fn load(path: &Path) -> Result<Model> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with options.
pub fn load_with(path: &Path, opts: &LoadOptions) -> Result<Model> {
    load_with_overrides(path, opts, &Overrides::none())
}

/// [`load_with`] after selecting variants and setting values ([`overrides`]).
pub fn load_with_overrides(path: &Path, opts: &LoadOptions, ov: &Overrides) -> Result<Model> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let in_file = |e: Error| match e {
        Error::Config { field, message } => Error::Config {
            field: format!("{}: {field}", path.display()),
            message,
        },
        other => other,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    from_str_with_overrides(&text, dir, opts, ov).map_err(in_file)
}

/// Parses and validates scenario text (mesh files relative to `dir`) after its
/// variants and `ov` are applied: [`load_with_overrides`] without the file.
pub fn from_str_with_overrides(
    text: &str,
    dir: &Path,
    opts: &LoadOptions,
    ov: &Overrides,
) -> Result<Model> {
    validate::build(&parse_with(text, ov)?, dir, opts)
}

/// Scenario text as a TOML table after its variants and `ov` are applied (no
/// validation): [`merged_table`] without the file.
pub fn merged_table_of(text: &str, ov: &Overrides) -> Result<toml::Table> {
    let table: toml::Table = toml::from_str(text).map_err(|e| toml_error(text, e))?;
    overrides::apply(table, ov)
}

/// The scenario file at `path` as a TOML table after its variants and `ov` are
/// applied (no validation): what a plan asks of a scenario before it runs it.
pub fn merged_table(path: &Path, ov: &Overrides) -> Result<toml::Table> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let table: toml::Table = toml::from_str(&text).map_err(|e| match toml_error(&text, e) {
        Error::Config { field, message } => Error::Config {
            field: format!("{}: {field}", path.display()),
            message,
        },
        other => other,
    })?;
    overrides::apply(table, ov)
}

/// Parses scenario text after applying `ov` (no validation). Without variants and
/// overrides this is [`parse`], whose messages give line numbers.
pub fn parse_with(text: &str, ov: &Overrides) -> Result<Scenario> {
    let table: toml::Table = toml::from_str(text).map_err(|e| toml_error(text, e))?;
    if ov.is_empty() && !table.contains_key("variants") {
        let mut s: Scenario = parse_located(text)?;
        s.analysis.given = analysis_keys(&table);
        return Ok(s);
    }
    let merged = overrides::apply(table, ov)?;
    let mut s: Scenario = serde_path_to_error::deserialize(toml::Value::Table(merged.clone()))
        .map_err(|e: serde_path_to_error::Error<toml::de::Error>| {
            let path = within_material(field_path(e.path()), e.inner().message(), || {
                Some(merged.clone())
            });
            Error::config(
                format!("{path} (after variants and --set)"),
                e.inner().message().to_string(),
            )
        })?;
    s.analysis.given = analysis_keys(&merged);
    Ok(s)
}

/// The keys of a scenario table's `[analysis]`.
fn analysis_keys(table: &toml::Table) -> std::collections::BTreeSet<String> {
    match table.get("analysis") {
        Some(toml::Value::Table(a)) => a.keys().cloned().collect(),
        _ => Default::default(),
    }
}

/// Parses scenario text (no validation). A value of the wrong type or length is
/// named by its field path and its line and column.
pub fn parse(text: &str) -> Result<Scenario> {
    parse_with(text, &Overrides::none())
}

/// Parses TOML text into any of the file types (a scenario, a material-point
/// file), naming a value of the wrong type or length by its field path and its
/// line and column.
pub fn parse_located<T: serde::de::DeserializeOwned>(text: &str) -> Result<T> {
    let de = toml::Deserializer::new(text);
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = field_path(e.path());
        let inner = e.into_inner();
        let path = within_material(path, inner.message(), || toml::from_str(text).ok());
        match inner.span() {
            Some(s) if path != "scenario" => {
                let (line, column) = line_column(text, s.start);
                Error::config(
                    format!("{path} (line {line}, column {column})"),
                    inner.message().to_string(),
                )
            }
            _ => toml_error(text, inner),
        }
    })
}

/// Parses and validates scenario text; relative mesh paths resolve against `dir`.
pub fn from_str(text: &str, dir: &Path) -> Result<Model> {
    from_str_with(text, dir, &LoadOptions::default())
}

/// [`from_str`] with options.
pub fn from_str_with(text: &str, dir: &Path, opts: &LoadOptions) -> Result<Model> {
    validate::build(&parse_with(text, &Overrides::none())?, dir, opts)
}
