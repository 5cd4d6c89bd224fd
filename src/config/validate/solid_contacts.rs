//! A solid's contact sides: slave node or face sets against master face sets (node
//! to face) or rigid planes.

use super::checks::finite;
use crate::config::{ContactSpec, RigidPlaneSpec};
use crate::error::{Error, Result};
use crate::mesh::{Face, Mesh};
use crate::model::{ContactSide, Formulation, Master};

/// The sides of pair `field` in a solid, its search radius and its shortest master
/// edge (for the default tolerance).
pub(super) fn sides(
    mesh: &Mesh,
    field: &str,
    c: &ContactSpec,
) -> Result<(Vec<ContactSide>, f64, f64)> {
    if c.formulation == Some(Formulation::Mortar) {
        return Err(Error::config(
            format!("{field}.formulation"),
            "a solid's contact is node to face (theory/contact3d.md): give \
             `formulation = \"node_to_segment\"` or leave it out",
        ));
    }
    if c.rigid_line.is_some() {
        return Err(Error::config(
            format!("{field}.rigid_line"),
            "a rigid line is a plane model's support; a solid's is `rigid_plane = { point \
             = [x, y, z], normal = [x, y, z] }`",
        ));
    }
    let (slaves, slave_faces) = slave_set(mesh, &format!("{field}.slave"), &c.slave)?;
    let slave_size = slaves
        .iter()
        .map(|&n| mesh.element_size_at(n))
        .fold(0.0, f64::max);
    let mut radius = slave_size;
    let mut shortest = f64::INFINITY;
    let mut sides = Vec::new();
    match (&c.master, &c.rigid_plane) {
        (Some(m), None) => {
            if *m == c.slave {
                return Err(Error::config(
                    format!("{field}.master"),
                    format!("the master `{m}` is the slave set too"),
                ));
            }
            let faces = master_faces(mesh, &format!("{field}.master"), m)?;
            let mut master_nodes: Vec<usize> = faces
                .iter()
                .flat_map(|f| f.corners().iter().copied())
                .collect();
            master_nodes.sort_unstable();
            master_nodes.dedup();
            let body = |n: &[usize]| {
                let b = mesh.node_body[n[0]];
                n.iter().all(|&k| mesh.node_body[k] == b).then_some(b)
            };
            if let (Some(a), Some(b)) = (body(&slaves), body(&master_nodes)) {
                if a == b {
                    return Err(Error::config(
                        format!("{field}.master"),
                        "slave and master belong to one body: self-contact is not supported",
                    ));
                }
            }
            let (longest, short) = edge_lengths(mesh, &faces);
            radius = radius.max(longest);
            shortest = shortest.min(short);
            sides.push(ContactSide {
                slaves: slaves.clone(),
                master: Master::Faces(faces.clone()),
                mortar: Vec::new(),
                faces: slave_faces.clone(),
                master_boundary: crate::contact::master::faces::boundary_edges(&faces),
            });
            if c.both_ways {
                if slave_faces.is_empty() {
                    return Err(Error::config(
                        format!("{field}.both_ways"),
                        format!("both ways needs the slave `{}` to be a face set", c.slave),
                    ));
                }
                let (longest, short) = edge_lengths(mesh, &slave_faces);
                radius = radius.max(longest);
                shortest = shortest.min(short);
                sides.push(ContactSide {
                    slaves: master_nodes,
                    master_boundary: crate::contact::master::faces::boundary_edges(&slave_faces),
                    master: Master::Faces(slave_faces),
                    mortar: Vec::new(),
                    faces,
                });
            }
        }
        (None, Some(plane)) => {
            if c.both_ways {
                return Err(Error::config(
                    format!("{field}.both_ways"),
                    "a rigid plane is a master only",
                ));
            }
            let (point, n) = plane_of(mesh, field, plane, &slaves)?;
            shortest = shortest.min(slave_size);
            sides.push(ContactSide {
                slaves,
                master: Master::Plane {
                    point,
                    n,
                    tangents: crate::geometry::tangents(n),
                },
                mortar: Vec::new(),
                faces: slave_faces,
                master_boundary: Vec::new(),
            });
        }
        _ => {
            return Err(Error::config(
                field,
                "give exactly one of `master` (a face set) or `rigid_plane`",
            ))
        }
    }
    Ok((sides, radius, shortest))
}

