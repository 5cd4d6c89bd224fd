//! The validated model a run works on: mesh, materials, supports, loads, probes and
//! analysis settings. Built from a scenario file by [`crate::config`] or directly in
//! code (tests, benches).

use crate::fe::Idealisation;
use crate::material::Material;
use crate::mesh::{Face, Mesh};

/// A scalar function of time that scales a load or a prescribed displacement.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum TimeFunction {
    /// 1 for all times.
    Constant,
    /// 0 before `at`, 1 from `at` on.
    Step {
        /// Switch-on time.
        at: f64,
    },
    /// 0 before `t0`, linear to 1 at `t1`, 1 after.
    Ramp {
        /// Start of the ramp.
        t0: f64,
        /// End of the ramp.
        t1: f64,
    },
    /// Piecewise linear through `[t, value]` points, constant outside.
    Table {
        /// Points `[t, value]` with increasing `t`.
        points: Vec<[f64; 2]>,
    },
    /// `sin(2π f t + phase)`.
    Harmonic {
        /// Frequency in Hz.
        frequency: f64,
        /// Phase in radians.
        #[serde(default)]
        phase: f64,
    },
}

impl TimeFunction {
    /// Value at time `t`.
    pub fn at(&self, t: f64) -> f64 {
        match self {
            TimeFunction::Constant => 1.0,
            TimeFunction::Step { at } => {
                if t >= *at {
                    1.0
                } else {
                    0.0
                }
            }
            TimeFunction::Ramp { t0, t1 } => {
                if t <= *t0 {
                    0.0
                } else if t >= *t1 {
                    1.0
                } else {
                    (t - t0) / (t1 - t0)
                }
            }
            TimeFunction::Table { points } => {
                // Validation keeps tables non-empty; a NaN time has no value.
                let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
                    return f64::NAN;
                };
                if t.is_nan() {
                    return f64::NAN;
                }
                if t <= first[0] {
                    return first[1];
                }
                if t >= last[0] {
                    return last[1];
                }
                let i = points.partition_point(|p| p[0] <= t);
                let (a, b) = (points[i - 1], points[i]);
                a[1] + (b[1] - a[1]) * (t - a[0]) / (b[0] - a[0])
            }
            TimeFunction::Harmonic { frequency, phase } => {
                (2.0 * std::f64::consts::PI * frequency * t + phase).sin()
            }
        }
    }
}

/// A displacement component held at `value * function(t)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Constraint {
    /// Global dof index (`d node + component`, `d` the mesh dimension).
    pub dof: usize,
    /// Amplitude.
    pub value: f64,
    /// Time function.
    pub function: TimeFunction,
}

impl Constraint {
    /// Prescribed displacement at `t`.
    pub fn at(&self, t: f64) -> f64 {
        if self.value == 0.0 {
            0.0
        } else {
            self.value * self.function.at(t)
        }
    }
}

/// A fixed spatial force pattern scaled by a time function.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    /// Label for messages.
    pub label: String,
    /// Nonzero entries `(dof, force)` of the pattern.
    pub entries: Vec<(usize, f64)>,
    /// Time function.
    pub function: TimeFunction,
}

/// Named output point: one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// Name (column prefix in `history.csv`).
    pub name: String,
    /// Node index.
    pub node: usize,
}

/// A body: a named group of element blocks with an initial velocity.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name (prefix of its sets).
    pub name: String,
    /// Initial velocity of all its nodes (`z = 0` in the plane).
    pub velocity: [f64; 3],
    /// Thickness of its continuum elements.
    pub thickness: f64,
}

