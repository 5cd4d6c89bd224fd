//! Gmsh `.msh` v4.1 meshes (ASCII or binary, read by [`super::msh41`]).
//!
//! 2D elements (3-node triangles, 4-node quadrilaterals) become the part's elements;
//! physical groups become sets: a physical surface gives a node set, a physical curve
//! gives a node set and an edge set (its 2-node line elements), a physical point gives
//! a node set. Sets are named by their `$PhysicalNames` entry, or `physical_<dim>_<tag>`
//! when the file names none; a named group without elements is an empty set.
//! Elements given clockwise are turned counter-clockwise. Every node gets the
//! coordinates its own block lists beside its tag, whatever the order of the tags.
//! The file's node and element tags are kept for messages. Refused, naming the tag: a
//! node tag defined twice, an element using a tag never defined, an element tag used
//! twice, a surface element listed twice (the same nodes), two physical groups of one
//! name, a node off the plane `z = 0`. The part is then checked (finite coordinates,
//! every node in an element, no degenerate or distorted element) before it is used.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::msh41::{self, MshFile};
use super::{ElementKind, Elements, Face, Part};
use crate::error::{Error, Result};

/// Reads a Gmsh v4.1 file into a [`Part`].
pub fn read(path: &Path) -> Result<Part> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let part = parse(&bytes).map_err(|m| Error::Mesh(format!("{}: {m}", path.display())))?;
    part.check()
        .map_err(|m| Error::Mesh(format!("{}: {m}", path.display())))?;
    Ok(part)
}

/// Parses the bytes of a Gmsh v4.1 file into a [`Part`].
pub fn parse(bytes: &[u8]) -> std::result::Result<Part, String> {
    let msh = msh41::parse(bytes).map_err(|e| format!("not a valid MSH 4.1 file: {e}"))?;
    if !msh.has_nodes {
        return Err("the file has no $Nodes section".into());
    }
    if !msh.has_elements {
        return Err("the file has no $Elements section".into());
    }
    // A file with any volume element is a solid, whatever its types: the solid
    // reader names the volume types it does not take (a plane reading would blame
    // the nodes for lying off z = 0).
    if msh
        .element_blocks
        .iter()
        .any(|b| b.entity_dim == 3 || is_volume_type(b.element_type))
    {
        return parse_solid(&msh);
    }
    let (coords, node_tags, tag_to_index) = nodes(&msh, false)?;
    let set_names = group_names(&msh)?;
    let (mut quads, mut quad_tags) = (Vec::new(), Vec::new());
    let (mut tris, mut tri_tags) = (Vec::new(), Vec::new());
    let mut edge_sets: BTreeMap<String, Vec<[usize; 2]>> = BTreeMap::new();
    let mut surface_elements: HashMap<Vec<usize>, u64> = HashMap::new();
    let node_sets = walk_elements(&msh, &tag_to_index, &set_names, |el| {
        let (tag, ns) = (el.tag, &mut *el.nodes);
        match el.element_type {
            3 | 2 => {
                let mut key = ns.clone();
                key.sort_unstable();
                if let Some(first) = surface_elements.insert(key, tag) {
                    return Err(format!(
                        "elements with Gmsh tags {first} and {tag} have the same nodes \
                         (an element listed twice)"
                    ));
                }
                let (list, tags) = if ns.len() == 4 {
                    (&mut quads, &mut quad_tags)
                } else {
                    (&mut tris, &mut tri_tags)
                };
                if signed_area(&coords, ns) < 0.0 {
                    ns[1..].reverse();
                }
                list.extend_from_slice(ns);
                tags.push(tag);
            }
            1 => {
                for g in el.groups {
                    edge_sets.entry(g.clone()).or_default().push([ns[0], ns[1]]);
                }
            }
            15 => {}
            other => {
                return Err(format!(
                    "element with Gmsh tag {tag} has type {other} ({}), which a 2D \
                     model does not take (use 3-node triangles, 4-node quadrilaterals \
                     and 2-node lines)",
                    type_name(other)
                ))
            }
        }
        Ok(())
    })?;
    // A named group of lines without elements is an empty edge set.
    for (dim, _, name) in &msh.physical_names {
        if *dim == 1 {
            edge_sets.entry(name.clone()).or_default();
        }
    }
    let mut blocks = Vec::new();
    if !quads.is_empty() {
        blocks.push(Elements {
            kind: ElementKind::Quad4,
            conn: quads,
            tags: Some(quad_tags),
        });
    }
    if !tris.is_empty() {
        blocks.push(Elements {
            kind: ElementKind::Tri3,
            conn: tris,
            tags: Some(tri_tags),
        });
    }
    if blocks.is_empty() {
        return Err(
            "the file has no 2D elements (3-node triangles or 4-node quadrilaterals)".into(),
        );
    }
    orient_edges(&blocks, &mut edge_sets);
    Ok(Part {
        dim: 2,
        coords,
        blocks,
        node_sets,
        edge_sets,
        face_sets: BTreeMap::new(),
        node_tags: Some(node_tags),
    })
}

