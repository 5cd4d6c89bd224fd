//! Supports, prescribed displacements, loads and probes: set resolution and
//! consistency (a dof is claimed by at most one prescribed value, probes are unique
//! and lie on a body).

use std::collections::BTreeMap;

use super::checks::{check_function, finite};
use crate::assembly::loads;
use crate::config::exact::Vector;
use crate::config::{LoadSpec, Scenario};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::model::{Body, Constraint, Load, Probe, TimeFunction};

/// The nodes of set `name`; an empty set and an unknown one are told apart.
pub(super) fn node_set<'a>(mesh: &'a Mesh, field: &str, name: &str) -> Result<&'a [usize]> {
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

/// Who holds a dof, for the message when two claim it.
#[derive(Clone)]
struct Claim {
    field: String,
    constraint: Constraint,
    /// A fixed support (value zero for all times): several may hold the same dof.
    support: bool,
}

/// Supports and prescribed displacements. Supports that overlap hold the dof at zero
/// together; a prescribed displacement may not share a dof with a support or with
/// another prescribed displacement: the error names both.
pub(super) fn constraints(s: &Scenario, mesh: &Mesh) -> Result<Vec<Constraint>> {
    let mut by_dof: BTreeMap<usize, Claim> = BTreeMap::new();
    let mut claim = |dof: usize, new: Claim| -> Result<()> {
        if let Some(old) = by_dof.get(&dof) {
            if !(old.support && new.support) {
                let (n, c) = (dof / mesh.dim, ["x", "y", "z"][dof % mesh.dim]);
                return Err(Error::config(
                    &new.field,
                    format!(
                        "claims component {c} of node {n} at {}, which `{}` already holds",
                        mesh.position(n),
                        old.field
                    ),
                ));
            }
            return Ok(());
        }
        by_dof.insert(dof, new);
        Ok(())
    };
    for (i, sup) in s.supports.iter().enumerate() {
        let field = format!("supports[{i}]");
        if sup.fix.is_empty() {
            return Err(Error::config(
                format!("{field}.fix"),
                "name at least one component (\"x\", \"y\")",
            ));
        }
        if let Some(c) = sup.fix.iter().find(|c| c.index() >= mesh.dim) {
            return Err(Error::config(
                format!("{field}.fix"),
                format!("component {c:?} in a plane model (only x and y)"),
            ));
        }
        for &n in node_set(mesh, &format!("{field}.set"), &sup.set)? {
            for c in &sup.fix {
                let dof = mesh.dim * n + c.index();
                claim(
                    dof,
                    Claim {
                        field: field.clone(),
                        constraint: Constraint {
                            dof,
                            value: 0.0,
                            function: TimeFunction::Constant,
                        },
                        support: true,
                    },
                )?;
            }
        }
    }
    for (i, p) in s.prescribed.iter().enumerate() {
        let field = format!("prescribed[{i}]");
        finite(&format!("{field}.value"), &[p.value])?;
        check_function(&format!("{field}.function"), &p.function)?;
        if p.component.index() >= mesh.dim {
            return Err(Error::config(
                format!("{field}.component"),
                "component z in a plane model (only x and y)",
            ));
        }
        for &n in node_set(mesh, &format!("{field}.set"), &p.set)? {
            let dof = mesh.dim * n + p.component.index();
            claim(
                dof,
                Claim {
                    field: field.clone(),
                    constraint: Constraint {
                        dof,
                        value: p.value,
                        function: p.function.clone(),
                    },
                    support: false,
                },
            )?;
        }
    }
    Ok(by_dof.into_values().map(|c| c.constraint).collect())
}

/// Checks that a vector has as many components as the model has dimensions (two in
/// the plane, three in a solid), and that they are finite; returns `[x, y, z]`.
pub(super) fn dimensioned(dim: usize, field: &str, v: &Vector) -> Result<[f64; 3]> {
    finite(field, &v.xyz)?;
    if v.len != 0 && v.len != dim {
        let what = if dim == 2 { "a plane model" } else { "a solid" };
        return Err(Error::config(
            field,
            format!("has {} entries, expected {dim} ({what})", v.len),
        ));
    }
    Ok(v.xyz)
}

