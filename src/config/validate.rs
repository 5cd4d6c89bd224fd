//! Scenario → model: range checks that name the field, set resolution, mesh building.

use std::collections::BTreeMap;
use std::path::Path;

use super::{Component, LoadSpec, MaterialSpec, MeshSpec, Scenario};
use crate::assembly::loads;
use crate::error::{Error, Result};
use crate::material::Material;
use crate::mesh::{gmsh, structured, ElementKind, Elements, Mesh, Part};
use crate::model::{Analysis, Body, Constraint, Load, Model, Probe, TimeFunction};

pub(crate) fn positive(field: &str, v: f64) -> Result<()> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(Error::config(
            field,
            format!("must be positive and finite, got {v}"),
        ))
    }
}

fn finite(field: &str, v: &[f64]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::config(field, format!("must be finite, got {v:?}")))
    }
}

pub(crate) fn check_elastic(field: &str, e: f64, nu: f64, rho: f64) -> Result<()> {
    positive(&format!("{field}.E"), e)?;
    positive(&format!("{field}.rho"), rho)?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(Error::config(
            format!("{field}.nu"),
            format!("Poisson's ratio must lie in (-1, 0.5), got {nu}"),
        ));
    }
    Ok(())
}

fn check_function(field: &str, f: &TimeFunction) -> Result<()> {
    match f {
        TimeFunction::Constant | TimeFunction::Step { .. } => Ok(()),
        TimeFunction::Ramp { t0, t1 } => {
            if t1 > t0 {
                Ok(())
            } else {
                Err(Error::config(
                    field,
                    format!("ramp needs t1 > t0, got t0 = {t0}, t1 = {t1}"),
                ))
            }
        }
        TimeFunction::Table { points } => {
            if points.is_empty() {
                return Err(Error::config(
                    field,
                    "table needs at least one [t, value] point",
                ));
            }
            if points.windows(2).any(|w| w[1][0] <= w[0][0]) {
                return Err(Error::config(field, "table times must increase strictly"));
            }
            finite(field, &points.iter().flatten().copied().collect::<Vec<_>>())
        }
        TimeFunction::Harmonic { frequency, .. } => {
            positive(&format!("{field}.frequency"), *frequency)
        }
    }
}

fn hardening(
    field: &str,
    spec: &super::HardeningSpec,
    e: f64,
) -> Result<crate::material::Hardening> {
    use super::HardeningSpec as S;
    use crate::material::Hardening as H;
    Ok(match *spec {
        S::Bilinear {
            strength,
            post_yield_modulus,
        } => {
            positive(&format!("{field}.strength"), strength)?;
            if !post_yield_modulus.is_finite() || post_yield_modulus.abs() >= e {
                return Err(Error::config(
                    format!("{field}.post_yield_modulus"),
                    format!("must lie in (-E, E), got {post_yield_modulus}"),
                ));
            }
            H::Bilinear {
                strength,
                post_yield_modulus,
            }
        }
        S::Ec2 {
            f_cm,
            eps_c1,
            eps_cu1,
        } => {
            positive(&format!("{field}.f_cm"), f_cm)?;
            positive(&format!("{field}.eps_c1"), eps_c1)?;
            if eps_cu1.is_nan() || eps_cu1 <= eps_c1 {
                return Err(Error::config(
                    format!("{field}.eps_cu1"),
                    format!("must exceed eps_c1 = {eps_c1}, got {eps_cu1}"),
                ));
            }
            let k = 1.05 * e * eps_c1 / f_cm;
            // The curve must stay positive (η < k) and finite (η < 1/(2−k) if k < 2)
            // up to ε_cu1.
            let eta_u = eps_cu1 / eps_c1;
            let eta_max = if k < 2.0 { k.min(1.0 / (2.0 - k)) } else { k };
            if eta_u >= eta_max {
                return Err(Error::config(
                    format!("{field}.eps_cu1"),
                    format!("the EC2 curve reaches zero strength before eps_cu1 (eps_cu1/eps_c1 = {eta_u:.3} must stay below {eta_max:.3})"),
                ));
            }
            if k <= 1.05 {
                return Err(Error::config(
                    field,
                    format!(
                        "E ε_c1 / f_cm = {:.3} must exceed 1 for the curve to start elastic",
                        k / 1.05
                    ),
                ));
            }
            H::Ec2 {
                f_cm,
                eps_c1,
                eps_cu1,
            }
        }
        S::LinearSoftening {
            strength,
            fracture_energy,
        } => {
            positive(&format!("{field}.strength"), strength)?;
            positive(&format!("{field}.fracture_energy"), fracture_energy)?;
            H::LinearSoftening {
                strength,
                fracture_energy,
            }
        }
    })
}

