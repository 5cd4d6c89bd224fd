//! Structured rectangle generator with named node and edge sets.

use std::collections::BTreeMap;

use super::{ElementKind, Elements, Part};

/// A rectangle `[x0, x0+lx] x [y0, y0+ly]` cut into `nx` by `ny` cells, each cell one
/// Quad4 or two Tri3 (split along the diagonal from lower left to upper right).
///
/// Node sets: `left, right, bottom, top` (edges including corners), `bottom_left,
/// bottom_right, top_left, top_right` (one node each). Edge sets: `left, right,
/// bottom, top`, each oriented counter-clockwise around the body.
pub fn rectangle(
    origin: [f64; 2],
    size: [f64; 2],
    nx: usize,
    ny: usize,
    kind: ElementKind,
) -> Part {
    assert!(
        nx > 0 && ny > 0,
        "rectangle needs at least one cell each way"
    );
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut coords = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            coords.push([
                origin[0] + size[0] * i as f64 / nx as f64,
                origin[1] + size[1] * j as f64 / ny as f64,
            ]);
        }
    }
    let mut conn = Vec::with_capacity(nx * ny * 6);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match kind {
                ElementKind::Quad4 => conn.extend_from_slice(&[a, b, c, d]),
                ElementKind::Tri3 => conn.extend_from_slice(&[a, b, c, a, c, d]),
                ElementKind::Bar2 => panic!("a rectangle is meshed with quad4 or tri3"),
            }
        }
    }
    let mut node_sets = BTreeMap::new();
    node_sets.insert("left".into(), (0..=ny).map(|j| id(0, j)).collect());
    node_sets.insert("right".into(), (0..=ny).map(|j| id(nx, j)).collect());
    node_sets.insert("bottom".into(), (0..=nx).map(|i| id(i, 0)).collect());
    node_sets.insert("top".into(), (0..=nx).map(|i| id(i, ny)).collect());
    node_sets.insert("bottom_left".into(), vec![id(0, 0)]);
    node_sets.insert("bottom_right".into(), vec![id(nx, 0)]);
    node_sets.insert("top_left".into(), vec![id(0, ny)]);
    node_sets.insert("top_right".into(), vec![id(nx, ny)]);
    let mut edge_sets = BTreeMap::new();
    edge_sets.insert(
        "bottom".into(),
        (0..nx).map(|i| [id(i, 0), id(i + 1, 0)]).collect(),
    );
    edge_sets.insert(
        "right".into(),
        (0..ny).map(|j| [id(nx, j), id(nx, j + 1)]).collect(),
    );
    edge_sets.insert(
        "top".into(),
        (0..nx).rev().map(|i| [id(i + 1, ny), id(i, ny)]).collect(),
    );
    edge_sets.insert(
        "left".into(),
        (0..ny).rev().map(|j| [id(0, j + 1), id(0, j)]).collect(),
    );
    Part {
        coords,
        blocks: vec![Elements::new(kind, conn)],
        node_sets,
        edge_sets,
        node_tags: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_sets() {
        let p = rectangle([0.0, 0.0], [2.0, 1.0], 4, 2, ElementKind::Quad4);
        assert_eq!(p.coords.len(), 15);
        assert_eq!(p.blocks[0].len(), 8);
        assert_eq!(p.node_sets["left"].len(), 3);
        assert_eq!(p.edge_sets["top"].len(), 4);
        assert_eq!(p.coords[p.node_sets["top_right"][0]], [2.0, 1.0]);
        let t = rectangle([0.0, 0.0], [2.0, 1.0], 4, 2, ElementKind::Tri3);
        assert_eq!(t.blocks[0].len(), 16);
    }
}