/// The time scheme of a dynamic analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TimeScheme {
    /// Backward Euler (the paper's Rothe scheme, eq. 9): implicit, contact as a QP.
    #[default]
    BackwardEuler,
    /// Central differences with lumped mass and the paper's kinematic contact
    /// method: explicit, the step bounded by the critical (CFL) step.
    CentralDifference,
    /// The trapezoidal rule (Newmark's average acceleration, β = 1/4, γ = 1/2) in
    /// its averaged-force form, contact at the step's end with the multiplier fully
    /// implicit: implicit, second order, no numerical loss in linear elasticity
    /// (`theory/trapezoidal.md`).
    Trapezoidal,
    /// Chung and Hulbert's generalized-α with high-frequency dissipation set by
    /// `rho_inf` (1: the trapezoidal rule's spectrum), contact at the step's end as
    /// the trapezoidal rule's: implicit, second order, its loss booked in `D_num`
    /// (`theory/trapezoidal.md`).
    GeneralizedAlpha,
}

impl TimeScheme {
    /// Whether the scheme is implicit (a factorised effective matrix, contact as a
    /// QP): backward Euler and the trapezoidal rule.
    pub fn is_implicit(self) -> bool {
        self != TimeScheme::CentralDifference
    }
}

/// How central differences bound their step (`analysis.critical_step`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum CriticalStepRule {
    /// Element by element, `min_e 2/ω_e` (a bound below the mesh's own limit; no
    /// global computation).
    #[default]
    Element,
    /// The mesh's own limit from its largest eigenvalue (Lanczos on `M_L⁻¹K`; the
    /// damping rate from `M_L⁻¹C`): exact for undamped and stiffness-proportional
    /// damping, a bound otherwise (`modal::exact_stable_step`).
    Eigen,
}

/// What the second-order implicit schemes do with the free flight before a step
/// (`analysis.contact_predictor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ContactPredictor {
    /// The step starts from the committed velocity.
    #[default]
    None,
    /// The contact-stabilised predictor (Deuflhard, Krause and Ertel; in Klapproth's
    /// form): the free flight `u_n + h v_n` is projected in the mass norm onto the
    /// admissible set and the step starts from the velocity of the projection, so a
    /// contact node arrives at rest on its master instead of rebounding in the
    /// step; the kinetic energy the projection removes is booked as `D_predictor`
    /// (`theory/trapezoidal.md`).
    Stabilised,
}

/// Static or dynamic analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum AnalysisKind {
    /// Backward-Euler dynamics (the paper's eq. 9).
    #[default]
    Dynamic,
    /// Equilibrium `K u = f` at each load step (no inertia).
    Static,
}

/// The analysis settings, one struct per concern.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    /// What is integrated in time and how.
    pub time: TimeSettings,
    /// Mass and Rayleigh damping.
    pub damping: Damping,
    /// The equilibrium iterations of the implicit schemes and the solves they make.
    pub iteration: IterationSettings,
    /// Impenetrability.
    pub contact: ContactSettings,
    /// What a run writes besides its history.
    pub output: OutputSettings,
}

/// Time stepping.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSettings {
    /// Static or dynamic.
    pub kind: AnalysisKind,
    /// The dynamic scheme.
    pub scheme: TimeScheme,
    /// Central differences: the fraction of the critical step of the default step.
    pub omega: f64,
    /// Central differences: how the stable step is bounded.
    pub critical_step: CriticalStepRule,
    /// Generalized-α: the spectral radius at `ωh → ∞`, in `[0, 1]`.
    pub rho_inf: f64,
    /// The second-order schemes' contact predictor.
    pub contact_predictor: ContactPredictor,
    /// Step size `h`.
    pub dt: f64,
    /// Central differences: the stable step the step was chosen and checked
    /// against, with the damping the run uses (s); `None` for the implicit schemes.
    pub stable_dt: Option<f64>,
    /// End time `T`.
    pub t_end: f64,
    /// Lumped (row-sum) instead of consistent mass.
    pub lumped_mass: bool,
    /// Where the implicit schemes keep the state of linear viscoelastic materials.
    pub viscoelastic_state: ViscoelasticState,
    /// Error-controlled steps (`analysis.adaptive`; `None`: fixed steps).
    pub adaptive: Option<Adaptive>,
}

