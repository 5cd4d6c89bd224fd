//! Contact pairs and unilateral supports, in the plane and in a solid: sets
//! resolved, sides oriented, the search radius and the default penetration
//! tolerance from the geometry. One validator over the facet kind of the mesh
//! ([`Facets`]: a plane body's edges, a solid's faces) and one over the rigid
//! masters (a line in the plane, a plane in a solid).

use std::collections::BTreeMap;

use super::checks::{finite, positive};
use crate::config::{ContactSpec, MasterSpec, RigidPlaneSpec, Scenario};
use crate::error::{Error, Result};
use crate::geometry::distance;
use crate::mesh::{Face, Mesh};
use crate::model::{
    ContactPair, ContactSide, Formulation, Master, MortarBasis, SlaveSurface, TimeScheme,
};

/// The facets a deformable contact surface is made of in a mesh of one dimension.
trait Facets: Clone + Sized {
    /// A set of them, with its article: "an edge set", "a face set".
    const A_SET: &'static str;
    /// What one is: "edge", "face".
    const WHAT: &'static str;
    /// The mesh's named sets of them.
    fn sets(mesh: &Mesh) -> &BTreeMap<String, Vec<Self>>;
    /// Its nodes.
    fn nodes(&self) -> &[usize];
    /// A master made of `facets`.
    fn master(facets: Vec<Self>) -> Master;
    /// A slave surface made of `facets`.
    fn surface(facets: Vec<Self>) -> SlaveSurface;
}

impl Facets for [usize; 2] {
    const A_SET: &'static str = "an edge set";
    const WHAT: &'static str = "edge";
    fn sets(mesh: &Mesh) -> &BTreeMap<String, Vec<Self>> {
        &mesh.edge_sets
    }
    fn nodes(&self) -> &[usize] {
        self
    }
    fn master(facets: Vec<Self>) -> Master {
        Master::Segments(facets)
    }
    fn surface(facets: Vec<Self>) -> SlaveSurface {
        SlaveSurface::Segments(facets)
    }
}

impl Facets for Face {
    const A_SET: &'static str = "a face set";
    const WHAT: &'static str = "face";
    fn sets(mesh: &Mesh) -> &BTreeMap<String, Vec<Self>> {
        &mesh.face_sets
    }
    fn nodes(&self) -> &[usize] {
        self.corners()
    }
    fn master(facets: Vec<Self>) -> Master {
        Master::Faces {
            boundary: crate::contact::master::faces::boundary_edges(&facets),
            faces: facets,
        }
    }
    fn surface(facets: Vec<Self>) -> SlaveSurface {
        SlaveSurface::Faces(facets)
    }
}

/// The sorted distinct nodes of `facets`.
fn nodes_of<F: Facets>(facets: &[F]) -> Vec<usize> {
    let mut nodes: Vec<usize> = facets
        .iter()
        .flat_map(|f| f.nodes().iter().copied())
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// The longest and the shortest edge of `facets` (a segment is its own edge).
fn edge_lengths<F: Facets>(mesh: &Mesh, facets: &[F]) -> (f64, f64) {
    let (mut long, mut short) = (0.0f64, f64::INFINITY);
    for f in facets {
        let c = f.nodes();
        let edges = if c.len() == 2 { 1 } else { c.len() };
        for i in 0..edges {
            let l = distance(mesh.coords[c[i]], mesh.coords[c[(i + 1) % c.len()]]);
            long = long.max(l);
            short = short.min(l);
        }
    }
    (long, short)
}

fn known<'a>(names: impl Iterator<Item = &'a String>) -> String {
    names.cloned().collect::<Vec<_>>().join(", ")
}

/// The slave side: the nodes of a node set, or of a set of facets (then its surface
/// too: a node set given under the same name as a facet set gives the nodes).
fn slave_set<F: Facets>(
    mesh: &Mesh,
    field: &str,
    name: &str,
) -> Result<(Vec<usize>, SlaveSurface)> {
    let facets = F::sets(mesh).get(name);
    if let Some(nodes) = mesh.node_sets.get(name) {
        if nodes.is_empty() {
            return Err(Error::config(field, format!("node set `{name}` is empty")));
        }
        let mut nodes = nodes.clone();
        nodes.sort_unstable();
        nodes.dedup();
        let surface = match facets {
            Some(f) if !f.is_empty() => F::surface(f.clone()),
            _ => SlaveSurface::Nodes,
        };
        return Ok((nodes, surface));
    }
    if let Some(facets) = facets {
        if facets.is_empty() {
            return Err(Error::config(
                field,
                format!("{} set `{name}` is empty", F::WHAT),
            ));
        }
        return Ok((nodes_of(facets), F::surface(facets.clone())));
    }
    Err(Error::config(
        field,
        format!(
            "unknown set `{name}` (known node sets: {}; {} sets: {})",
            known(mesh.node_sets.keys()),
            F::WHAT,
            known(F::sets(mesh).keys())
        ),
    ))
}

