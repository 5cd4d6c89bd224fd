//! Structured rectangle generator with named node and edge sets.

use std::collections::BTreeMap;

use super::{ElementKind, Elements, Part};

/// A rectangle `[x0, x0+lx] x [y0, y0+ly]` cut into `nx` by `ny` equal cells, each
/// cell one Quad4 or two Tri3 (split along the diagonal from lower left to upper
/// right).
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
    let xs: Vec<f64> = (0..=nx).map(|i| size[0] * i as f64 / nx as f64).collect();
    let ys: Vec<f64> = (0..=ny).map(|j| size[1] * j as f64 / ny as f64).collect();
    grid(origin, &xs, &ys, kind)
}

/// The cell boundaries `0 = c_0 < ... < c_n = length` of one side of a rectangle:
/// the side is cut at `lines` (distances from the start, strictly inside), and each
/// band between two cuts into [`cells_in_band`] equal cells, none larger than `size`.
pub fn graded_lines(length: f64, size: f64, lines: &[f64]) -> Vec<f64> {
    let mut cuts = vec![0.0];
    cuts.extend_from_slice(lines);
    cuts.push(length);
    let mut out = vec![0.0];
    for w in cuts.windows(2) {
        let band = w[1] - w[0];
        let n = cells_in_band(band, size) as usize;
        out.extend((1..=n).map(|k| w[0] + band * k as f64 / n as f64));
    }
    *out.last_mut().expect("at least one band") = length;
    out
}

/// The number of equal cells no larger than `size` (to a millionth) that fill a band
/// of width `band`: `⌈band/size − 10⁻⁶⌉`, at least one. A float, so that a tiny size
/// cannot overflow before it is refused.
pub fn cells_in_band(band: f64, size: f64) -> f64 {
    (band / size - 1e-6).ceil().max(1.0)
}

/// A tensor-product grid on `origin + [xs] x [ys]` (cell boundaries increasing from
/// 0), with the node and edge sets of [`rectangle`].
pub fn grid(origin: [f64; 2], xs: &[f64], ys: &[f64], kind: ElementKind) -> Part {
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    assert!(nx > 0 && ny > 0, "a grid needs at least one cell each way");
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut coords = Vec::with_capacity((nx + 1) * (ny + 1));
    for y in ys {
        for x in xs {
            coords.push([origin[0] + x, origin[1] + y, 0.0]);
        }
    }
    let mut conn = Vec::with_capacity(nx * ny * 6);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match kind {
                ElementKind::Quad4 => conn.extend_from_slice(&[a, b, c, d]),
                ElementKind::Tri3 => conn.extend_from_slice(&[a, b, c, a, c, d]),
                _ => panic!("a rectangle is meshed with quad4 or tri3"),
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
        dim: 2,
        coords,
        blocks: vec![Elements::new(kind, conn)],
        node_sets,
        edge_sets,
        face_sets: BTreeMap::new(),
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
        assert_eq!(p.coords[p.node_sets["top_right"][0]], [2.0, 1.0, 0.0]);
        let t = rectangle([0.0, 0.0], [2.0, 1.0], 4, 2, ElementKind::Tri3);
        assert_eq!(t.blocks[0].len(), 16);
    }

    #[test]
    fn graded_lines_pass_through_the_cuts() {
        // Benchmark 2's beam: rebar lines 0.03 m from each face, cells near 0.025 m.
        let ys = graded_lines(0.25, 0.025, &[0.03, 0.22]);
        // 2 cells of 0.015 m, 8 of 0.02375 m, 2 of 0.015 m.
        assert_eq!(ys.len(), 13);
        assert!(ys.iter().any(|y| (y - 0.03).abs() < 1e-15));
        assert!(ys.iter().any(|y| (y - 0.22).abs() < 1e-15));
        assert!(ys.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(*ys.last().unwrap(), 0.25);
        // Without cuts and a size that divides the length: the uniform grid.
        let xs = graded_lines(1.2, 0.2, &[]);
        assert_eq!(xs.len(), 7);
        assert!((xs[3] - 0.6).abs() < 1e-15);
        // Concrete of benchmark 1 at 0.2 m with lines under the steel's corners:
        // 0.3 m bands in two cells of 0.15 m, the middle 0.6 m in three.
        let xs = graded_lines(1.2, 0.2, &[0.3, 0.9]);
        assert_eq!(xs.len(), 8);
        assert!((xs[1] - 0.15).abs() < 1e-15 && (xs[3] - 0.5).abs() < 1e-15);
        // A size that divides the length to round-off gives exactly that many cells.
        assert_eq!(graded_lines(1.2, 0.15, &[]).len(), 9);
        assert!(xs.iter().any(|x| (x - 0.3).abs() < 1e-15));
    }
}