/// Error-controlled steps (`analysis.adaptive`, `theory/adaptive.md`): each step
/// judged by the scheme's local error estimate, the sizes on the ladder
/// `dt_max / 2^k`, impacts landed on as events.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// The tolerance on a step's relative error measure.
    pub tolerance: f64,
    /// The top rung (s).
    pub dt_max: f64,
    /// The smallest step wanted (s); the bottom rung is the largest `dt_max / 2^k`
    /// not below it.
    pub dt_min: f64,
    /// How a step's error is measured.
    pub norm: ErrorNorm,
    /// Steps held at the bottom rung after an impact before the step may grow.
    pub impact_steps: usize,
}

/// The numeric factors an error-controlled run keeps besides the current one.
pub const KEPT_FACTORS: usize = 3;

impl Adaptive {
    /// The ladder's rungs `dt_max / 2^k` down to the bottom.
    pub fn rungs(&self) -> usize {
        let mut h = self.dt_max;
        let mut n = 1;
        while 0.5 * h >= self.dt_min * (1.0 - 1e-12) {
            h *= 0.5;
            n += 1;
        }
        n
    }

    /// The factors kept besides the current one: one per other rung, at most
    /// [`KEPT_FACTORS`].
    pub fn kept_factors(&self) -> usize {
        (self.rungs() - 1).min(KEPT_FACTORS)
    }
}

/// The measure of a step's local error (`analysis.adaptive.norm`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ErrorNorm {
    /// `√(½ eᵀKe / E)`: the error's elastic energy relative to the state's
    /// mechanical energy (`theory/adaptive.md`).
    #[default]
    Energy,
}

/// Damping `C = ζ M + a_m M + a_k K`.
#[derive(Clone, Debug, PartialEq)]
pub struct Damping {
    /// Mass damping factor `zeta` of eq. (4): `C = zeta M`.
    pub zeta: f64,
    /// Rayleigh damping `C += a_m M + a_k K`.
    pub rayleigh: [f64; 2],
    /// What the pair was set from, when it came from modal targets.
    pub targets: Option<RayleighTargets>,
}

/// Modal targets of Rayleigh damping: the ratio and the two circular frequencies
/// (rad/s) it holds at.
pub type RayleighTargets = (f64, [f64; 2]);

impl Damping {
    /// Rayleigh's pair giving the ratio `xi` at the circular frequencies `w`:
    /// `ξ(ω) = a_m/(2ω) + a_k ω/2` equal to `xi` at both, so
    /// `a_m = 2ξ ω₁ω₂/(ω₁ + ω₂)`, `a_k = 2ξ/(ω₁ + ω₂)`.
    pub fn rayleigh_for(xi: f64, w: [f64; 2]) -> [f64; 2] {
        let s = w[0] + w[1];
        [2.0 * xi * w[0] * w[1] / s, 2.0 * xi / s]
    }

    /// The damping ratio Rayleigh's pair (and `zeta`, a mass term) gives a mode of
    /// circular frequency `w`.
    pub fn ratio_at(&self, w: f64) -> f64 {
        (self.zeta + self.rayleigh[0]) / (2.0 * w) + self.rayleigh[1] * w / 2.0
    }
}

/// Equilibrium iterations, step cuts and the factorisations they use.
#[derive(Clone, Debug, PartialEq)]
pub struct IterationSettings {
    /// Relative residual tolerance of equilibrium iterations.
    pub tolerance: f64,
    /// Iteration limit per step.
    pub max_iterations: usize,
    /// Relative tolerance on the last displacement correction.
    pub displacement_tolerance: f64,
    /// How a state-dependent tangent is followed.
    pub method: IterationMethod,
    /// Keep the factor while the iterations converge on it (`refactor_rate`), or
    /// refactorise whenever the tangent changed (`None`).
    pub refactor_rate: Option<f64>,
    /// Step cuts allowed (each halves `h`) before a run stops.
    pub max_cuts: usize,
    /// The smallest step a cut may reach (s); below it the run stops as stalled.
    pub dt_min: f64,
    /// Fill-reducing ordering for the faer backend.
    pub ordering: Ordering,
}