/// The non-empty named set `set` of `sets` (`what`: "edge" or "face"), or an error
/// that lists the known ones.
fn named_set<'m, T>(
    field: &str,
    what: &str,
    sets: &'m BTreeMap<String, Vec<T>>,
    set: &str,
) -> Result<&'m [T]> {
    match sets.get(set) {
        Some(e) if !e.is_empty() => Ok(e),
        Some(_) => Err(Error::config(
            format!("{field}.set"),
            format!("{what} set `{set}` is empty"),
        )),
        None => Err(Error::config(
            format!("{field}.set"),
            format!(
                "unknown {what} set `{set}` (known: {})",
                sets.keys().cloned().collect::<Vec<_>>().join(", ")
            ),
        )),
    }
}

/// The loads as force patterns scaled by their time functions.
pub(super) fn loads(s: &Scenario, mesh: &Mesh, bodies: &[Body]) -> Result<Vec<Load>> {
    let mut out = Vec::new();
    for (i, l) in s.loads.iter().enumerate() {
        let field = format!("loads[{i}]");
        let mut f = vec![0.0; mesh.n_dofs()];
        let (function, label) = match l {
            LoadSpec::Traction {
                set,
                value,
                function,
            } => {
                let value = dimensioned(mesh.dim, &format!("{field}.value"), value)?;
                if mesh.dim == 3 {
                    let faces = named_set(&field, "face", &mesh.face_sets, set)?;
                    loads::add_face_traction(mesh, faces, value, &mut f);
                    (function, format!("traction on {set}"))
                } else {
                    let edges = named_set(&field, "edge", &mesh.edge_sets, set)?;
                    let body = mesh.node_body[edges[0][0]];
                    loads::add_edge_traction(
                        mesh,
                        edges,
                        [value[0], value[1]],
                        bodies[body].thickness,
                        &mut f,
                    );
                    (function, format!("traction on {set}"))
                }
            }
            LoadSpec::Nodal {
                set,
                value,
                function,
            } => {
                let value = dimensioned(mesh.dim, &format!("{field}.value"), value)?;
                loads::add_nodal(
                    mesh.dim,
                    node_set(mesh, &format!("{field}.set"), set)?,
                    value,
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
        out.push(Load {
            label,
            entries,
            function: function.clone(),
        });
    }
    Ok(out)
}

/// The probes: unique names, each at one node; a point farther than one element
/// size from the nearest node lies on no body and is refused with its distance.
pub(super) fn probes(s: &Scenario, mesh: &Mesh) -> Result<Vec<Probe>> {
    let mut probes: Vec<Probe> = Vec::new();
    for (i, p) in s.probes.iter().enumerate() {
        let field = format!("probes[{i}]");
        if p.name.is_empty() || p.name.contains(',') || p.name.contains('\n') {
            return Err(Error::config(
                format!("{field}.name"),
                "must be non-empty and contain no comma or line break",
            ));
        }
        if let Some(j) = s.probes[..i].iter().position(|q| q.name == p.name) {
            return Err(Error::config(
                format!("{field}.name"),
                format!("duplicate probe name `{}` (also probes[{j}])", p.name),
            ));
        }
        let node = match (&p.at, &p.set) {
            (Some(x), None) => {
                let x = &dimensioned(mesh.dim, &format!("{field}.at"), x)?;
                let n = mesh
                    .nearest_node(*x)
                    .ok_or_else(|| Error::config(&field, "the mesh has no nodes"))?;
                let d = crate::mesh::distance(mesh.coords[n], *x);
                let size = mesh.element_size_at(n);
                if d > size {
                    let at = if mesh.dim == 2 {
                        format!("{:?}", [x[0], x[1]])
                    } else {
                        format!("{x:?}")
                    };
                    return Err(Error::config(
                        format!("{field}.at"),
                        format!(
                            "{at} is {d:.4e} m from the nearest node {n} at {}, farther than \
                             the size of its elements ({size:.4e} m): the point lies on no body",
                            mesh.position(n)
                        ),
                    ));
                }
                n
            }
            (None, Some(set)) => {
                let nodes = node_set(mesh, &format!("{field}.set"), set)?;
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
    Ok(probes)
}
