//! Fill-reducing orderings beyond the backends' own: geometric nested dissection with
//! minimum-degree leaves.
//!
//! FE matrices come with coordinates. Splitting the vertices at the median of the
//! longer side of their bounding box, taking as separator the vertices below the cut
//! that touch the other side, and numbering `[below, above, separator]` recursively
//! gives the nested-dissection ordering of a 2D mesh (separators of one mesh line)
//! without a graph partitioner. Parts below `LEAF` vertices are ordered by faer's
//! approximate minimum degree, and the whole order is then postordered along its
//! elimination tree so that the supernodes of the factor stay whole.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SymbolicSparseColMatRef;

/// Symmetric adjacency (without the diagonal) of a lower-triangular CSC pattern.
fn adjacency(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut deg = vec![0usize; n + 1];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j {
                deg[i + 1] += 1;
                deg[j + 1] += 1;
            }
        }
    }
    for k in 0..n {
        deg[k + 1] += deg[k];
    }
    let mut fill = deg.clone();
    let mut adj = vec![0usize; deg[n]];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j {
                adj[fill[i]] = j;
                fill[i] += 1;
                adj[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    (deg, adj)
}

/// Parts up to this many vertices are ordered by minimum degree.
const LEAF: usize = 512;

struct Graph<'a> {
    coords: &'a [[f64; 3]],
    ptr: Vec<usize>,
    adj: Vec<usize>,
}

/// Nested-dissection elimination order of the matrix with lower pattern
/// `(col_ptr, row_idx)` whose column `j` sits at `coords[j]`: `order[k]` is the
/// column eliminated `k`-th.
pub fn nested_dissection(coords: &[[f64; 3]], col_ptr: &[usize], row_idx: &[usize]) -> Vec<usize> {
    let n = coords.len();
    let (ptr, adj) = adjacency(n, col_ptr, row_idx);
    let g = Graph { coords, ptr, adj };
    let mut part = vec![0u32; n];
    let mut local = vec![usize::MAX; n];
    let mut order = Vec::with_capacity(n);
    let mut next_label = 1u32;
    dissect(
        &g,
        (0..n).collect(),
        &mut part,
        &mut local,
        &mut next_label,
        &mut order,
    );
    postorder(n, &g.ptr, &g.adj, &order)
}

fn dissect(
    g: &Graph,
    set: Vec<usize>,
    part: &mut [u32],
    local: &mut [usize],
    next_label: &mut u32,
    order: &mut Vec<usize>,
) {
    if set.len() <= LEAF {
        minimum_degree(g, &set, local, order);
        return;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &v in &set {
        for d in 0..3 {
            lo[d] = lo[d].min(g.coords[v][d]);
            hi[d] = hi[d].max(g.coords[v][d]);
        }
    }
    // The longest extent (the first of equals): plane meshes have no z extent.
    let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let axis = if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    };
    // Cut at the median coordinate: vertices strictly below it go one way, so a mesh
    // line never straddles the cut and the separator is one line of the mesh.
    let mut sorted = set.clone();
    let mid = sorted.len() / 2;
    sorted.select_nth_unstable_by(mid, |&a, &b| {
        g.coords[a][axis].total_cmp(&g.coords[b][axis])
    });
    let cut = g.coords[sorted[mid]][axis];
    let (mut below, mut above): (Vec<usize>, Vec<usize>) =
        set.iter().partition(|&&v| g.coords[v][axis] < cut);
    if below.is_empty() || above.is_empty() {
        below = sorted[..mid].to_vec();
        above = sorted[mid..].to_vec();
    }
    let (la, lb) = (*next_label, *next_label + 1);
    *next_label += 2;
    for &v in &below {
        part[v] = la;
    }
    for &v in &above {
        part[v] = lb;
    }
    let (mut left, mut sep) = (Vec::with_capacity(below.len()), Vec::new());
    for &v in &below {
        if g.adj[g.ptr[v]..g.ptr[v + 1]].iter().any(|&w| part[w] == lb) {
            sep.push(v);
        } else {
            left.push(v);
        }
    }
    if left.is_empty() {
        minimum_degree(g, &set, local, order);
        return;
    }
    dissect(g, left, part, local, next_label, order);
    dissect(g, above, part, local, next_label, order);
    minimum_degree(g, &sep, local, order);
}

