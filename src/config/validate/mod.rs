//! Scenario → model: range checks that name the field, set resolution, mesh building,
//! model consistency, and the memory estimate before anything large is allocated.
//!
//! The order matters: the analysis and the materials are checked first, the size of
//! every generated mesh is estimated before it is built (a mistyped `divisions`
//! must not allocate terabytes), then the meshes are built and checked, then the bars,
//! supports, loads and probes that refer to their sets.

mod adaptive;
mod checks;
mod constraints;
mod contacts;
mod damping;
mod explicit_step;
mod materials;
mod meshes;
mod unread;

use std::collections::BTreeMap;
use std::path::Path;

pub use checks::HUGE_STEPS;
pub use checks::{check_function, finite, positive};
pub use materials::material;

use super::{DampingSpec, LoadOptions, Scenario};
use crate::error::{Error, Result};
use crate::fe::{Idealisation, StrainSpace};
use crate::mesh::Mesh;
use crate::model::{
    Analysis, AnalysisKind, Body, ContactPredictor, ContactSettings, Damping, Formulation,
    IterationSettings, Model, MortarBasis, OutputSettings, TimeScheme, TimeSettings,
};

/// Builds the model of `s`; relative file names resolve against `dir`.
pub fn build(s: &Scenario, dir: &Path, opts: &LoadOptions) -> Result<Model> {
    let a = &s.analysis;
    analysis(a)?;
    if s.materials.is_empty() {
        return Err(Error::config(
            "materials",
            "at least one material is needed",
        ));
    }
    let mut materials = Vec::new();
    let mut mat_index = BTreeMap::new();
    for (name, spec) in &s.materials {
        mat_index.insert(name.clone(), materials.len());
        materials.push(material(name, &format!("materials.{name}"), spec)?);
    }
    let find_material = |field: String, name: &str| -> Result<usize> {
        mat_index.get(name).copied().ok_or_else(|| {
            Error::config(
                field,
                format!(
                    "unknown material `{name}` (known: {})",
                    mat_index.keys().cloned().collect::<Vec<_>>().join(", ")
                ),
            )
        })
    };

    if s.bodies.is_empty() {
        return Err(Error::config("bodies", "at least one body is needed"));
    }
    meshes::check_generated_size(s, &materials, &mat_index, opts)?;
    meshes::meshing_size_is_taken(s)?;
    let mut mesh = Mesh::default();
    let mut bodies = Vec::new();
    // The largest stiffness and mass products of the bodies.
    let mut largest = [0.0f64; 2];
    for (bi, b) in s.bodies.iter().enumerate() {
        let field = format!("bodies[{bi}]");
        if b.name.is_empty() || b.name.contains('.') {
            return Err(Error::config(
                format!("{field}.name"),
                "must be non-empty and contain no `.`",
            ));
        }
        if s.bodies[..bi].iter().any(|o| o.name == b.name) {
            return Err(Error::config(
                format!("{field}.name"),
                format!("duplicate body name `{}`", b.name),
            ));
        }
        if let Some(t) = b.thickness {
            positive(&format!("{field}.thickness"), t)?;
        }
        let mat = find_material(format!("{field}.material"), &b.material)?;
        let part =
            meshes::body_part(&format!("{field}.mesh"), &b.mesh, &s.meshing, dir).map_err(|e| {
                match e {
                    Error::Config { field, message } => Error::Config {
                        field,
                        message: format!("body `{}`: {message}", b.name),
                    },
                    e => e,
                }
            })?;
        let thickness = match (part.dim, b.thickness) {
            (2, Some(t)) => t,
            (2, None) => {
                return Err(Error::config(
                    format!("{field}.thickness"),
                    format!(
                        "body `{}` is plane: give its thickness (m), the length its \
                         elements stand for",
                        b.name
                    ),
                ))
            }
            (_, None) => 1.0,
            (_, Some(_)) => {
                return Err(Error::config(
                    format!("{field}.thickness"),
                    format!(
                        "body `{}` is a solid (its mesh is three-dimensional): it has no \
                         thickness; remove the key",
                        b.name
                    ),
                ))
            }
        };
        if bi > 0 && part.dim != mesh.dim {
            return Err(Error::config(
                format!("{field}.mesh"),
                format!(
                    "body `{}` is {}D but `{}` is {}D: one model has one dimension",
                    b.name, part.dim, s.bodies[0].name, mesh.dim
                ),
            ));
        }
        let plane = body_plane(a.plane, part.dim, &b.name)?;
        let velocity =
            constraints::dimensioned(part.dim, &format!("{field}.velocity"), &b.velocity)?;
        let (stiff, mass) =
            products_are_finite(&field, thickness, &materials[mat], plane, &part, a.dt)?;
        largest = [largest[0].max(stiff), largest[1].max(mass)];
        mesh.add_part(&part, bi, &b.name, mat, thickness);
        bodies.push(Body {
            name: b.name.clone(),
            velocity,
            thickness,
        });
    }
    let (rayleigh, targets) = damping::targets(a)?;
    rayleigh_is_finite(rayleigh, a.dt, largest[0], largest[1])?;
    meshes::add_bars(s, &mut mesh, &bodies, &materials, &find_material)?;
    let names: Vec<String> = bodies.iter().map(|b| b.name.clone()).collect();
    mesh.check_elements(&names)?;
    let solid = mesh.dim == 3;
    let gravity = match &a.gravity {
        Some(g) => Some(constraints::dimensioned(mesh.dim, "analysis.gravity", g)?),
        None => None,
    };
    materials::check_crack_band(&mesh, &materials)?;
    meshes::check_memory(&mesh, &materials, opts)?;

    let constraints = constraints::constraints(s, &mesh)?;
    let loads = constraints::loads(s, &mesh, &bodies)?;
    let probes = constraints::probes(s, &mesh)?;
    let (contacts, shortest) = contacts::contacts(s, &mesh, a.scheme)?;
    if a.contact_predictor == Some(crate::model::ContactPredictor::Stabilised)
        && contacts.is_empty()
    {
        return Err(Error::config(
            "analysis.contact_predictor",
            "\"stabilised\" projects the free flight onto the contact constraints, and the \
             scenario has no contact pair; remove the key",
        ));
    }
    if a.contact_qp == Some(crate::model::ContactQp::Full)
        && a.scheme != TimeScheme::CentralDifference
    {
        return Err(Error::config(
            "analysis.contact_qp",
            "the full primal QP is a reference the tests compare the condensed QP with, \
             not a solver for runs: over every free dof an interior point is as accurate \
             as its tolerance only, and steps whose contact opens stalled on it where the \
             condensed QP converges (theory/contact.md); remove the key (\"condensed\", \
             the default)",
        ));
    }
    let contact_tolerance = match a.contact_tolerance {
        Some(t) => {
            positive("analysis.contact_tolerance", t)?;
            t
        }
        None if shortest.is_finite() => 1e-4 * shortest,
        None => 1e-6,
    };

    let explicit = a.scheme == TimeScheme::CentralDifference;
    let mut model = Model {
        mesh,
        materials,
        idealisation: if solid {
            Idealisation::Solid
        } else {
            a.plane.unwrap_or_default()
        },
        bodies,
        constraints,
        loads,
        gravity,
        probes,
        contacts,
        analysis: Analysis {
            time: TimeSettings {
                kind: a.kind,
                scheme: a.scheme,
                omega: a.omega.unwrap_or(DEFAULT_OMEGA),
                critical_step: a.critical_step.unwrap_or_default(),
                rho_inf: a.rho_inf.unwrap_or(DEFAULT_RHO_INF),
                contact_predictor: a.contact_predictor.unwrap_or_default(),
                dt: a.dt.unwrap_or(f64::NAN),
                stable_dt: None,
                t_end: a.t_end,
                lumped_mass: explicit || a.mass == Some(super::MassKind::Lumped),
                viscoelastic_state: a.viscoelastic_state.unwrap_or_default(),
                adaptive: adaptive::adaptive(a)?,
            },
            damping: Damping {
                zeta: a.zeta,
                rayleigh,
                targets,
            },
            iteration: IterationSettings {
                tolerance: a.tolerance,
                max_iterations: a.max_iterations,
                displacement_tolerance: a.displacement_tolerance,
                method: a.iteration.unwrap_or_default(),
                refactor_rate: a
                    .keep_factor
                    .unwrap_or(a.kind == crate::model::AnalysisKind::Dynamic)
                    .then(|| {
                        a.refactor_rate
                            .unwrap_or(crate::model::DEFAULT_REFACTOR_RATE)
                    }),
                max_cuts: a.max_cuts,
                dt_min: match (a.dt_min, a.dt) {
                    (Some(m), _) => m,
                    (None, Some(h)) => h * DEFAULT_DT_MIN,
                    (None, None) => 0.0,
                },
                ordering: a.ordering,
            },
            contact: ContactSettings {
                tolerance: contact_tolerance,
                qp: a.contact_qp.unwrap_or_default(),
                friction_guess: a.friction_guess.unwrap_or(!solid),
            },
            output: OutputSettings {
                vtk_every: a.vtk_every,
                vtk_every_time: adaptive::vtk_every_time(a)?,
            },
        },
        warnings: Vec::new(),
    };
    model.warnings = unread::unread_keys(s, &model);
    // Rayleigh's pair from modal targets before the explicit step is chosen and
    // checked: the stable step of central differences depends on the damping that
    // will be used (theory/explicit.md).
    if let Some(DampingSpec {
        ratio,
        modes: Some([i, j]),
        ..
    }) = &a.damping
    {
        damping::modal_targets(&mut model, *ratio, [*i, *j])?;
    }
    if explicit {
        explicit_step::explicit_step(&mut model, a.dt, opts)?;
    }
    chatter_warning(&mut model);
    adaptive::impact_warning(&mut model);
    initial_overlap(&model)?;
    Ok(model)
}