/// Linear tension softening needs elements smaller than `2 G_f E / f_t²`, or the
/// softening branch turns back on itself (snap-back) and the return has no solution.
fn check_crack_band(mesh: &Mesh, materials: &[Material]) -> Result<()> {
    use crate::material::{Hardening, Model};
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let mat = &materials[b.material];
        let Model::RankineHill(p) = &mat.model else {
            continue;
        };
        let Hardening::LinearSoftening {
            strength,
            fracture_energy,
        } = p.tension
        else {
            continue;
        };
        let limit = 2.0 * fracture_energy * mat.e / (strength * strength);
        for e in 0..b.elements.len() {
            let x: Vec<[f64; 2]> = b
                .elements
                .element(e)
                .iter()
                .map(|&n| mesh.coords[n])
                .collect();
            let area = 0.5
                * (0..x.len())
                    .map(|a| {
                        let c = (a + 1) % x.len();
                        x[a][0] * x[c][1] - x[c][0] * x[a][1]
                    })
                    .sum::<f64>();
            let h = area.abs().sqrt();
            if h >= limit {
                return Err(Error::config(
                    format!("materials.{}.tension.fracture_energy", mat.name),
                    format!("element {e} of block {bi} is {h:.3} m across, beyond the crack-band limit 2 G_f E / f_t² = {limit:.3} m: refine the mesh or raise G_f"),
                ));
            }
        }
    }
    Ok(())
}

/// Validates one material spec into a [`Material`]; `field` prefixes error paths.
pub fn material(name: &str, field: &str, spec: &MaterialSpec) -> Result<Material> {
    use crate::material::{Model, Viscosity};
    let with = |e, nu, rho, model| -> Result<Material> {
        check_elastic(field, e, nu, rho)?;
        Ok(Material {
            name: name.into(),
            e,
            nu,
            rho,
            model,
        })
    };
    let viscosity = |key: &str, v: f64| positive(&format!("{field}.{key}"), v);
    match *spec {
        MaterialSpec::Elastic { e, nu, rho } => with(e, nu, rho, Model::Elastic),
        MaterialSpec::KelvinVoigt {
            e,
            nu,
            rho,
            alpha,
            beta,
        } => {
            let v = match (alpha, beta) {
                (Some(a), None) => {
                    viscosity("alpha", a)?;
                    Viscosity::Proportional(a)
                }
                (None, Some(b)) => {
                    viscosity("beta", b)?;
                    Viscosity::Identity(b)
                }
                _ => {
                    return Err(Error::config(
                        field,
                        "give exactly one of `alpha` (s, η = α C) or `beta` (Pa·s, η = β I)",
                    ))
                }
            };
            with(e, nu, rho, Model::KelvinVoigt(v))
        }
        MaterialSpec::Sls {
            e,
            nu,
            rho,
            alpha,
            beta,
        } => {
            viscosity("alpha", alpha)?;
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::Sls {
                    alpha,
                    beta,
                    parallel: true,
                },
            )
        }
        MaterialSpec::Maxwell { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::Sls {
                    alpha: 1.0,
                    beta,
                    parallel: false,
                },
            )
        }
        MaterialSpec::Mazars {
            e,
            nu,
            rho,
            variant,
            eps_t0,
            eps_c0,
            a_t,
            b_t,
            a_c,
            b_c,
            beta,
            d_max,
        } => {
            use crate::material::MazarsParams;
            positive(&format!("{field}.eps_t0"), eps_t0)?;
            let eps_c0 = eps_c0.unwrap_or(eps_t0);
            positive(&format!("{field}.eps_c0"), eps_c0)?;
            for (k, v) in [("A_t", a_t), ("A_c", a_c)] {
                if !(0.0..=2.0).contains(&v) {
                    return Err(Error::config(
                        format!("{field}.{k}"),
                        format!("must lie in [0, 2], got {v}"),
                    ));
                }
            }
            positive(&format!("{field}.B_t"), b_t)?;
            positive(&format!("{field}.B_c"), b_c)?;
            positive(&format!("{field}.beta"), beta)?;
            if !(d_max > 0.0 && d_max < 1.0) {
                return Err(Error::config(
                    format!("{field}.d_max"),
                    format!("must lie in (0, 1), got {d_max}"),
                ));
            }
            with(
                e,
                nu,
                rho,
                Model::Mazars(MazarsParams {
                    variant,
                    eps_t0,
                    eps_c0,
                    a_t,
                    b_t,
                    a_c,
                    b_c,
                    beta,
                    d_max,
                }),
            )
        }
        MaterialSpec::RankineHill {
            e,
            nu,
            rho,
            ref tension,
            ref compression,
        } => {
            let tension = hardening(&format!("{field}.tension"), tension, e)?;
            let compression = hardening(&format!("{field}.compression"), compression, e)?;
            with(
                e,
                nu,
                rho,
                Model::RankineHill(crate::material::RankineHillParams {
                    tension,
                    compression,
                }),
            )
        }
        MaterialSpec::Kelvin { e, nu, rho, beta } => {
            viscosity("beta", beta)?;
            with(
                e,
                nu,
                rho,
                Model::KelvinVoigt(Viscosity::Proportional(beta)),
            )
        }
    }
}