/// Appends the vertices of `set` in faer's AMD order of the subgraph they induce.
fn minimum_degree(g: &Graph, set: &[usize], local: &mut [usize], order: &mut Vec<usize>) {
    let m = set.len();
    if m <= 2 {
        order.extend_from_slice(set);
        return;
    }
    for (k, &v) in set.iter().enumerate() {
        local[v] = k;
    }
    let mut col_ptr = Vec::with_capacity(m + 1);
    col_ptr.push(0usize);
    let mut rows = Vec::new();
    for &v in set {
        let start = rows.len();
        rows.extend(
            g.adj[g.ptr[v]..g.ptr[v + 1]]
                .iter()
                .filter_map(|&w| (local[w] != usize::MAX).then_some(local[w])),
        );
        rows[start..].sort_unstable();
        col_ptr.push(rows.len());
    }
    for &v in set {
        local[v] = usize::MAX;
    }
    let (mut perm, mut perm_inv) = (vec![0usize; m], vec![0usize; m]);
    let pattern = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &rows);
    let done = MemBuffer::try_new(amd::order_scratch::<usize>(m, rows.len()))
        .ok()
        .and_then(|mut mem| {
            amd::order(
                &mut perm,
                &mut perm_inv,
                pattern,
                amd::Control::default(),
                MemStack::new(&mut mem),
            )
            .ok()
        });
    match done {
        Some(_) => order.extend(perm.iter().map(|&k| set[k])),
        None => order.extend_from_slice(set),
    }
}

/// Postorders `order` along the elimination tree of the permuted matrix.
fn postorder(n: usize, ptr: &[usize], adj: &[usize], order: &[usize]) -> Vec<usize> {
    let mut inv = vec![0usize; n];
    for (k, &v) in order.iter().enumerate() {
        inv[v] = k;
    }
    const NONE: usize = usize::MAX;
    let mut parent = vec![NONE; n];
    let mut ancestor = vec![NONE; n];
    for k in 0..n {
        let v = order[k];
        for &w in &adj[ptr[v]..ptr[v + 1]] {
            let mut i = inv[w];
            if i >= k {
                continue;
            }
            while ancestor[i] != NONE && ancestor[i] != k {
                let next = ancestor[i];
                ancestor[i] = k;
                i = next;
            }
            if ancestor[i] == NONE {
                ancestor[i] = k;
                parent[i] = k;
            }
        }
    }
    let mut head = vec![NONE; n];
    let mut next = vec![NONE; n];
    for k in (0..n).rev() {
        if parent[k] != NONE {
            next[k] = head[parent[k]];
            head[parent[k]] = k;
        }
    }
    let mut post = Vec::with_capacity(n);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for root in 0..n {
        if parent[root] != NONE {
            continue;
        }
        stack.push((root, head[root]));
        while let Some(top) = stack.last_mut() {
            let (node, child) = *top;
            if child == NONE {
                post.push(order[node]);
                stack.pop();
            } else {
                top.1 = next[child];
                stack.push((child, head[child]));
            }
        }
    }
    post
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_a_permutation_with_a_grid_line_as_top_separator() {
        // 5-point Laplacian on a 120x30 grid.
        let (nx, ny) = (120, 30);
        let n = nx * ny;
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        let coords: Vec<[f64; 3]> = (0..n)
            .map(|c| [(c % nx) as f64, (c / nx) as f64, 0.0])
            .collect();
        for c in 0..n {
            let (i, j) = (c % nx, c / nx);
            row_idx.push(c);
            if i + 1 < nx {
                row_idx.push(c + 1);
            }
            if j + 1 < ny {
                row_idx.push(c + nx);
            }
            col_ptr.push(row_idx.len());
        }
        let order = nested_dissection(&coords, &col_ptr, &row_idx);
        let mut seen = vec![false; n];
        for &v in &order {
            assert!(!seen[v], "vertex {v} twice");
            seen[v] = true;
        }
        assert_eq!(order.len(), n);
        // The vertices eliminated last form the first separator: one grid column.
        let x0 = coords[order[n - 1]][0];
        assert!(
            order[n - ny..].iter().all(|&v| coords[v][0] == x0),
            "top separator is a grid line"
        );
    }
}