/// Warns of a solid's mortar pair under a second-order scheme without the contact
/// predictor: its contact phase chatters and amplifies round-off (two backends'
/// forces part by 4 % on benchmark 1 as solids, theory/contact3d.md), unless the
/// scheme is generalized-α and the basis dual (7e-7).
fn chatter_warning(model: &mut Model) {
    let t = &model.analysis.time;
    let second_order = matches!(
        t.scheme,
        TimeScheme::Trapezoidal | TimeScheme::GeneralizedAlpha
    );
    if model.mesh.dim != 3 || !second_order || t.contact_predictor != ContactPredictor::None {
        return;
    }
    // Generalized-α damps the chatter, and the dual basis takes the coupling of a
    // row's slave nodes away: together their backends agree to 7e-7.
    let alpha = t.scheme == TimeScheme::GeneralizedAlpha;
    if let Some((i, p)) = model.contacts.iter().enumerate().find(|(_, p)| {
        p.formulation == Formulation::Mortar && !(alpha && p.mortar_basis == MortarBasis::Dual)
    }) {
        model.warnings.push(format!(
            "contact[{i}] (`{}`): mortar between solids under a second-order scheme chatters \
             in contact and its results then depend on round-off (theory/contact3d.md); \
             add `analysis.contact_predictor = \"stabilised\"`, give the pair \
             `formulation = \"node_to_face\"`, or (generalized-α) \
             `mortar_basis = \"dual\"`",
            p.name
        ));
    }
}

