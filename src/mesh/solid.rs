//! Structured box generator: hexahedra or tetrahedra on a tensor-product grid, with
//! named face, edge and corner node sets and oriented boundary face sets.

use std::collections::BTreeMap;

use super::{ElementKind, Elements, Part};

/// The faces of a box: set name, axis, and whether it is the high side.
const FACES: [(&str, usize, bool); 6] = [
    ("left", 0, false),
    ("right", 0, true),
    ("bottom", 1, false),
    ("top", 1, true),
    ("back", 2, false),
    ("front", 2, true),
];

/// A box `origin + [0, lx] x [0, ly] x [0, lz]` cut at the cell boundaries `xs`,
/// `ys`, `zs` (increasing from 0, as [`super::structured::graded_lines`] gives
/// them), each cell one Hex8 or six Tet4 (the cube's Kuhn split along its diagonal
/// from the low corner to the high one, which conforms from cell to cell).
///
/// Node sets: the faces `left, right` (x), `bottom, top` (y), `back, front` (z); the
/// twelve edges named by their two faces in the order y, x, z (`bottom_left`,
/// `top_front`, `left_back`, ...); the eight corners by their three
/// (`bottom_left_back`, ...). Face sets: the six faces as quadrilaterals (Hex8) or
/// triangles (Tet4), counter-clockwise seen from outside.
pub fn block(origin: [f64; 3], xs: &[f64], ys: &[f64], zs: &[f64], kind: ElementKind) -> Part {
    let (nx, ny, nz) = (xs.len() - 1, ys.len() - 1, zs.len() - 1);
    assert!(
        nx > 0 && ny > 0 && nz > 0,
        "a box needs at least one cell each way"
    );
    let id = |i: usize, j: usize, k: usize| (k * (ny + 1) + j) * (nx + 1) + i;
    let mut coords = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for z in zs {
        for y in ys {
            for x in xs {
                coords.push([origin[0] + x, origin[1] + y, origin[2] + z]);
            }
        }
    }
    let mut conn = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                match kind {
                    ElementKind::Hex8 => conn.extend_from_slice(&v),
                    ElementKind::Tet4 => {
                        for t in KUHN {
                            conn.extend(t.iter().map(|&a| v[a]));
                        }
                    }
                    _ => panic!("a box is meshed with hex8 or tet4"),
                }
            }
        }
    }
    let n = [nx, ny, nz];
    let at = |axis: usize, high: bool| if high { n[axis] } else { 0 };
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let nodes_where = |fixed: &[(usize, usize)]| -> Vec<usize> {
        let mut out = Vec::new();
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let ijk = [i, j, k];
                    if fixed.iter().all(|&(a, v)| ijk[a] == v) {
                        out.push(id(i, j, k));
                    }
                }
            }
        }
        out
    };
    // Names in the order y, x, z, as the rectangle's `bottom_left`.
    let order = |a: usize| [1, 0, 2].iter().position(|&x| x == a).unwrap_or(0);
    for (fi, &(name, axis, high)) in FACES.iter().enumerate() {
        node_sets.insert(name.into(), nodes_where(&[(axis, at(axis, high))]));
        for &(name2, axis2, high2) in &FACES[fi + 1..] {
            if axis2 == axis {
                continue;
            }
            let mut pair = [(name, axis), (name2, axis2)];
            pair.sort_by_key(|p| order(p.1));
            node_sets.insert(
                format!("{}_{}", pair[0].0, pair[1].0),
                nodes_where(&[(axis, at(axis, high)), (axis2, at(axis2, high2))]),
            );
        }
    }
    for y in [("bottom", false), ("top", true)] {
        for x in [("left", false), ("right", true)] {
            for z in [("back", false), ("front", true)] {
                node_sets.insert(
                    format!("{}_{}_{}", y.0, x.0, z.0),
                    vec![id(at(0, x.1), at(1, y.1), at(2, z.1))],
                );
            }
        }
    }
    let mut face_sets: BTreeMap<String, Vec<crate::mesh::Face>> = BTreeMap::new();
    let elements = Elements::new(kind, conn);
    for &(name, axis, high) in &FACES {
        let value = at(axis, high);
        let mut faces = Vec::new();
        for e in 0..elements.len() {
            let el = elements.element(e);
            for f in kind.faces() {
                let on = f.iter().all(|&a| {
                    let nd = el[a];
                    let ijk = [
                        nd % (nx + 1),
                        (nd / (nx + 1)) % (ny + 1),
                        nd / ((nx + 1) * (ny + 1)),
                    ];
                    ijk[axis] == value
                });
                if on {
                    let mut q = [0; 4];
                    for (s, &a) in f.iter().enumerate() {
                        q[s] = el[a];
                    }
                    faces.extend(crate::mesh::Face::from_corners(&q[..f.len()]));
                }
            }
        }
        face_sets.insert(name.into(), faces);
    }
    Part {
        dim: 3,
        coords,
        blocks: vec![elements],
        node_sets,
        edge_sets: BTreeMap::new(),
        face_sets,
        node_tags: None,
    }
}