/// The nodes of a node set or a face set, and the faces of a face set.
fn slave_set(mesh: &Mesh, field: &str, name: &str) -> Result<(Vec<usize>, Vec<Face>)> {
    if let Some(faces) = mesh.face_sets.get(name) {
        if faces.is_empty() {
            return Err(Error::config(field, format!("face set `{name}` is empty")));
        }
        let mut nodes: Vec<usize> = faces
            .iter()
            .flat_map(|f| f.corners().iter().copied())
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        return Ok((nodes, faces.clone()));
    }
    if let Some(nodes) = mesh.node_sets.get(name) {
        if nodes.is_empty() {
            return Err(Error::config(field, format!("node set `{name}` is empty")));
        }
        let mut nodes = nodes.clone();
        nodes.sort_unstable();
        nodes.dedup();
        return Ok((nodes, Vec::new()));
    }
    Err(Error::config(
        field,
        format!(
            "unknown set `{name}` (known face sets: {}; node sets: {})",
            known(mesh.face_sets.keys()),
            known(mesh.node_sets.keys())
        ),
    ))
}

fn known<'a>(names: impl Iterator<Item = &'a String>) -> String {
    names.cloned().collect::<Vec<_>>().join(", ")
}

/// The faces of a face set.
fn master_faces(mesh: &Mesh, field: &str, name: &str) -> Result<Vec<Face>> {
    match mesh.face_sets.get(name) {
        Some(f) if !f.is_empty() => Ok(f.clone()),
        Some(_) => Err(Error::config(field, format!("face set `{name}` is empty"))),
        None if mesh.node_sets.contains_key(name) => Err(Error::config(
            field,
            format!("`{name}` is a node set; the master of a solid's contact pair is a face set"),
        )),
        None => Err(Error::config(
            field,
            format!(
                "unknown face set `{name}` (known: {})",
                known(mesh.face_sets.keys())
            ),
        )),
    }
}

/// The longest and the shortest edge of a set of faces.
fn edge_lengths(mesh: &Mesh, faces: &[Face]) -> (f64, f64) {
    let (mut long, mut short) = (0.0f64, f64::INFINITY);
    for f in faces {
        let c = f.corners();
        for i in 0..c.len() {
            let l = crate::geometry::distance(mesh.coords[c[i]], mesh.coords[c[(i + 1) % c.len()]]);
            long = long.max(l);
            short = short.min(l);
        }
    }
    (long, short)
}

/// A rigid plane's point and unit normal, turned towards the slave body's centroid.
fn plane_of(
    mesh: &Mesh,
    field: &str,
    plane: &RigidPlaneSpec,
    slaves: &[usize],
) -> Result<([f64; 3], [f64; 3])> {
    let three = |what: &str, v: &[f64]| -> Result<[f64; 3]> {
        let f = format!("{field}.rigid_plane.{what}");
        let a: [f64; 3] = v.try_into().map_err(|_| {
            Error::config(&f, format!("has {} entries, expected 3 (x, y, z)", v.len()))
        })?;
        finite(&f, &a)?;
        Ok(a)
    };
    let point = three("point", &plane.point)?;
    let raw = three("normal", &plane.normal)?;
    // Scaled by its largest component first, so that a normal of any magnitude
    // (1e-200 or 1e200) has a length; only the zero vector has no direction.
    let big = raw.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    if big == 0.0 {
        return Err(Error::config(
            format!("{field}.rigid_plane.normal"),
            format!("{raw:?} is no direction (all components zero)"),
        ));
    }
    let scaled = raw.map(|c| c / big);
    let l = (scaled[0] * scaled[0] + scaled[1] * scaled[1] + scaled[2] * scaled[2]).sqrt();
    let mut n = scaled.map(|c| c / l);
    let body = mesh.node_body[slaves[0]];
    let (mut c, mut k) = ([0.0; 3], 0.0);
    for (node, &b) in mesh.node_body.iter().enumerate() {
        if b == body {
            for i in 0..3 {
                c[i] += mesh.coords[node][i];
            }
            k += 1.0;
        }
    }
    let side: f64 = (0..3).map(|i| (c[i] / k - point[i]) * n[i]).sum();
    if side < 0.0 {
        n = [-n[0], -n[1], -n[2]];
    }
    Ok((point, n))
}
