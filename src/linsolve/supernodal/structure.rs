//! The supernodes of a factor and the two-thread cut of its elimination forest.

use super::Row;

#[derive(Clone, Copy, Debug)]
pub(super) struct Supernode {
    /// First column.
    pub(super) begin: usize,
    /// Number of columns.
    pub(super) ncols: usize,
    /// Offset of its pattern in `rows`.
    pub(super) pattern: usize,
    /// Length of its pattern.
    pub(super) npattern: usize,
    /// Offset of its values.
    pub(super) values: usize,
}

/// The row indices as [`Row`]s, `None` if one does not fit.
pub(super) fn narrow(rows: &[usize]) -> Option<Vec<Row>> {
    rows.iter().map(|&r| Row::try_from(r).ok()).collect()
}

/// Systems of at least this order are worth a second thread.
pub(super) const PARALLEL_ORDER: usize = 20_000;

/// The cut of the elimination forest stops refining once its time (the heavier
/// part plus the top, in values) is within this share of half the factor above it.
pub(super) const MAX_IMBALANCE: f64 = 0.04;

/// The top of a cut holds at most this share of the factor.
pub(super) const MAX_TOP: f64 = 0.3;

/// A cut is used only if its time is at most this share of the sequential one.
pub(super) const MIN_GAIN: f64 = 0.8;

/// The elimination forest cut for two threads: two sets of whole subtrees, each
/// over a contiguous range of columns (the supernodes are in postorder), and the
/// supernodes above them (the top). A sweep runs the two parts at once, each on its
/// own part of `x`, and the top alone: forward after the parts (their updates of
/// top rows collected in a buffer per thread and added in), backward before them
/// (the parts read the top rows from a copy).
#[derive(Debug)]
pub(super) struct TreeSplit {
    /// The first column of the second part.
    pub(super) mid: usize,
    /// Each part's `(supernode, split)` in order: the pattern rows from position
    /// `split` on lie above the supernode's subtree, in the top.
    pub(super) parts: [Vec<(u32, u32)>; 2],
    /// The top's supernodes in order.
    pub(super) top: Vec<u32>,
    /// The top's columns.
    pub(super) top_cols: Vec<u32>,
}

impl TreeSplit {
    /// The split of the forest `parent` of `nodes`, if it is in postorder and has
    /// two balanced parts below a small top.
    pub(super) fn new(nodes: &[Supernode], parent: &[usize], rows: &[Row]) -> Option<Self> {
        let ns = nodes.len();
        let mut children = vec![Vec::new(); ns];
        let mut roots = Vec::new();
        for (s, &p) in parent.iter().enumerate() {
            if p == usize::MAX {
                roots.push(s);
            } else if p <= s {
                return None;
            } else {
                children[p].push(s);
            }
        }
        // Subtree weights (values stored) and first supernodes; postorder check.
        let mut weight = vec![0.0f64; ns];
        let mut first = (0..ns).collect::<Vec<_>>();
        let mut size = vec![1usize; ns];
        for s in 0..ns {
            let sn = &nodes[s];
            weight[s] += (sn.ncols * (sn.ncols + sn.npattern)) as f64;
            if s + 1 < first[s] + size[s] {
                return None;
            }
            if s + 1 - first[s] != size[s] {
                return None;
            }
            let p = parent[s];
            if p != usize::MAX {
                weight[p] += weight[s];
                first[p] = first[p].min(first[s]);
                size[p] += size[s];
            }
        }
        let total: f64 = roots.iter().map(|&r| weight[r]).sum();
        let own = |t: usize| (nodes[t].ncols * (nodes[t].ncols + nodes[t].npattern)) as f64;
        // Cut the heaviest subtree of the frontier while the top stays light; keep
        // the cut whose time, the heavier part plus the top, is least.
        let mut frontier = roots;
        let mut top = Vec::new();
        let mut top_weight = 0.0;
        let mut best: Option<(f64, usize, Vec<usize>, Vec<usize>)> = None;
        loop {
            let mut prefix = 0.0;
            let (mut cost, mut at) = (f64::INFINITY, 0);
            for (i, &r) in frontier.iter().enumerate().take(frontier.len() - 1) {
                prefix += weight[r];
                let c = prefix.max(total - top_weight - prefix) + top_weight;
                if c < cost {
                    (cost, at) = (c, i + 1);
                }
            }
            if at > 0 && best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, at, frontier.clone(), top.clone()));
            }
            if cost <= (0.5 + MAX_IMBALANCE) * total {
                break;
            }
            let Some(heaviest) = frontier
                .iter()
                .enumerate()
                .filter(|(_, &r)| !children[r].is_empty())
                .max_by(|a, b| weight[*a.1].total_cmp(&weight[*b.1]))
                .map(|(i, _)| i)
            else {
                break;
            };
            let r = frontier.remove(heaviest);
            top.push(r);
            top_weight += own(r);
            if top_weight > MAX_TOP * total {
                break;
            }
            frontier.splice(heaviest..heaviest, children[r].iter().copied());
        }
        let (cost, cut, frontier, mut top) = best?;
        if cost > MIN_GAIN * total {
            return None;
        }
        let mid = nodes[first[frontier[cut]]].begin;
        let part = |roots: &[usize]| {
            let mut out = Vec::new();
            for &r in roots {
                let hi = nodes[r].begin + nodes[r].ncols;
                for s in first[r]..=r {
                    let sn = &nodes[s];
                    let pattern = &rows[sn.pattern..sn.pattern + sn.npattern];
                    out.push((
                        s as u32,
                        pattern.partition_point(|&row| (row as usize) < hi) as u32,
                    ));
                }
            }
            out
        };
        top.sort_unstable();
        let top_cols = top
            .iter()
            .flat_map(|&t| (nodes[t].begin..nodes[t].begin + nodes[t].ncols).map(|c| c as u32))
            .collect();
        Some(TreeSplit {
            mid,
            parts: [part(&frontier[..cut]), part(&frontier[cut..])],
            top: top.into_iter().map(|t| t as u32).collect(),
            top_cols,
        })
    }
}