fn node_set<'a>(mesh: &'a Mesh, field: &str, name: &str) -> Result<&'a [usize]> {
    match mesh.node_sets.get(name) {
        Some(s) if !s.is_empty() => Ok(s),
        Some(_) => Err(Error::config(field, format!("node set `{name}` is empty"))),
        None => Err(Error::config(
            field,
            format!(
                "unknown node set `{name}` (known: {})",
                mesh.node_sets
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// Builds the model of `s`; relative file names resolve against `dir`.
pub fn build(s: &Scenario, dir: &Path) -> Result<Model> {
    let a = &s.analysis;
    positive("analysis.dt", a.dt)?;
    positive("analysis.t_end", a.t_end)?;
    if a.dt > a.t_end {
        return Err(Error::config(
            "analysis.dt",
            format!("step {} exceeds t_end {}", a.dt, a.t_end),
        ));
    }
    if a.zeta < 0.0 || !a.zeta.is_finite() {
        return Err(Error::config(
            "analysis.zeta",
            format!("must be non-negative, got {}", a.zeta),
        ));
    }
    positive("analysis.tolerance", a.tolerance)?;
    positive("analysis.displacement_tolerance", a.displacement_tolerance)?;
    if a.max_iterations == 0 {
        return Err(Error::config(
            "analysis.max_iterations",
            "must be at least 1",
        ));
    }
    if a.rayleigh.iter().any(|c| *c < 0.0 || !c.is_finite()) {
        return Err(Error::config(
            "analysis.rayleigh",
            format!("coefficients must be non-negative, got {:?}", a.rayleigh),
        ));
    }
    if let Some(g) = a.gravity {
        finite("analysis.gravity", &g)?;
    }
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
    for m in &materials {
        if matches!(m.model, crate::material::Model::RankineHill(_))
            && a.plane == crate::fe::Plane::Strain
        {
            return Err(Error::config(format!("materials.{}", m.name), "Rankine-Hill plasticity is formulated in plane stress; set analysis.plane = \"stress\""));
        }
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
    let mut mesh = Mesh::default();
    let mut bodies = Vec::new();
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
        positive(&format!("{field}.thickness"), b.thickness)?;
        finite(&format!("{field}.velocity"), &b.velocity)?;
        let mat = find_material(format!("{field}.material"), &b.material)?;
        let part = body_part(&format!("{field}.mesh"), &b.mesh, dir)?;
        mesh.add_part(&part, bi, &b.name, mat, b.thickness);
        bodies.push(Body {
            name: b.name.clone(),
            velocity: b.velocity,
            thickness: b.thickness,
        });
    }
    for (i, bar) in s.bars.iter().enumerate() {
        let field = format!("bars[{i}]");
        positive(&format!("{field}.area"), bar.area)?;
        let mat = find_material(format!("{field}.material"), &bar.material)?;
        if !materials[mat].is_linear_elastic() {
            return Err(Error::config(
                format!("{field}.material"),
                "bars take an elastic material",
            ));
        }
        let body = bodies
            .iter()
            .position(|b| b.name == bar.body)
            .ok_or_else(|| {
                Error::config(
                    format!("{field}.body"),
                    format!("unknown body `{}`", bar.body),
                )
            })?;
        let len = ((bar.to[0] - bar.from[0]).powi(2) + (bar.to[1] - bar.from[1]).powi(2)).sqrt();
        positive(&format!("{field}.to"), len)?;
        let nodes = mesh.nodes_on_segment(body, bar.from, bar.to, 1e-9 * len.max(1.0));
        if nodes.len() < 2 {
            return Err(Error::config(
                field,
                format!(
                    "the line from {:?} to {:?} passes through fewer than two nodes of `{}`",
                    bar.from, bar.to, bar.body
                ),
            ));
        }
        let conn = nodes.windows(2).flat_map(|w| [w[0], w[1]]).collect();
        mesh.blocks.push(crate::mesh::Block {
            elements: Elements {
                kind: ElementKind::Bar2,
                conn,
            },
            body,
            material: mat,
            section: bar.area,
        });
        mesh.node_sets
            .insert(format!("{}.{}", bar.body, bar.name), nodes);
    }
    mesh.check_elements()?;
    check_crack_band(&mesh, &materials)?;

    // Supports and prescribed displacements; a dof named twice keeps the last.
    let mut by_dof: BTreeMap<usize, Constraint> = BTreeMap::new();
    for (i, sup) in s.supports.iter().enumerate() {
        let field = format!("supports[{i}].set");
        if sup.fix.is_empty() {
            return Err(Error::config(
                format!("supports[{i}].fix"),
                "name at least one component (\"x\", \"y\")",
            ));
        }
        for &n in node_set(&mesh, &field, &sup.set)? {
            for c in &sup.fix {
                let dof = 2 * n + (*c == Component::Y) as usize;
                by_dof.insert(
                    dof,
                    Constraint {
                        dof,
                        value: 0.0,
                        function: TimeFunction::Constant,
                    },
                );
            }
        }
    }
    for (i, p) in s.prescribed.iter().enumerate() {
        let field = format!("prescribed[{i}]");
        finite(&format!("{field}.value"), &[p.value])?;
        check_function(&format!("{field}.function"), &p.function)?;
        for &n in node_set(&mesh, &format!("{field}.set"), &p.set)? {
            let dof = 2 * n + (p.component == Component::Y) as usize;
            by_dof.insert(
                dof,
                Constraint {
                    dof,
                    value: p.value,
                    function: p.function.clone(),
                },
            );
        }
    }
    let constraints: Vec<Constraint> = by_dof.into_values().collect();

    let mut loads_out = Vec::new();
    for (i, l) in s.loads.iter().enumerate() {
        let field = format!("loads[{i}]");
        let mut f = vec![0.0; mesh.n_dofs()];
        let (function, label) = match l {
            LoadSpec::Traction {
                set,
                value,
                function,
            } => {
                finite(&format!("{field}.value"), value)?;
                let edges = match mesh.edge_sets.get(set) {
                    Some(e) if !e.is_empty() => e,
                    Some(_) => {
                        return Err(Error::config(
                            format!("{field}.set"),
                            format!("edge set `{set}` is empty"),
                        ))
                    }
                    None => {
                        return Err(Error::config(
                            format!("{field}.set"),
                            format!(
                                "unknown edge set `{set}` (known: {})",
                                mesh.edge_sets
                                    .keys()
                                    .cloned()
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        ))
                    }
                };
                let body = mesh.node_body[edges[0][0]];
                loads::add_edge_traction(&mesh, edges, *value, bodies[body].thickness, &mut f);
                (function, format!("traction on {set}"))
            }
            LoadSpec::Nodal {
                set,
                value,
                function,
            } => {
                finite(&format!("{field}.value"), value)?;
                loads::add_nodal(
                    node_set(&mesh, &format!("{field}.set"), set)?,
                    *value,
                    &mut f,
                );
                (function, format!("nodal force on {set}"))
            }
        };
        check_function(&format!("{field}.function"), function)?;
        let entries = f
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(d, v)| (d, *v))
            .collect();
        loads_out.push(Load {
            label,
            entries,
            function: function.clone(),
        });
    }

    let mut probes = Vec::new();
    for (i, p) in s.probes.iter().enumerate() {
        let field = format!("probes[{i}]");
        if p.name.is_empty() || p.name.contains(',') {
            return Err(Error::config(
                format!("{field}.name"),
                "must be non-empty and contain no comma",
            ));
        }
        let node = match (&p.at, &p.set) {
            (Some(x), None) => {
                finite(&format!("{field}.at"), x)?;
                mesh.nearest_node(*x).expect("the mesh has nodes")
            }
            (None, Some(set)) => {
                let nodes = node_set(&mesh, &format!("{field}.set"), set)?;
                if nodes.len() != 1 {
                    return Err(Error::config(
                        format!("{field}.set"),
                        format!(
                            "a probe set must hold exactly one node, `{set}` holds {}",
                            nodes.len()
                        ),
                    ));
                }
                nodes[0]
            }
            _ => return Err(Error::config(field, "give exactly one of `at` or `set`")),
        };
        probes.push(Probe {
            name: p.name.clone(),
            node,
        });
    }

    Ok(Model {
        mesh,
        materials,
        plane: a.plane,
        bodies,
        constraints,
        loads: loads_out,
        gravity: a.gravity,
        probes,
        analysis: Analysis {
            kind: a.kind,
            dt: a.dt,
            t_end: a.t_end,
            lumped_mass: a.mass == super::MassKind::Lumped,
            zeta: a.zeta,
            rayleigh: a.rayleigh,
            vtk_every: a.vtk_every,
            tolerance: a.tolerance,
            max_iterations: a.max_iterations,
            displacement_tolerance: a.displacement_tolerance,
            iteration: a.iteration,
            max_cuts: a.max_cuts,
            ordering: a.ordering,
        },
    })
}

fn body_part(field: &str, spec: &MeshSpec, dir: &Path) -> Result<Part> {
    match spec {
        MeshSpec::Rectangle {
            origin,
            size,
            divisions,
            element,
        } => {
            finite(&format!("{field}.origin"), origin)?;
            positive(&format!("{field}.size[0]"), size[0])?;
            positive(&format!("{field}.size[1]"), size[1])?;
            if divisions[0] == 0 || divisions[1] == 0 {
                return Err(Error::config(
                    format!("{field}.divisions"),
                    format!("must be at least 1 each way, got {divisions:?}"),
                ));
            }
            if *element == ElementKind::Bar2 {
                return Err(Error::config(
                    format!("{field}.element"),
                    "a rectangle is meshed with quad4 or tri3",
                ));
            }
            Ok(structured::rectangle(
                *origin,
                *size,
                divisions[0],
                divisions[1],
                *element,
            ))
        }
        MeshSpec::Gmsh { file } => {
            let path = dir.join(file);
            if !path.exists() {
                return Err(Error::config(
                    format!("{field}.file"),
                    format!("mesh file {} does not exist", path.display()),
                ));
            }
            gmsh::read(&path).map_err(|e| Error::config(format!("{field}.file"), e.to_string()))
        }
    }
}