/// One element of the file as [`walk_elements`] hands it over.
struct FileElement<'a> {
    /// Gmsh element type.
    element_type: i32,
    /// Element tag.
    tag: u64,
    /// Node indices (the visitor may renumber them).
    nodes: &'a mut Vec<usize>,
    /// The set names of the element's physical groups.
    groups: &'a [String],
}

/// Walks every element of the file: refuses a tag used twice or a node tag no block
/// defines, maps the node tags to indices, hands the element to `visit`, and adds
/// its nodes to the node set of each of its physical groups. Returns the node sets,
/// sorted, with an empty set for every named group that has no element.
fn walk_elements(
    msh: &MshFile,
    tag_to_index: &HashMap<u64, usize>,
    set_names: &HashMap<(i32, i32), String>,
    mut visit: impl FnMut(FileElement) -> std::result::Result<(), String>,
) -> std::result::Result<BTreeMap<String, Vec<usize>>, String> {
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut seen: HashMap<u64, ()> = HashMap::new();
    let mut ns = Vec::new();
    for block in &msh.element_blocks {
        let dim = block.entity_dim;
        let groups: Vec<String> = msh
            .entity_groups
            .get(&(dim, block.entity_tag))
            .map(|gs| {
                gs.iter()
                    .map(|&g| {
                        set_names
                            .get(&(dim, g))
                            .cloned()
                            .unwrap_or_else(|| format!("physical_{dim}_{g}"))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let per = block.nodes_per_element;
        for (e, &tag) in block.tags.iter().enumerate() {
            if seen.insert(tag, ()).is_some() {
                return Err(format!("element tag {tag} is used by two elements"));
            }
            ns.clear();
            for &t in &block.nodes[e * per..(e + 1) * per] {
                ns.push(tag_to_index.get(&t).copied().ok_or_else(|| {
                    format!(
                        "element with Gmsh tag {tag} refers to node tag {t}, which no node \
                         block defines"
                    )
                })?);
            }
            visit(FileElement {
                element_type: block.element_type,
                tag,
                nodes: &mut ns,
                groups: &groups,
            })?;
            for g in &groups {
                node_sets
                    .entry(g.clone())
                    .or_default()
                    .extend_from_slice(&ns);
            }
        }
    }
    for nodes in node_sets.values_mut() {
        nodes.sort_unstable();
        nodes.dedup();
    }
    for (_, _, name) in &msh.physical_names {
        node_sets.entry(name.clone()).or_default();
    }
    Ok(node_sets)
}

/// A file with volume elements: a solid part of 4-node tetrahedra and 8-node
/// hexahedra (each renumbered to positive volume if the file lists it the other way
/// round), its 3- and 4-node surface elements as face sets of their physical groups
/// (oriented outwards from the volume element they bound), and every physical
/// group's nodes as a node set. Other element types are refused by name.
fn parse_solid(msh: &MshFile) -> std::result::Result<Part, String> {
    let (coords, node_tags, tag_to_index) = nodes(msh, true)?;
    let set_names = group_names(msh)?;
    let mut volumes: [(Vec<usize>, Vec<u64>); 2] = Default::default();
    let mut faces: Vec<(String, Face, u64)> = Vec::new();
    let mut volume_elements: HashMap<Vec<usize>, u64> = HashMap::new();
    let node_sets = walk_elements(msh, &tag_to_index, &set_names, |el| {
        let (tag, ns) = (el.tag, &mut *el.nodes);
        match el.element_type {
            4 | 5 => {
                let mut key = ns.clone();
                key.sort_unstable();
                if let Some(first) = volume_elements.insert(key, tag) {
                    return Err(format!(
                        "elements with Gmsh tags {first} and {tag} have the same nodes \
                         (an element listed twice would count its stiffness and mass twice)"
                    ));
                }
                let (kind, slot) = if ns.len() == 4 {
                    (ElementKind::Tet4, 0)
                } else {
                    (ElementKind::Hex8, 1)
                };
                let x: Vec<[f64; 3]> = ns.iter().map(|&n| coords[n]).collect();
                if crate::fe::element::measure(kind, &x) < 0.0 {
                    // The mirror numbering: swap within each face's cycle.
                    if kind == ElementKind::Tet4 {
                        ns.swap(1, 2);
                    } else {
                        ns.swap(1, 3);
                        ns.swap(5, 7);
                    }
                }
                volumes[slot].0.extend_from_slice(ns);
                volumes[slot].1.push(tag);
            }
            2 | 3 => {
                let f = Face::from_corners(ns).expect("a triangle's or quadrilateral's nodes");
                for g in el.groups {
                    faces.push((g.clone(), f, tag));
                }
            }
            1 | 15 => {}
            other => {
                return Err(format!(
                    "element with Gmsh tag {tag} has type {other} ({}), which a solid \
                     model does not take (use 4-node tetrahedra, 8-node hexahedra, \
                     3-node triangles and 4-node quadrilaterals)",
                    type_name(other)
                ))
            }
        }
        Ok(())
    })?;
    let mut blocks = Vec::new();
    for (kind, (conn, tags)) in [ElementKind::Tet4, ElementKind::Hex8]
        .into_iter()
        .zip(volumes)
    {
        if !conn.is_empty() {
            blocks.push(Elements {
                kind,
                conn,
                tags: Some(tags),
            });
        }
    }
    if blocks.is_empty() {
        return Err(
            "the file has no volume elements (4-node tetrahedra or 8-node \
                    hexahedra)"
                .into(),
        );
    }
    let mut face_sets = oriented_faces(&blocks, &coords, faces)?;
    // A named surface group without elements is an empty face set (said so where it
    // is used), not an unknown name.
    for (dim, _, name) in &msh.physical_names {
        if *dim == 2 {
            face_sets.entry(name.clone()).or_default();
        }
    }
    Ok(Part {
        dim: 3,
        coords,
        blocks,
        node_sets,
        edge_sets: BTreeMap::new(),
        face_sets,
        node_tags: Some(node_tags),
    })
}

/// The face sets with every face turned to point away from the volume element it
/// lies on: the element one of whose faces holds all its corners (a triangle on a
/// hexahedron's quadrilateral face included). A face on no element's boundary is
/// refused with its tag: its outward side would be a guess, and contact reads the
/// normal from it.
fn oriented_faces(
    blocks: &[Elements],
    coords: &[[f64; 3]],
    faces: Vec<(String, Face, u64)>,
) -> std::result::Result<BTreeMap<String, Vec<Face>>, String> {
    use crate::geometry::{cross, dot, sub};
    // The elements (block, index) at each node.
    let mut at_node: HashMap<usize, Vec<(usize, usize)>> = HashMap::new();
    for (bi, b) in blocks.iter().enumerate() {
        for e in 0..b.len() {
            for &k in b.element(e) {
                at_node.entry(k).or_default().push((bi, e));
            }
        }
    }
    let lies_on = |corners: &[usize], bi: usize, e: usize| {
        let el = blocks[bi].element(e);
        blocks[bi]
            .kind
            .faces()
            .iter()
            .any(|f| corners.iter().all(|c| f.iter().any(|&a| el[a] == *c)))
    };
    let mut out: BTreeMap<String, Vec<Face>> = BTreeMap::new();
    for (name, mut f, tag) in faces {
        let owner = at_node
            .get(&f[0])
            .and_then(|els| els.iter().find(|&&(bi, e)| lies_on(f.corners(), bi, e)));
        let Some(&(bi, e)) = owner else {
            return Err(format!(
                "surface element with Gmsh tag {tag} (group `{name}`) does not lie on a \
                 face of any volume element, so its outward side is unknown: mesh the \
                 surface on the volume's boundary"
            ));
        };
        let el = blocks[bi].element(e);
        let centre = el.iter().fold([0.0; 3], |c, &k| {
            let x = coords[k];
            [c[0] + x[0], c[1] + x[1], c[2] + x[2]]
        });
        let centre = centre.map(|c| c / el.len() as f64);
        let normal = cross(
            sub(coords[f[1]], coords[f[0]]),
            sub(coords[f[2]], coords[f[0]]),
        );
        let out_dir = sub(coords[f[0]], centre);
        if dot(normal, out_dir) < 0.0 {
            f.corners_mut()[1..].reverse();
        }
        out.entry(name).or_default().push(f);
    }
    Ok(out)
}

/// Whether a Gmsh element type is a volume element (of any order).
fn is_volume_type(t: i32) -> bool {
    matches!(t, 4..=7 | 11..=14 | 17..=19 | 29..=31 | 92 | 93)
}

/// Orients every edge of the edge sets with its element on the left (the element's
/// counter-clockwise order), as the rectangle meshes give them: contact takes a
/// segment's outward normal from its direction. Gmsh lists a curve's lines in the
/// curve's own direction, which is the other one for half of a body's boundary. An
/// edge of no element (an interior line of the file) keeps the file's direction.
fn orient_edges(blocks: &[Elements], edge_sets: &mut BTreeMap<String, Vec<[usize; 2]>>) {
    let mut directed = std::collections::HashSet::new();
    for b in blocks {
        let n = b.kind.nodes();
        for e in b.conn.chunks(n) {
            for k in 0..n {
                directed.insert((e[k], e[(k + 1) % n]));
            }
        }
    }
    for edges in edge_sets.values_mut() {
        for e in edges.iter_mut() {
            if !directed.contains(&(e[0], e[1])) && directed.contains(&(e[1], e[0])) {
                e.swap(0, 1);
            }
        }
    }
}

/// The nodes in the order the file lists them: coordinates, tags and the map from a
/// tag to its index. A tag defined twice and a node off the plane are errors.
#[allow(clippy::type_complexity)]
fn nodes(
    msh: &MshFile,
    solid: bool,
) -> std::result::Result<(Vec<[f64; 3]>, Vec<u64>, HashMap<u64, usize>), String> {
    let n: usize = msh.node_blocks.iter().map(|b| b.tags.len()).sum();
    let mut coords = Vec::with_capacity(n);
    let mut tags = Vec::with_capacity(n);
    let mut index = HashMap::with_capacity(n);
    let extent = msh
        .node_blocks
        .iter()
        .flat_map(|b| &b.xyz)
        .flat_map(|p| [p[0].abs(), p[1].abs()])
        .filter(|x| x.is_finite())
        .fold(0.0f64, f64::max);
    let z_tolerance = 1e-9 * extent.max(f64::MIN_POSITIVE);
    for block in &msh.node_blocks {
        for (&tag, p) in block.tags.iter().zip(&block.xyz) {
            if index.insert(tag, coords.len()).is_some() {
                return Err(format!("node tag {tag} is defined twice"));
            }
            if !solid && p[2].abs() > z_tolerance {
                return Err(format!(
                    "node with Gmsh tag {tag} at {p:?} lies off the plane z = 0 \
                     (a 2D model takes x and y only)"
                ));
            }
            coords.push([p[0], p[1], if solid { p[2] } else { 0.0 }]);
            tags.push(tag);
        }
    }
    Ok((coords, tags, index))
}

/// The set names of the physical groups; two groups of one name are an error.
fn group_names(msh: &MshFile) -> std::result::Result<HashMap<(i32, i32), String>, String> {
    let mut by_name: HashMap<&str, (i32, i32)> = HashMap::new();
    let mut out = HashMap::new();
    for (dim, tag, name) in &msh.physical_names {
        if let Some((d0, t0)) = by_name.insert(name, (*dim, *tag)) {
            return Err(format!(
                "two physical groups are named `{name}` (dimension {d0} tag {t0} and \
                 dimension {dim} tag {tag}): set names must be unique"
            ));
        }
        if out.insert((*dim, *tag), name.clone()).is_some() {
            return Err(format!(
                "physical group of dimension {dim} and tag {tag} is named twice"
            ));
        }
    }
    Ok(out)
}

/// A short name of a Gmsh element type, for messages.
fn type_name(t: i32) -> &'static str {
    match t {
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrilateral",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        16 => "8-node quadrilateral",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        t if is_volume_type(t) => "a higher-order volume element",
        _ => "a higher-order element",
    }
}

fn signed_area(coords: &[[f64; 3]], poly: &[usize]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (coords[poly[i]], coords[poly[(i + 1) % n]]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}
