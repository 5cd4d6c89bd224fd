//! Contact pairs and unilateral supports: sets resolved, sides oriented, the search
//! radius and the default penetration tolerance from the geometry.

use super::checks::{finite, positive};
use crate::config::{ContactSpec, Scenario};
use crate::error::{Error, Result};
use crate::geometry::distance as dist;
use crate::mesh::Mesh;
use crate::model::{ContactPair, ContactSide, Formulation, Master};

/// The nodes of a node set or of an edge set.
fn slave_nodes(mesh: &Mesh, field: &str, name: &str) -> Result<Vec<usize>> {
    if let Some(nodes) = mesh.node_sets.get(name) {
        if nodes.is_empty() {
            return Err(Error::config(field, format!("node set `{name}` is empty")));
        }
        let mut nodes = nodes.clone();
        nodes.sort_unstable();
        nodes.dedup();
        return Ok(nodes);
    }
    if let Some(edges) = mesh.edge_sets.get(name) {
        if edges.is_empty() {
            return Err(Error::config(field, format!("edge set `{name}` is empty")));
        }
        let mut nodes: Vec<usize> = edges.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        return Ok(nodes);
    }
    Err(Error::config(
        field,
        format!(
            "unknown set `{name}` (known node sets: {}; edge sets: {})",
            mesh.node_sets
                .keys()
                .cloned()
                .collect::<Vec<_>>()
                .join(", "),
            mesh.edge_sets
                .keys()
                .cloned()
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ))
}

/// The segments of an edge set.
fn master_edges(mesh: &Mesh, field: &str, name: &str) -> Result<Vec<[usize; 2]>> {
    match mesh.edge_sets.get(name) {
        Some(e) if !e.is_empty() => Ok(e.clone()),
        Some(_) => Err(Error::config(field, format!("edge set `{name}` is empty"))),
        None if mesh.node_sets.contains_key(name) => Err(Error::config(
            field,
            format!("`{name}` is a node set; the master of a contact pair is an edge set"),
        )),
        None => Err(Error::config(
            field,
            format!(
                "unknown edge set `{name}` (known: {})",
                mesh.edge_sets
                    .keys()
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// Refuses a mortar pair whose rows need more than
/// [`crate::contact::rows::ROW_NODES`] nodes at the initial geometry: a slave node's
/// two segments facing more master segments than a row holds (the master locally
/// much finer than the slave).
fn mortar_reach(
    mesh: &Mesh,
    field: &str,
    slaves: &[usize],
    slave_segments: &[[usize; 2]],
    master: &[[usize; 2]],
    radius: f64,
) -> Result<()> {
    let mut rows = Vec::new();
    let needed = crate::contact::mortar::rows(
        (0, 0),
        slaves,
        slave_segments,
        master,
        radius,
        &|n| mesh.xy(n),
        &mut rows,
    );
    if needed > crate::contact::rows::ROW_NODES {
        return Err(Error::config(
            field,
            format!(
                "the master is too fine for mortar against this slave: a slave node's \
                 weighted gap would hold {needed} nodes, at most {} fit; refine the slave \
                 side where it faces the finer master, or give \
                 `formulation = \"node_to_segment\"`",
                crate::contact::rows::ROW_NODES
            ),
        ));
    }
    Ok(())
}

/// The body of a set of nodes, if they all belong to one.
fn body_of(mesh: &Mesh, nodes: &[usize]) -> Option<usize> {
    let b = mesh.node_body[*nodes.first()?];
    nodes.iter().all(|&n| mesh.node_body[n] == b).then_some(b)
}

/// The pairs, and the smallest master segment (or slave element) length for the
/// default tolerance.
pub(super) fn contacts(
    s: &Scenario,
    mesh: &Mesh,
    scheme: crate::model::TimeScheme,
) -> Result<(Vec<ContactPair>, f64)> {
    let mut pairs = Vec::new();
    let mut shortest = f64::INFINITY;
    for (i, c) in s.contact.iter().enumerate() {
        let field = format!("contact[{i}]");
        let ContactSpec {
            name,
            slave,
            master,
            rigid_line,
            rigid_plane,
            both_ways,
            friction,
            position_weight,
            mu,
            formulation,
        } = c;
        let mu = mu.unwrap_or(0.0);
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(Error::config(
                format!("{field}.mu"),
                format!("{mu:?} is not a friction coefficient (finite, 0 or more)"),
            ));
        }
        let explicit = scheme == crate::model::TimeScheme::CentralDifference;
        if mu > 0.0 && friction.is_some_and(|b| b != 0.0) {
            return Err(Error::config(
                format!("{field}.mu"),
                "give Coulomb's `mu` or the paper's friction interpolation `friction` (beta), \
                 not both",
            ));
        }
        let friction = friction.unwrap_or(0.0);
        let position_weight = position_weight.unwrap_or(0.5);
        for (what, v) in [("friction", friction), ("position_weight", position_weight)] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::config(
                    format!("{field}.{what}"),
                    format!("{v:?} is not in [0, 1]"),
                ));
            }
        }
        if scheme != crate::model::TimeScheme::CentralDifference {
            for (what, given) in [
                ("friction", c.friction.is_some_and(|b| b != 0.0)),
                ("position_weight", c.position_weight.is_some()),
            ] {
                if given {
                    return Err(Error::config(
                        format!("{field}.{what}"),
                        "belongs to the explicit kinematic contact (analysis.scheme = \"central_difference\"); \
                         the implicit contact's friction is Coulomb's `mu`",
                    ));
                }
            }
        }
        if name.is_empty() || name.contains(',') || name.contains('\n') {
            return Err(Error::config(
                format!("{field}.name"),
                "must be non-empty and contain no comma or line break",
            ));
        }
        if let Some(j) = s.contact[..i].iter().position(|o| &o.name == name) {
            return Err(Error::config(
                format!("{field}.name"),
                format!("duplicate contact name `{name}` (also contact[{j}])"),
            ));
        }
        if s.probes.iter().any(|p| &p.name == name) {
            return Err(Error::config(
                format!("{field}.name"),
                format!("`{name}` is a probe name too: the history columns would clash"),
            ));
        }
        if mesh.dim == 3 {
            let (sides, radius, short) = super::solid_contacts::sides(mesh, &field, c)?;
            shortest = shortest.min(short);
            pairs.push(ContactPair {
                name: name.clone(),
                sides,
                radius,
                friction,
                mu,
                formulation: Formulation::NodeToSegment,
                position_weight,
            });
            continue;
        }
        if rigid_plane.is_some() {
            return Err(Error::config(
                format!("{field}.rigid_plane"),
                "a rigid plane is a solid's support; a plane model's is `rigid_line`",
            ));
        }
        let slaves = slave_nodes(mesh, &format!("{field}.slave"), slave)?;
        let slave_size = slaves
            .iter()
            .map(|&n| mesh.element_size_at(n))
            .fold(0.0, f64::max);
        let mut sides = Vec::new();
        let mut radius = slave_size;
        match (master, rigid_line) {
            (Some(m), None) => {
                if m == slave {
                    return Err(Error::config(
                        format!("{field}.master"),
                        format!("the master `{m}` is the slave set too"),
                    ));
                }
                let edges = master_edges(mesh, &format!("{field}.master"), m)?;
                let master_nodes: Vec<usize> = edges.iter().flatten().copied().collect();
                if let (Some(a), Some(b)) = (body_of(mesh, &slaves), body_of(mesh, &master_nodes)) {
                    if a == b {
                        return Err(Error::config(
                            format!("{field}.master"),
                            "slave and master belong to one body: self-contact is not supported",
                        ));
                    }
                }
                for e in &edges {
                    let l = dist(mesh.xy(e[0]), mesh.xy(e[1]));
                    radius = radius.max(l);
                    shortest = shortest.min(l);
                }
                let mortar = match (formulation, explicit) {
                    (Some(Formulation::Mortar), true) => {
                        return Err(Error::config(
                            format!("{field}.formulation"),
                            "the explicit kinematic contact is node to segment; \
                             mortar belongs to the implicit schemes",
                        ))
                    }
                    (Some(Formulation::Mortar), false) | (None, false) => {
                        match mesh.edge_sets.get(slave) {
                            Some(e) => Some(e.clone()),
                            None if formulation.is_some() => {
                                return Err(Error::config(
                                    format!("{field}.formulation"),
                                    format!(
                                        "mortar needs the slave `{slave}` to be an edge set \
                                         (its segments carry the weights); it is a node set"
                                    ),
                                ))
                            }
                            None => None,
                        }
                    }
                    _ => None,
                };
                if let Some(slave_segments) = &mortar {
                    if *both_ways {
                        return Err(Error::config(
                            format!("{field}.both_ways"),
                            "a mortar pair is one pass (its weighted gaps hold both surfaces); \
                             give `formulation = \"node_to_segment\"` for two passes",
                        ));
                    }
                    let field = format!("{field}.formulation");
                    mortar_reach(mesh, &field, &slaves, slave_segments, &edges, radius)?;
                }
                sides.push(ContactSide {
                    slaves: slaves.clone(),
                    master: Master::Segments(edges.clone()),
                    mortar: mortar.clone().unwrap_or_default(),
                    faces: Vec::new(),
                    master_boundary: Vec::new(),
                });
                if *both_ways {
                    let back =
                        master_edges(mesh, &format!("{field}.slave"), slave).map_err(|_| {
                            Error::config(
                                format!("{field}.both_ways"),
                                format!("both ways needs the slave `{slave}` to be an edge set"),
                            )
                        })?;
                    let mut nodes = master_nodes;
                    nodes.sort_unstable();
                    nodes.dedup();
                    for e in &back {
                        let l = dist(mesh.xy(e[0]), mesh.xy(e[1]));
                        radius = radius.max(l);
                        shortest = shortest.min(l);
                    }
                    sides.push(ContactSide {
                        slaves: nodes,
                        master: Master::Segments(back),
                        mortar: Vec::new(),
                        faces: Vec::new(),
                        master_boundary: Vec::new(),
                    });
                }
            }
            (None, Some([a, b])) => {
                finite(&format!("{field}.rigid_line[0]"), a)?;
                finite(&format!("{field}.rigid_line[1]"), b)?;
                let l = dist(*a, *b);
                positive(&format!("{field}.rigid_line"), l).map_err(|_| {
                    Error::config(
                        format!("{field}.rigid_line"),
                        format!("the rigid line from {a:?} to {b:?} has zero length"),
                    )
                })?;
                if *both_ways {
                    return Err(Error::config(
                        format!("{field}.both_ways"),
                        "a rigid line is a master only",
                    ));
                }
                if *formulation == Some(Formulation::Mortar) {
                    return Err(Error::config(
                        format!("{field}.formulation"),
                        "a rigid line is straight: its gaps are the slave nodes' own \
                         (node to segment); mortar is for a deformable master",
                    ));
                }
                // The normal points to the side of the slave body's centroid.
                let body = mesh.node_body[slaves[0]];
                let (mut cx, mut cy, mut k) = (0.0, 0.0, 0.0);
                for (n, &bn) in mesh.node_body.iter().enumerate() {
                    if bn == body {
                        cx += mesh.coords[n][0];
                        cy += mesh.coords[n][1];
                        k += 1.0;
                    }
                }
                let (cx, cy) = (cx / k, cy / k);
                let t = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
                let mut n = [-t[1], t[0]];
                if (cx - a[0]) * n[0] + (cy - a[1]) * n[1] < 0.0 {
                    n = [-n[0], -n[1]];
                }
                shortest = shortest.min(slave_size);
                sides.push(ContactSide {
                    slaves,
                    master: Master::Rigid { a: *a, b: *b, n },
                    mortar: Vec::new(),
                    faces: Vec::new(),
                    master_boundary: Vec::new(),
                });
            }
            _ => {
                return Err(Error::config(
                    field,
                    "give exactly one of `master` (an edge set) or `rigid_line`",
                ))
            }
        }
        let formulation = if sides.iter().any(|s| !s.mortar.is_empty()) {
            Formulation::Mortar
        } else {
            Formulation::NodeToSegment
        };
        pairs.push(ContactPair {
            name: name.clone(),
            sides,
            radius,
            friction,
            mu,
            formulation,
            position_weight,
        });
    }
    Ok((pairs, shortest))
}
