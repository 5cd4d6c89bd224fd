//! Gmsh `.msh` v4.1 reader (ASCII or binary) through the `mshio` crate.
//!
//! 2D elements (3-node triangles, 4-node quadrilaterals) become the part's elements;
//! physical groups become sets: a physical surface gives a node set, a physical curve
//! gives a node set and an edge set (its 2-node line elements), a physical point gives
//! a node set. Sets are named by their `$PhysicalNames` entry, or `physical_<dim>_<tag>`
//! when the file names none; a named group without elements is an empty set.
//! Elements given clockwise are turned counter-clockwise. The file's node and element
//! tags are kept for messages, and the part is checked (finite coordinates, every
//! node in an element, no degenerate or distorted element) before it is used.
//! `mshio` does not read `$PhysicalNames`, so that small text section is read here.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use super::{ElementKind, Elements, Part};
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
    let msh =
        mshio::parse_msh_bytes(bytes).map_err(|e| format!("not a valid MSH 4.1 file: {e}"))?;
    let names = physical_names(bytes);
    let nodes = msh
        .data
        .nodes
        .as_ref()
        .ok_or("the file has no $Nodes section")?;
    let elements = msh
        .data
        .elements
        .as_ref()
        .ok_or("the file has no $Elements section")?;

    // Node tags to dense indices.
    let mut tag_to_index: HashMap<u64, usize> = HashMap::new();
    let mut coords = Vec::new();
    let mut node_tags = Vec::new();
    let mut running_tag = nodes.min_node_tag;
    for block in &nodes.node_blocks {
        match &block.node_tags {
            Some(tags) => {
                let mut pairs: Vec<(u64, usize)> = tags.iter().map(|(&t, &i)| (t, i)).collect();
                pairs.sort_by_key(|p| p.1);
                for (tag, i) in pairs {
                    let n = block
                        .nodes
                        .get(i)
                        .ok_or_else(|| format!("node tag {tag} points past its node block"))?;
                    tag_to_index.insert(tag, coords.len());
                    coords.push([n.x, n.y]);
                    node_tags.push(tag);
                }
            }
            None => {
                for n in &block.nodes {
                    tag_to_index.insert(running_tag, coords.len());
                    coords.push([n.x, n.y]);
                    node_tags.push(running_tag);
                    running_tag += 1;
                }
            }
        }
    }
    let index = |tag: u64| -> std::result::Result<usize, String> {
        tag_to_index
            .get(&tag)
            .copied()
            .ok_or_else(|| format!("an element refers to node tag {tag}, which is not defined"))
    };

    // Physical tags of each entity.
    let mut phys: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &msh.data.entities {
        for p in &ent.points {
            phys.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &ent.curves {
            phys.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &ent.surfaces {
            phys.insert((2, s.tag), s.physical_tags.clone());
        }
    }
    let set_name = |dim: i32, tag: i32| -> String {
        names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_else(|| format!("physical_{dim}_{tag}"))
    };

    let (mut quads, mut quad_tags) = (Vec::new(), Vec::new());
    let (mut tris, mut tri_tags) = (Vec::new(), Vec::new());
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut edge_sets: BTreeMap<String, Vec<[usize; 2]>> = BTreeMap::new();
    for block in &elements.element_blocks {
        let dim = block.entity_dim;
        let groups = phys
            .get(&(dim, block.entity_tag))
            .cloned()
            .unwrap_or_default();
        for el in &block.elements {
            let ns: Vec<usize> = el
                .nodes
                .iter()
                .map(|&t| index(t))
                .collect::<std::result::Result<_, _>>()?;
            let wanted = match block.element_type {
                mshio::ElementType::Qua4 => 4,
                mshio::ElementType::Tri3 => 3,
                mshio::ElementType::Lin2 => 2,
                _ => 0,
            };
            if ns.len() < wanted {
                return Err(format!(
                    "element with Gmsh tag {} has {} nodes, its type needs {wanted}",
                    el.element_tag,
                    ns.len()
                ));
            }
            match block.element_type {
                mshio::ElementType::Qua4 => {
                    let mut q = [ns[0], ns[1], ns[2], ns[3]];
                    if signed_area(&coords, &q) < 0.0 {
                        q.swap(1, 3);
                    }
                    quads.extend_from_slice(&q);
                    quad_tags.push(el.element_tag);
                }
                mshio::ElementType::Tri3 => {
                    let mut t = [ns[0], ns[1], ns[2]];
                    if signed_area(&coords, &t) < 0.0 {
                        t.swap(1, 2);
                    }
                    tris.extend_from_slice(&t);
                    tri_tags.push(el.element_tag);
                }
                mshio::ElementType::Lin2 => {
                    for &g in &groups {
                        edge_sets
                            .entry(set_name(1, g))
                            .or_default()
                            .push([ns[0], ns[1]]);
                    }
                }
                mshio::ElementType::Pnt => {}
                other => {
                    return Err(format!(
                        "element type {other:?} is not supported (use 3-node triangles, \
                         4-node quadrilaterals and 2-node lines)"
                    ))
                }
            }
            for &g in &groups {
                node_sets
                    .entry(set_name(dim, g))
                    .or_default()
                    .extend_from_slice(&ns);
            }
        }
    }
    for nodes in node_sets.values_mut() {
        nodes.sort_unstable();
        nodes.dedup();
    }
    // A named group without elements is an empty set, not an unknown one.
    for (&(dim, _), name) in &names {
        node_sets.entry(name.clone()).or_default();
        if dim == 1 {
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
    Ok(Part {
        coords,
        blocks,
        node_sets,
        edge_sets,
        node_tags: Some(node_tags),
    })
}

fn signed_area(coords: &[[f64; 2]], poly: &[usize]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (coords[poly[i]], coords[poly[(i + 1) % n]]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5
}

/// Reads the `$PhysicalNames` section (always ASCII, even in binary files).
fn physical_names(bytes: &[u8]) -> HashMap<(i32, i32), String> {
    let mut out = HashMap::new();
    let text = String::from_utf8_lossy(bytes);
    let Some(start) = text.find("$PhysicalNames") else {
        return out;
    };
    let Some(end) = text[start..].find("$EndPhysicalNames") else {
        return out;
    };
    for line in text[start..start + end].lines().skip(2) {
        let mut parts = line.splitn(3, char::is_whitespace);
        let (Some(dim), Some(tag), Some(name)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        if let (Ok(dim), Ok(tag)) = (dim.parse(), tag.parse()) {
            out.insert((dim, tag), name.trim().trim_matches('"').to_string());
        }
    }
    out
}