/// The facets of a master set.
fn master_set<F: Facets>(mesh: &Mesh, field: &str, name: &str) -> Result<Vec<F>> {
    match F::sets(mesh).get(name) {
        Some(f) if !f.is_empty() => Ok(f.clone()),
        Some(_) => Err(Error::config(
            field,
            format!("{} set `{name}` is empty", F::WHAT),
        )),
        None if mesh.node_sets.contains_key(name) => Err(Error::config(
            field,
            format!(
                "`{name}` is a node set; the master of a contact pair is {}",
                F::A_SET
            ),
        )),
        None => Err(Error::config(
            field,
            format!(
                "unknown {} set `{name}` (known: {})",
                F::WHAT,
                known(F::sets(mesh).keys())
            ),
        )),
    }
}

/// The body of a set of nodes, if they all belong to one.
fn body_of(mesh: &Mesh, nodes: &[usize]) -> Option<usize> {
    let b = mesh.node_body[*nodes.first()?];
    nodes.iter().all(|&n| mesh.node_body[n] == b).then_some(b)
}

/// The centroid of the nodes of body `body`.
fn centroid(mesh: &Mesh, body: usize) -> [f64; 3] {
    let (mut c, mut k) = ([0.0; 3], 0.0);
    for (n, &b) in mesh.node_body.iter().enumerate() {
        if b == body {
            for i in 0..3 {
                c[i] += mesh.coords[n][i];
            }
            k += 1.0;
        }
    }
    c.map(|x| x / k)
}