/// The Kuhn split of the cube (local hexahedron nodes) into six tetrahedra around
/// the diagonal 0-6, each positively oriented.
pub(crate) const KUHN: [[usize; 4]; 6] = [
    [0, 1, 2, 6],
    [0, 2, 3, 6],
    [0, 3, 7, 6],
    [0, 7, 4, 6],
    [0, 4, 5, 6],
    [0, 5, 1, 6],
];

/// A box of `divisions` equal cells each way: [`block`] on uniform lines.
pub fn uniform(origin: [f64; 3], size: [f64; 3], divisions: [usize; 3], kind: ElementKind) -> Part {
    let lines =
        |l: f64, n: usize| -> Vec<f64> { (0..=n).map(|i| l * i as f64 / n as f64).collect() };
    block(
        origin,
        &lines(size[0], divisions[0]),
        &lines(size[1], divisions[1]),
        &lines(size[2], divisions[2]),
        kind,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::element::measure;

    #[test]
    fn boxes_of_both_kinds_fill_their_volume_with_valid_elements_and_named_sets() {
        for (kind, per_cell) in [(ElementKind::Hex8, 1), (ElementKind::Tet4, 6)] {
            let p = uniform([1.0, -1.0, 0.5], [2.0, 1.0, 0.5], [4, 2, 3], kind);
            p.check().unwrap();
            assert_eq!(p.coords.len(), 5 * 3 * 4);
            assert_eq!(p.blocks[0].len(), 24 * per_cell);
            let volume: f64 = (0..p.blocks[0].len())
                .map(|e| {
                    let x: Vec<[f64; 3]> = p.blocks[0]
                        .element(e)
                        .iter()
                        .map(|&n| p.coords[n])
                        .collect();
                    measure(kind, &x)
                })
                .sum();
            assert!((volume - 1.0).abs() < 1e-12, "{kind:?}: volume {volume}");
            assert_eq!(p.node_sets["left"].len(), 3 * 4);
            assert_eq!(p.node_sets["front"].len(), 5 * 3);
            assert_eq!(p.node_sets["bottom_left"].len(), 4);
            assert_eq!(p.node_sets["left_back"].len(), 3);
            assert_eq!(p.node_sets["top_front"].len(), 5);
            assert_eq!(p.coords[p.node_sets["top_right_front"][0]], [3.0, 0.0, 1.0]);
            // Each face set covers its face once, each face pointing outwards.
            for &(name, axis, high) in &FACES {
                let faces = &p.face_sets[name];
                let mut area = 0.0;
                for f in faces {
                    let x = |s: usize| p.coords[f[s]];
                    let nrm = crate::geometry::cross(
                        crate::geometry::sub(x(1), x(0)),
                        crate::geometry::sub(x(2), x(0)),
                    );
                    let sign = if high { 1.0 } else { -1.0 };
                    assert!(sign * nrm[axis] > 0.0, "{kind:?} {name}: inward face");
                    area += if f.is_triangle() {
                        crate::mesh::triangle_area(x(0), x(1), x(2))
                    } else {
                        crate::mesh::triangle_area(x(0), x(1), x(2))
                            + crate::mesh::triangle_area(x(0), x(2), x(3))
                    };
                }
                let sides = [2.0, 1.0, 0.5];
                let want = sides[(axis + 1) % 3] * sides[(axis + 2) % 3];
                assert!((area - want).abs() < 1e-12, "{kind:?} {name}: area {area}");
            }
        }
    }
}