/// Contact settings of the analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSettings {
    /// Largest penetration a contact step accepts (m).
    pub tolerance: f64,
    /// How the contact QP is solved.
    pub qp: ContactQp,
    /// Whether a frictional QP first tries the statuses (and slip directions) its
    /// predecessor ended in, eliminations accepted only if they satisfy the whole
    /// law, before the cone programs (`analysis.friction_guess`: default true in the
    /// plane, false in a solid; false runs the cone programs only, the reference the
    /// guess is checked against).
    pub friction_guess: bool,
}

/// Output settings of the analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputSettings {
    /// Write VTK every this many steps (0: never).
    pub vtk_every: usize,
    /// Write VTK at the multiples of this time instead (s), landed on by the steps
    /// of an error-controlled run.
    pub vtk_every_time: Option<f64>,
}

/// Fill-reducing ordering of the effective matrix. Nested dissection is handed to
/// both backends; `Amd` lets each backend run its own AMD.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Ordering {
    /// Nested dissection from `AUTO_ND_DOFS` free dofs on in the plane
    /// (`AUTO_ND_DOFS_SOLID` in a solid), AMD below. On W1 the two tie at 0.5M dofs
    /// and nested dissection factorises 1.5x faster at 2M dofs, while AMD is 20 %
    /// faster at 80k dofs. In a solid the separators are planes, which AMD does not
    /// find: on W3 at 15k dofs its factor holds 8.0M entries against 6.0M, at 107k
    /// dofs 152M against 97M.
    #[default]
    Auto,
    /// faer's approximate minimum degree.
    Amd,
    /// Geometric nested dissection from the node coordinates with minimum-degree
    /// leaves, postordered (`linsolve::ordering`).
    NestedDissection,
}

/// Size from which `Ordering::Auto` picks nested dissection.
pub const AUTO_ND_DOFS: usize = 400_000;

/// Size from which `Ordering::Auto` picks nested dissection in a solid.
pub const AUTO_ND_DOFS_SOLID: usize = 10_000;

impl Ordering {
    /// Whether nested dissection is used for `n` free dofs in a mesh of dimension
    /// `dim`.
    pub fn nested_dissection(self, n: usize, dim: usize) -> bool {
        match self {
            Ordering::Auto if dim == 3 => n >= AUTO_ND_DOFS_SOLID,
            Ordering::Auto => n >= AUTO_ND_DOFS,
            Ordering::Amd => false,
            Ordering::NestedDissection => true,
        }
    }
}

/// How the equilibrium iterations of materials with a state-dependent tangent pay
/// for the linear solves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum IterationMethod {
    /// Refactorise every iteration with the material tangent (consistent for
    /// plasticity; the secant `(1 − D) C` for damage: the paper's fixed point).
    #[default]
    Newton,
    /// Factorise once per step (tangent at the start of the step) and move the
    /// stiffness change to the right-hand side.
    Fixed,
}

/// The default `analysis.refactor_rate`: the ratio of successive residuals above
/// which a kept factor is remade.
pub const DEFAULT_REFACTOR_RATE: f64 = 0.1;

impl Analysis {
    /// Number of steps `m = round(T / h)`.
    pub fn n_steps(&self) -> usize {
        (self.time.t_end / self.time.dt).round().max(1.0) as usize
    }
}

/// Everything a run needs.
#[derive(Clone, Debug)]
pub struct Model {
    /// The mesh.
    pub mesh: Mesh,
    /// Material table (blocks refer to it by index).
    pub materials: Vec<Material>,
    /// Plane stress, plane strain or solid: the kinematics of every element
    /// (`fe::kinematics`), and with it the dimension `D` and Voigt size `V`.
    pub idealisation: Idealisation,
    /// Bodies.
    pub bodies: Vec<Body>,
    /// Prescribed displacement components (fixed supports have value 0).
    pub constraints: Vec<Constraint>,
    /// Loads.
    pub loads: Vec<Load>,
    /// Gravity acceleration, applied as `M g` (constant in time).
    pub gravity: Option<[f64; 3]>,
    /// Output probes.
    pub probes: Vec<Probe>,
    /// Contact pairs and unilateral supports.
    pub contacts: Vec<ContactPair>,
    /// Analysis settings.
    pub analysis: Analysis,
    /// What the scenario gives that this analysis will not read, one sentence each
    /// naming the key (`check` and `run` print them; `summary.json` keeps them).
    pub warnings: Vec<String>,
}