/// Refuses a mortar pair whose rows need more than
/// [`crate::contact::rows::ROW_NODES`] nodes at the initial geometry: a slave node's
/// segments or faces facing more master facets than a row holds (the master locally
/// much finer than the slave).
fn mortar_reach(
    mesh: &Mesh,
    field: &str,
    slaves: &[usize],
    (surface, master): (&SlaveSurface, &Master),
    radius: f64,
    basis: MortarBasis,
) -> Result<()> {
    let mut rows = Vec::new();
    let needed = match (surface, master) {
        (SlaveSurface::Segments(s), Master::Segments(m)) => crate::contact::mortar::segment_rows(
            (0, 0),
            slaves,
            s,
            m,
            radius,
            basis,
            &|n| mesh.xy(n),
            &mut rows,
        ),
        (SlaveSurface::Faces(s), Master::Faces { faces, .. }) => {
            let x: Vec<f64> = mesh
                .coords
                .iter()
                .flat_map(|c| [c[0], c[1], c[2]])
                .collect();
            let x = crate::contact::master::Positions::new(&x, 3);
            let kept = crate::contact::master::face_tree::KeptFaces::new(faces, x, 0.0);
            crate::contact::mortar::face_rows(
                (0, 0),
                slaves,
                s,
                faces,
                &kept,
                radius,
                basis,
                x,
                &mut rows,
            )
        }
        _ => 0,
    };
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

/// A pair's sides, its search radius, its shortest master edge (for the default
/// tolerance) and its formulation.
struct Sides {
    sides: Vec<ContactSide>,
    radius: f64,
    shortest: f64,
    formulation: Formulation,
}

/// The sides of pair `field` against the deformable master set `name`, of facets
/// `F`: slaves against the master's facets, and back when `both_ways`. Mortar (a
/// plane pair's default when its slave is an edge set) takes its weighted gaps over
/// the slave's segments; a solid's pair is node to face.
fn deformable<F: Facets>(
    mesh: &Mesh,
    (field, mfield): (&str, &str),
    c: &ContactSpec,
    name: &str,
    explicit: bool,
) -> Result<Sides> {
    if name == c.slave {
        return Err(Error::config(
            mfield,
            format!("the master `{name}` is the slave set too"),
        ));
    }
    let (slaves, surface) = slave_set::<F>(mesh, &format!("{field}.slave"), &c.slave)?;
    let facets = master_set::<F>(mesh, mfield, name)?;
    let master_nodes = nodes_of(&facets);
    if let (Some(a), Some(b)) = (body_of(mesh, &slaves), body_of(mesh, &master_nodes)) {
        if a == b {
            return Err(Error::config(
                mfield,
                "slave and master belong to one body: self-contact is not supported",
            ));
        }
    }
    let slave_size = slaves
        .iter()
        .map(|&n| mesh.element_size_at(n))
        .fold(0.0, f64::max);
    let (longest, short) = edge_lengths(mesh, &facets);
    let (mut radius, mut shortest) = (slave_size.max(longest), short);
    let mortar = match c.formulation {
        Some(Formulation::Mortar) if explicit => {
            return Err(Error::config(
                format!("{field}.formulation"),
                "the explicit kinematic contact is node to segment (node to face); mortar \
                 belongs to the implicit schemes",
            ))
        }
        Some(Formulation::Mortar) if matches!(surface, SlaveSurface::Nodes) => {
            return Err(Error::config(
                format!("{field}.formulation"),
                format!(
                    "mortar needs the slave `{}` to be {} (its {}s carry the weights); it \
                     is a node set",
                    c.slave,
                    F::A_SET,
                    F::WHAT
                ),
            ))
        }
        Some(Formulation::NodeToSegment) => false,
        _ => !explicit && !matches!(surface, SlaveSurface::Nodes),
    };
    if mortar {
        if c.both_ways {
            return Err(Error::config(
                format!("{field}.both_ways"),
                "a mortar pair is one pass (its weighted gaps hold both surfaces); give \
                 `formulation = \"node_to_segment\"` for two passes",
            ));
        }
        let master = F::master(facets.clone());
        mortar_reach(
            mesh,
            &format!("{field}.formulation"),
            &slaves,
            (&surface, &master),
            radius,
            c.mortar_basis.unwrap_or_default(),
        )?;
    }
    let mut sides = vec![ContactSide {
        slaves,
        surface: surface.clone(),
        master: F::master(facets.clone()),
    }];
    if c.both_ways {
        let back = F::sets(mesh)
            .get(&c.slave)
            .filter(|f| !f.is_empty())
            .cloned()
            .ok_or_else(|| {
                Error::config(
                    format!("{field}.both_ways"),
                    format!("both ways needs the slave `{}` to be {}", c.slave, F::A_SET),
                )
            })?;
        let (longest, short) = edge_lengths(mesh, &back);
        radius = radius.max(longest);
        shortest = shortest.min(short);
        sides.push(ContactSide {
            slaves: master_nodes,
            surface: F::surface(facets),
            master: F::master(back),
        });
    }
    Ok(Sides {
        sides,
        radius,
        shortest,
        formulation: if mortar {
            Formulation::Mortar
        } else {
            Formulation::NodeToSegment
        },
    })
}

/// The side of pair `field` against a rigid line (plane) or plane (solid): its
/// normal turned towards the slave body's centroid.
fn rigid(
    mesh: &Mesh,
    (field, mfield): (&str, &str),
    c: &ContactSpec,
    master: MasterSpec,
) -> Result<Sides> {
    match (mesh.dim, master) {
        (3, MasterSpec::RigidLine(_)) => {
            return Err(Error::config(
                mfield,
                "a rigid line is a plane model's support; a solid's is `rigid_plane = { point \
                 = [x, y, z], normal = [x, y, z] }`",
            ))
        }
        (2, MasterSpec::RigidPlane(_)) => {
            return Err(Error::config(
                mfield,
                "a rigid plane is a solid's support; a plane model's is `rigid_line`",
            ))
        }
        _ => {}
    }
    let (slaves, surface) = if mesh.dim == 3 {
        slave_set::<Face>(mesh, &format!("{field}.slave"), &c.slave)?
    } else {
        slave_set::<[usize; 2]>(mesh, &format!("{field}.slave"), &c.slave)?
    };
    let slave_size = slaves
        .iter()
        .map(|&n| mesh.element_size_at(n))
        .fold(0.0, f64::max);
    let centre = centroid(mesh, mesh.node_body[slaves[0]]);
    let master = match master {
        MasterSpec::RigidLine(&[a, b]) => {
            finite(&format!("{mfield}[0]"), &a)?;
            finite(&format!("{mfield}[1]"), &b)?;
            let l = distance(a, b);
            positive(mfield, l).map_err(|_| {
                Error::config(
                    mfield,
                    format!("the rigid line from {a:?} to {b:?} has zero length"),
                )
            })?;
            if c.formulation == Some(Formulation::Mortar) {
                return Err(Error::config(
                    format!("{field}.formulation"),
                    "a rigid line is straight: its gaps are the slave nodes' own (node to \
                     segment); mortar is for a deformable master",
                ));
            }
            let t = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
            let mut n = [-t[1], t[0]];
            if (centre[0] - a[0]) * n[0] + (centre[1] - a[1]) * n[1] < 0.0 {
                n = [-n[0], -n[1]];
            }
            Master::Rigid { a, b, n }
        }
        MasterSpec::RigidPlane(plane) => {
            if c.formulation == Some(Formulation::Mortar) {
                return Err(Error::config(
                    format!("{field}.formulation"),
                    "a rigid plane is flat: its gaps are the slave nodes' own (node to \
                     face); mortar is for a deformable master",
                ));
            }
            let (point, n) = plane_of(mfield, plane, centre)?;
            Master::Plane { point, n }
        }
        MasterSpec::Set(_) => unreachable!("a deformable master"),
    };
    if c.both_ways {
        return Err(Error::config(
            format!("{field}.both_ways"),
            "a rigid line or plane is a master only",
        ));
    }
    Ok(Sides {
        sides: vec![ContactSide {
            slaves,
            surface,
            master,
        }],
        radius: slave_size,
        shortest: slave_size,
        formulation: Formulation::NodeToSegment,
    })
}

/// A rigid plane's point and unit normal, turned towards the slave body's
/// `centre`.
fn plane_of(field: &str, plane: &RigidPlaneSpec, centre: [f64; 3]) -> Result<([f64; 3], [f64; 3])> {
    let three = |what: &str, v: &[f64]| -> Result<[f64; 3]> {
        let f = format!("{field}.{what}");
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
            format!("{field}.normal"),
            format!("{raw:?} is no direction (all components zero)"),
        ));
    }
    let scaled = raw.map(|c| c / big);
    let l = (scaled[0] * scaled[0] + scaled[1] * scaled[1] + scaled[2] * scaled[2]).sqrt();
    let mut n = scaled.map(|c| c / l);
    let side: f64 = (0..3).map(|i| (centre[i] - point[i]) * n[i]).sum();
    if side < 0.0 {
        n = [-n[0], -n[1], -n[2]];
    }
    Ok((point, n))
}