/// Bodies (or a body and a rigid line) must not overlap at the start: a slave node
/// deeper than the contact tolerance behind its master is refused with the pair, the
/// node and the depth. (The QP would otherwise fling it out in the first step, or
/// report an infeasible step far from the cause.)
fn initial_overlap(model: &Model) -> Result<()> {
    let mut cands = Vec::new();
    crate::contact::candidates(model, &vec![0.0; model.mesh.n_dofs()], &mut cands);
    let tol = model.analysis.contact.tolerance;
    let deepest = cands
        .iter()
        .filter(|c| c.gap < -tol)
        .min_by(|a, b| a.gap.total_cmp(&b.gap));
    let Some(c) = deepest else {
        return deep_overlap(model, tol);
    };
    let count = cands.iter().filter(|c| c.gap < -tol).count();
    let pair = &model.contacts[c.pair];
    let master = match c.master {
        crate::contact::rows::Contactee::Rigid if model.mesh.dim == 3 => {
            "its rigid plane".to_string()
        }
        crate::contact::rows::Contactee::Rigid => "its rigid line".to_string(),
        crate::contact::rows::Contactee::Segment { nodes, .. } => {
            format!("the master segment of nodes {} and {}", nodes[0], nodes[1])
        }
        crate::contact::rows::Contactee::Mortar => {
            // The master node the weighted gap leans on most.
            let near = c
                .weights
                .iter()
                .filter(|&(_, w)| w < 0.0)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map_or(String::new(), |(n, _)| format!(" near its node {n}"));
            format!("the master surface{near} (mortar)")
        }
        crate::contact::rows::Contactee::Face { nodes, .. } => format!(
            "the master face of nodes {}",
            nodes
                .corners()
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    Err(Error::config(
        format!("contact[{}]", c.pair),
        format!(
            "pair `{}`: the bodies overlap at the start: {} lies {:.3e} m behind {master} \
             ({count} slave node{} deeper than the contact tolerance {tol:.1e} m); move \
             the bodies apart (touching is fine)",
            pair.name,
            model.describe_node(c.slave),
            -c.gap,
            if count == 1 { "" } else { "s" },
        ),
    ))
}

/// The idealisation a body of dimension `dim` runs with: a solid mesh is a solid
/// (`plane = "stress"` or `"strain"` are refused there: they would be ignored), a
/// plane mesh takes the given plane, never `solid` (a plane element has three strain
/// components).
fn body_plane(given: Option<Idealisation>, dim: usize, body: &str) -> Result<Idealisation> {
    match (dim, given) {
        (3, None | Some(Idealisation::Solid)) => Ok(Idealisation::Solid),
        (3, Some(p)) => Err(Error::config(
            "analysis.plane",
            format!(
                "body `{body}` is a solid (its mesh is three-dimensional), so `plane = \"{}\"` \
                 would be ignored: remove the key (or give \"solid\")",
                p.name()
            ),
        )),
        (_, Some(Idealisation::Solid)) => Err(Error::config(
            "analysis.plane",
            format!(
                "`solid` needs a three-dimensional mesh, but body `{body}` is plane; give \
                 \"stress\" or \"strain\", or mesh the body as a solid (`box` or a Gmsh \
                 solid)"
            ),
        )),
        (_, p) => Ok(p.unwrap_or_default()),
    }
}

/// Overlaps deeper than detection's reach (`contact::overlap`): a slave inside the
/// master's body at any depth, a rigid line or plane that cuts its slave body.
fn deep_overlap(model: &Model, tol: f64) -> Result<()> {
    let Some(o) = crate::contact::overlap::deepest(&model.mesh, &model.contacts, tol) else {
        return Ok(());
    };
    Err(Error::config(
        format!("contact[{}]", o.pair),
        format!(
            "pair `{}`: the bodies overlap at the start: {} lies {:.3e} m {} ({} node{} \
             deeper than the contact tolerance {tol:.1e} m); move the bodies apart \
             (touching is fine)",
            model.contacts[o.pair].name,
            model.describe_node(o.node),
            o.depth,
            o.what,
            o.count,
            if o.count == 1 { "" } else { "s" },
        ),
    ))
}

/// A body's thickness times its material's stiffness and density (and times its
/// area) must stay finite: a thickness of 1e300 overflows the element matrices,
/// which would otherwise surface as a singular stiffness far from its cause.
fn products_are_finite(
    field: &str,
    thickness: f64,
    m: &crate::material::Material,
    idealisation: Idealisation,
    part: &crate::mesh::Part,
    dt: Option<f64>,
) -> Result<(f64, f64)> {
    let stiffness = crate::dispatch_kinematics!(idealisation, <D, V, K> =>
        K::elasticity(m.e, m.nu)
            .iter()
            .flatten()
            .fold(0.0f64, |a, c| a.max(c.abs())));
    let area: f64 = part
        .blocks
        .iter()
        .flat_map(|bl| (0..bl.len()).map(move |e| (bl, e)))
        .map(|(bl, e)| {
            let x: Vec<[f64; 3]> = bl.element(e).iter().map(|&n| part.coords[n]).collect();
            if bl.kind.dim() == 3 {
                crate::fe::element::measure(bl.kind, &x).abs()
            } else {
                crate::mesh::polygon_area(&x).abs()
            }
        })
        .sum();
    let solid = idealisation == Idealisation::Solid;
    let thick = (format!("{field}.thickness"), thickness, "m");
    let size = (
        format!("{field}.mesh"),
        area,
        if solid { "m³" } else { "m²" },
    );
    let e = (format!("materials.{}.E", m.name), m.e, "Pa");
    let rho = (format!("materials.{}.rho", m.name), m.rho, "kg/m³");
    let (stiff, mass) = (thickness * stiffness, thickness * m.rho * area);
    let per_h2 = dt.map_or(1.0, |h| 1.0 / (h * h));
    for (what, product, mut factors) in [
        ("the stiffness", stiff, vec![e]),
        ("the mass over h²", mass * per_h2, vec![rho, size]),
    ] {
        // NaN counts as beyond.
        if product.is_nan() || product.abs() >= MATRIX_LIMIT {
            // A solid has no thickness to blame; the largest factor is the culprit.
            if !solid {
                factors.push(thick.clone());
            }
            let (key, value, unit) = factors
                .iter()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .cloned()
                .expect("factors");
            let terms = factors
                .iter()
                .map(|(k, v, u)| format!("{k} = {} {u}", crate::material::sig(*v)))
                .collect::<Vec<_>>()
                .join(" × ");
            return Err(Error::config(
                key,
                format!(
                    "{} {unit} makes {what} of the body {}, beyond \
                     {MATRIX_LIMIT:e} ({terms}): the residual's squared forces would \
                     overflow",
                    crate::material::sig(value),
                    crate::material::sig(product)
                ),
            ));
        }
    }
    Ok((stiff, mass))
}

/// The largest entry an effective matrix may reach: the residual test squares
/// forces, and `1e154²` overflows. No model of a real structure comes near it
/// (steel: `E t` about 2e10 N/m, `ρ V/h²` about 1e17 kg/s² at h = 1 µs).
const MATRIX_LIMIT: f64 = 1e150;

/// Rayleigh's `a_m M + a_k K` must stay finite, and so must its share `C/h` of the
/// effective matrix: a coefficient of 1e300 would otherwise surface as a failed
/// step far from its cause.
fn rayleigh_is_finite(
    rayleigh: [f64; 2],
    dt: Option<f64>,
    stiffness: f64,
    mass: f64,
) -> Result<()> {
    let h = dt.unwrap_or(1.0);
    for (i, scale, what) in [(0, mass, "mass"), (1, stiffness, "stiffness")] {
        let c = rayleigh[i];
        let term = (c * scale / h).abs();
        if c != 0.0 && (term.is_nan() || term >= MATRIX_LIMIT) {
            return Err(Error::config(
                format!("analysis.rayleigh[{i}]"),
                format!(
                    "{c:e} times the largest {what} of the model ({scale:e}) over the step \
                     exceeds {MATRIX_LIMIT:e}: the residual's squared forces would overflow"
                ),
            ));
        }
    }
    Ok(())
}

/// Generalized-α's default spectral radius at infinity.
const DEFAULT_RHO_INF: f64 = 0.8;

/// The paper's default fraction of the critical step.
const DEFAULT_OMEGA: f64 = 0.9;

/// `t_end / dt` must fit a step counter.
fn step_count(field: &str, t_end: f64, dt: f64) -> Result<()> {
    let steps = (t_end / dt).round();
    if steps.is_nan() || steps > checks::MAX_STEPS {
        return Err(Error::config(
            field,
            format!(
                "t_end / dt = {steps:e} steps does not fit a step counter (at most 2^53); \
                 is dt in seconds?"
            ),
        ));
    }
    Ok(())
}

/// The `[analysis]` table.
fn analysis(a: &super::AnalysisSpec) -> Result<()> {
    positive("analysis.t_end", a.t_end)?;
    let explicit = a.scheme == TimeScheme::CentralDifference;
    if explicit && a.kind == AnalysisKind::Static {
        return Err(Error::config(
            "analysis.scheme",
            "central differences integrate dynamics; a static analysis has no scheme",
        ));
    }
    if explicit && a.mass == Some(super::MassKind::Consistent) {
        return Err(Error::config(
            "analysis.mass",
            "central differences need the lumped mass (they invert it per dof); omit `mass`",
        ));
    }
    if let Some(r) = a.rho_inf {
        if a.scheme != TimeScheme::GeneralizedAlpha {
            return Err(Error::config(
                "analysis.rho_inf",
                "is generalized-α's spectral radius at infinity (scheme = \"generalized_alpha\"); \
                 the other schemes read no rho_inf",
            ));
        }
        if !(0.0..=1.0).contains(&r) {
            return Err(Error::config(
                "analysis.rho_inf",
                format!("{r:?} is outside [0, 1] (1 damps nothing, 0 the most)"),
            ));
        }
    }
    if a.contact_predictor == Some(crate::model::ContactPredictor::Stabilised)
        && (a.kind == AnalysisKind::Static
            || !matches!(
                a.scheme,
                TimeScheme::Trapezoidal | TimeScheme::GeneralizedAlpha
            ))
    {
        return Err(Error::config(
            "analysis.contact_predictor",
            "\"stabilised\" is the predictor of the second-order implicit schemes \
             (scheme = \"trapezoidal\" or \"generalized_alpha\"): backward Euler's contact \
             takes no rebound to stabilise, central differences have their kinematic contact, \
             a static analysis has no free flight",
        ));
    }
    if let Some(w) = a.omega {
        if !explicit {
            return Err(Error::config(
                "analysis.omega",
                "is the explicit step's fraction of the critical step (scheme = \"central_difference\")",
            ));
        }
        positive("analysis.omega", w)?;
        if w > 1.0 {
            return Err(Error::config(
                "analysis.omega",
                format!("{w:?} is above 1: the default step would exceed the critical step"),
            ));
        }
    }
    match a.dt {
        Some(dt) => {
            positive("analysis.dt", dt)?;
            if dt > a.t_end {
                return Err(Error::config(
                    "analysis.dt",
                    format!("step {dt} exceeds t_end {}", a.t_end),
                ));
            }
            step_count("analysis.dt", a.t_end, dt)?;
        }
        None if !explicit => {
            return Err(Error::config(
                "analysis.dt",
                "missing: backward Euler and statics need the step (central differences \
                 default it to omega x the critical step)",
            ));
        }
        None => {}
    }
    checks::non_negative("analysis.zeta", a.zeta)?;
    positive("analysis.tolerance", a.tolerance)?;
    positive("analysis.displacement_tolerance", a.displacement_tolerance)?;
    if let Some(rate) = a.refactor_rate {
        if !(rate > 0.0 && rate < 1.0) {
            return Err(Error::config(
                "analysis.refactor_rate",
                format!(
                    "must lie strictly between 0 and 1 (the residual ratio of two \
                     iterations above which the factor is remade), got {rate:?}"
                ),
            ));
        }
        if a.keep_factor == Some(false) {
            return Err(Error::config(
                "analysis.refactor_rate",
                "is read only with a kept factor, but analysis.keep_factor = false",
            ));
        }
        if a.keep_factor.is_none() && a.kind == AnalysisKind::Static {
            return Err(Error::config(
                "analysis.refactor_rate",
                "is read only with a kept factor, which statics does not keep by default: \
                 give analysis.keep_factor = true beside it, or remove it",
            ));
        }
    }
    checks::count_in(
        "analysis.max_iterations",
        a.max_iterations,
        1,
        MAX_ITERATIONS,
        "corrections per step",
    )?;
    checks::count_in(
        "analysis.max_cuts",
        a.max_cuts,
        0,
        MAX_CUTS,
        "each halves the step",
    )?;
    for (i, c) in a.rayleigh.iter().enumerate() {
        checks::non_negative(&format!("analysis.rayleigh[{i}]"), *c)?;
    }
    if let Some(m) = a.dt_min {
        positive("analysis.dt_min", m)?;
        if let Some(h) = a.dt.filter(|&h| m > h) {
            return Err(Error::config(
                "analysis.dt_min",
                format!("{m:?} s exceeds the step dt = {h:?} s: no step could be taken"),
            ));
        }
        // A floor below the resolution of the time itself: near t_end a step of it
        // leaves t unchanged, so a run cut to it could never get on.
        if a.t_end / m > 2f64.powi(53) {
            return Err(Error::config(
                "analysis.dt_min",
                format!(
                    "{m:?} s is below what the time can resolve near t_end = {:?} s (a \
                     step of it leaves t unchanged); give at least {:.1e} s",
                    a.t_end,
                    a.t_end * 2f64.powi(-52)
                ),
            ));
        }
    }

    Ok(())
}

/// More corrections per step than any converging iteration needs; the residual
/// history of a step is kept for its report.
const MAX_ITERATIONS: usize = 10_000;

/// The default smallest step, relative to `dt`: 2⁻²⁰, twelve halvings beyond the
/// default eight in a row. A run that keeps cutting, succeeding and cutting again
/// (a fixed-point iteration past a softening peak) would otherwise crawl on for ever.
const DEFAULT_DT_MIN: f64 = 1.0 / 1_048_576.0;

/// Halvings in a row: 2⁻⁵⁰ of the step is far below any useful step size.
const MAX_CUTS: usize = 50;