/// The master side of one direction of a contact pair.
#[derive(Clone, Debug, PartialEq)]
pub enum Master {
    /// Segments (node pairs) of a deformable body, oriented with the body on their
    /// left, so `n = (Δy, −Δx)/L` points out of it.
    Segments(Vec<[usize; 2]>),
    /// A rigid line from `a` to `b` with unit normal `n` towards the slave body.
    Rigid {
        /// First end.
        a: [f64; 2],
        /// Second end.
        b: [f64; 2],
        /// Unit normal pointing to the side the slave body lies on.
        n: [f64; 2],
    },
    /// Faces of a solid (triangles or quadrilaterals), numbered counter-clockwise
    /// seen from outside, so their normal points out of the body.
    Faces {
        /// The faces.
        faces: Vec<Face>,
        /// The set's boundary edges (sorted node pairs, each an edge of one face
        /// only), where node to face ends: topology, so found once at validation
        /// (`contact::master::faces::boundary_edges`).
        boundary: Vec<[usize; 2]>,
    },
    /// A rigid plane through `point` with unit normal `n` towards the slave body: a
    /// unilateral support of a solid, unbounded.
    Plane {
        /// A point of the plane.
        point: [f64; 3],
        /// Unit normal pointing to the side the slave body lies on.
        n: [f64; 3],
    },
}

/// The slave side's surface: what the slaves are a part of.
#[derive(Clone, Debug, PartialEq)]
pub enum SlaveSurface {
    /// A node set: nodes only.
    Nodes,
    /// A plane body's edge set (oriented with its body on the left): a mortar
    /// pair's weighted gaps integrate over it.
    Segments(Vec<[usize; 2]>),
    /// A solid's face set: its nodes' tributary areas for the contact pressure.
    Faces(Vec<Face>),
}

/// One direction of a contact pair: slave nodes that may not cross the master.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSide {
    /// Slave nodes, sorted and distinct (detection looks them up by number).
    pub slaves: Vec<usize>,
    /// The surface the slaves belong to.
    pub surface: SlaveSurface,
    /// The master surface.
    pub master: Master,
}

impl ContactSide {
    /// The nodes of a deformable master (segments' or faces' corners, with
    /// repeats); none for a rigid one.
    pub fn master_nodes(&self) -> Vec<usize> {
        match &self.master {
            Master::Segments(segs) => segs.iter().flatten().copied().collect(),
            Master::Faces { faces, .. } => faces
                .iter()
                .flat_map(|f| f.corners().iter().copied())
                .collect(),
            _ => Vec::new(),
        }
    }
}

/// How a deformable pair's impenetrability is written (`theory/contact.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Segment to segment: one weighted gap per slave node, the integral of its
    /// shape function against the gap to the projected master.
    #[default]
    Mortar,
    /// Each slave node against its closest master segment (in a solid, face;
    /// `node_to_face` there reads the same).
    #[serde(alias = "node_to_face")]
    NodeToSegment,
}

/// The test functions of mortar's weighted gaps on the slave side
/// (`contact.mortar_basis`, `theory/contact.md`, "The dual basis").
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MortarBasis {
    /// Biorthogonal to the slave's shape functions over each facet's covered part:
    /// each weighted gap holds one slave node, so the rows of neighbouring slave
    /// nodes do not couple through the slave side.
    Dual,
    /// The slave's own (linear, bilinear) shape functions (the default: every
    /// figure of the theory's tables was measured with it).
    #[default]
    Standard,
}