/// The pairs, and the smallest master segment (or slave element) length for the
/// default tolerance.
pub(super) fn contacts(
    s: &Scenario,
    mesh: &Mesh,
    scheme: TimeScheme,
) -> Result<(Vec<ContactPair>, f64)> {
    let mut pairs = Vec::new();
    let mut shortest = f64::INFINITY;
    let explicit = scheme == TimeScheme::CentralDifference;
    for (i, c) in s.contact.iter().enumerate() {
        let field = format!("contact[{i}]");
        let name = &c.name;
        let mu = c.mu.unwrap_or(0.0);
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(Error::config(
                format!("{field}.mu"),
                format!("{mu:?} is not a friction coefficient (finite, 0 or more)"),
            ));
        }
        if mu > 0.0 && c.friction.is_some_and(|b| b != 0.0) {
            return Err(Error::config(
                format!("{field}.mu"),
                "give Coulomb's `mu` or the paper's friction interpolation `friction` (beta), \
                 not both",
            ));
        }
        let friction = c.friction.unwrap_or(0.0);
        let position_weight = c.position_weight.unwrap_or(0.5);
        for (what, v) in [("friction", friction), ("position_weight", position_weight)] {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::config(
                    format!("{field}.{what}"),
                    format!("{v:?} is not in [0, 1]"),
                ));
            }
        }
        if !explicit {
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
        let (master, mfield) = c.master_spec(&field)?;
        let fields = (field.as_str(), mfield.as_str());
        let sides = match master {
            MasterSpec::Set(m) if mesh.dim == 3 => {
                deformable::<Face>(mesh, fields, c, m, explicit)?
            }
            MasterSpec::Set(m) => deformable::<[usize; 2]>(mesh, fields, c, m, explicit)?,
            rigid_master => rigid(mesh, fields, c, rigid_master)?,
        };
        shortest = shortest.min(sides.shortest);
        if c.mortar_basis.is_some() && sides.formulation != Formulation::Mortar {
            return Err(Error::config(
                format!("{field}.mortar_basis"),
                "is read by mortar pairs only (a deformable master in the implicit \
                 schemes, `formulation = \"mortar\"`); this pair is node to segment",
            ));
        }
        pairs.push(ContactPair {
            name: name.clone(),
            sides: sides.sides,
            radius: sides.radius,
            friction,
            mu,
            formulation: sides.formulation,
            mortar_basis: c.mortar_basis.unwrap_or_default(),
            position_weight,
        });
    }
    Ok((pairs, shortest))
}