/// A named contact pair: one side, or two (both ways), or a unilateral support.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPair {
    /// Name for output.
    pub name: String,
    /// Its directions.
    pub sides: Vec<ContactSide>,
    /// Search radius of the detection (m): the largest master segment or slave
    /// element edge.
    pub radius: f64,
    /// Central differences: friction interpolation `β` (0 frictionless, 1 sticking).
    pub friction: f64,
    /// Coulomb's friction coefficient `μ` (0: frictionless).
    pub mu: f64,
    /// How the gaps are written.
    pub formulation: Formulation,
    /// Mortar's slave-side test functions (read by mortar pairs only).
    pub mortar_basis: MortarBasis,
    /// Central differences: weight `w` of the pre-impact velocity in the position
    /// update over the time to impact.
    pub position_weight: f64,
}

/// How the implicit contact QP is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ContactQp {
    /// The dual QP on the contact forces with `W = G K_eff⁻¹ Gᵀ` from the factor.
    #[default]
    Condensed,
    /// The primal QP over all free dofs: the reference the tests compare the
    /// condensed QP with (frictionless only). Scenarios refuse it: an interior point
    /// over every free dof is accurate to its tolerance only, and steps whose contact
    /// opens stall on it.
    Full,
}

/// Where the implicit schemes keep the state of constant-tangent materials
/// (elastic, Kelvin-Voigt, standard linear solid, Maxwell, Kelvin).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ViscoelasticState {
    /// Nodal fields (the dashpot displacement `u_d`): a step costs matrix-vector
    /// products only; the Gauss-point state is built from the fields for output,
    /// without the cumulative dissipation density per point.
    #[default]
    Nodal,
    /// The Gauss points (a pass per step), with every point's cumulative
    /// dissipation density for output.
    Points,
}

impl Model {
    /// Whether the run takes generalized-α's impact steps by the trapezoidal rule
    /// (dynamics by generalized-α with contact; `theory/trapezoidal.md`): it then
    /// keeps the trapezoidal rule's factor beside its own (`memory::of_model`
    /// counts it).
    pub fn takes_impact_steps(&self) -> bool {
        let t = &self.analysis.time;
        t.kind == AnalysisKind::Dynamic
            && t.scheme == TimeScheme::GeneralizedAlpha
            && !self.contacts.is_empty()
    }

    /// Initial velocity field (per dof) from the bodies' velocities.
    pub fn initial_velocity(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.mesh.n_dofs()];
        let d = self.mesh.dim;
        for (n, &b) in self.mesh.node_body.iter().enumerate() {
            for i in 0..d {
                v[d * n + i] = self.bodies[b].velocity[i];
            }
        }
        for c in &self.constraints {
            v[c.dof] = 0.0;
        }
        v
    }
}

impl Model {
    /// Where dof `d` sits, for messages: node, coordinates, body, one element
    /// holding it, component.
    pub fn describe_dof(&self, d: usize) -> String {
        let dim = self.mesh.dim;
        format!(
            "{}, component {}",
            self.describe_node(d / dim),
            ["x", "y", "z"][d % dim]
        )
    }

    /// Where node `n` sits, for messages: coordinates, body, one element holding it.
    pub fn describe_node(&self, n: usize) -> String {
        let mesh = &self.mesh;
        let body = &self.bodies[mesh.node_body[n]].name;
        let element = mesh.blocks.iter().enumerate().find_map(|(bi, b)| {
            (0..b.elements.len())
                .find(|&e| b.elements.element(e).contains(&n))
                .map(|e| format!("block {bi} element {e}"))
        });
        let c = mesh.coords[n];
        let at = if mesh.dim == 3 {
            format!("({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
        } else {
            format!("({:.4}, {:.4})", c[0], c[1])
        };
        format!(
            "node {n} at {at} of body `{body}`, {}",
            element.unwrap_or_else(|| "no element".into()),
        )
    }

    /// Element `element` of block `block`, for messages: its body, material and the
    /// coordinates of its first node.
    pub fn describe_point(&self, block: usize, element: usize) -> String {
        let b = &self.mesh.blocks[block];
        let nodes = b.elements.element(element);
        let x = self.mesh.coords[nodes[0]];
        format!(
            "block {block} element {element} (nodes {nodes:?}, first at ({:.4}, {:.4})) of body `{}`, material `{}`",
            x[0], x[1], self.bodies[b.body].name, self.materials[b.material].name
        )
    }
}
