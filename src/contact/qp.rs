//! The contact QPs, solved with Clarabel.
//!
//! - [`DualQp`], the condensed form: `min ½ λᵀWλ + λᵀc`, `λ ≥ 0`, with the dense
//!   `W = G A⁻¹ Gᵀ` (`m x m`) and `c = g + G δ₀`. Its data is scaled to order one
//!   (`W/w̄`, `c/ℓ`, `λ = (ℓ/w̄) μ`) before Clarabel sees it, since `W` is of the order
//!   of a compliance (1e-10 m/N) and the gaps of micrometres; the solver is kept and
//!   its data updated (`update_P`, `update_q`) while the number of rows stays.
//! - [`primal_qp`], the reference: `min ½ δᵀAδ + rᵀδ` subject to `g + Gδ ≥ 0` over
//!   all free dofs, `A` sparse; its constraint duals are the contact forces.
//!
//! A Clarabel status other than solved (or almost solved) is returned as an error
//! string naming it, for the step to be cut.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use crate::linsolve::LowerCsc;

/// Clarabel's settings: quiet, no presolve (so the data can be updated in place),
/// and tolerances of 1e-9 on the data scaled to order one: the gaps they leave are
/// 1e-9 of the largest predicted gap, far below the contact tolerance. (Tighter
/// tolerances end in `InsufficientProgress` on well-posed problems.)
pub(super) fn settings() -> DefaultSettings<f64> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .input_sparse_dropzeros(false)
        .max_iter(200)
        .tol_gap_abs(1e-9)
        .tol_gap_rel(1e-9)
        .tol_feas(1e-9)
        .build()
        .expect("valid Clarabel settings")
}

pub(super) fn accept(status: SolverStatus) -> Result<(), String> {
    match status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(()),
        other => Err(format!("Clarabel status {other:?}")),
    }
}

/// The upper triangle of a dense symmetric `m x m` matrix (column-major) in CSC.
pub(super) fn dense_upper(w: &[f64], m: usize, scale: f64) -> CscMatrix<f64> {
    let mut colptr = Vec::with_capacity(m + 1);
    let mut rowval = Vec::with_capacity(m * (m + 1) / 2);
    let mut nzval = Vec::with_capacity(m * (m + 1) / 2);
    colptr.push(0);
    for j in 0..m {
        for i in 0..=j {
            rowval.push(i);
            nzval.push(0.5 * (w[i + j * m] + w[j + i * m]) * scale);
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(m, m, colptr, rowval, nzval)
}

/// What a QP solve gave.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct QpStats {
    /// Clarabel iterations.
    pub iterations: u32,
    /// Clarabel's own solve time (s).
    pub solve_s: f64,
    /// Cone programs solved (the friction shift's fixed point; 1 otherwise).
    pub programs: u32,
}

/// Rounds of changes to the active set [`solve_by_active_set`] tries before it gives
/// up.
const MAX_SWAPS: usize = 8;

/// Solves the dual QP by a primal active-set method started from the guess `active`
/// (sorted row indices, the previous QP's active set): on the current set,
/// `W_AA λ_A = −c_A` by a dense Cholesky factorisation and `λ = 0` elsewhere; the
/// rows of negative multipliers leave the set, else the penetrating rows join it, for
/// up to [`MAX_SWAPS`] rounds. Returns whether the result satisfies the QP's KKT conditions
/// (`λ ≥ 0`, and every row's gap `c + Wλ` nonnegative to `gap_tol`): then it is the
/// QP's solution, and `lambda` holds it. `active` ends as the set tried last.
pub(crate) fn solve_by_active_set(
    w: &[f64],
    c: &[f64],
    active: &mut Vec<usize>,
    gap_tol: f64,
    lambda: &mut Vec<f64>,
    work: &mut Vec<f64>,
) -> bool {
    let m = c.len();
    for _ in 0..=MAX_SWAPS {
        if !on_active_set(w, c, active, lambda, work) {
            return false;
        }
        // The negative multipliers leave.
        let before = active.len();
        active.retain(|&a| lambda[a] >= 0.0);
        if active.len() < before {
            continue;
        }
        // Else the penetrating rows join.
        let mut joined = false;
        let mut stuck = false;
        for r in 0..m {
            let gap = c[r]
                + active
                    .iter()
                    .map(|&a| w[r + a * m] * lambda[a])
                    .sum::<f64>();
            if gap < -gap_tol {
                match active.binary_search(&r) {
                    Err(p) => {
                        active.insert(p, r);
                        joined = true;
                    }
                    // A row of the set penetrates: it was dropped as dependent.
                    Ok(_) => stuck = true,
                }
            }
        }
        if !joined {
            return !stuck;
        }
    }
    false
}

/// `W_AA λ_A = −c_A` by a dense Cholesky factorisation into `lambda` (zero off the
/// set). A row that depends on those before it (a pivot below 1e-13 of its
/// diagonal: two rows of one slave in an all but flat notch) is dropped, its
/// multiplier left zero. False when `W_AA` has a non-positive diagonal.
pub(crate) fn on_active_set(
    w: &[f64],
    c: &[f64],
    active: &[usize],
    lambda: &mut Vec<f64>,
    work: &mut Vec<f64>,
) -> bool {
    let m = c.len();
    let k = active.len();
    lambda.clear();
    lambda.resize(m, 0.0);
    work.clear();
    work.resize(k * k + k, 0.0);
    let (l, x) = work.split_at_mut(k * k);
    for (j, &aj) in active.iter().enumerate() {
        for (i, &ai) in active.iter().enumerate().skip(j) {
            l[i + j * k] = w[ai + aj * m];
        }
    }
    for j in 0..k {
        let diag = l[j + j * k];
        let mut d = diag;
        for p in 0..j {
            d -= l[j + p * k] * l[j + p * k];
        }
        if !d.is_finite() || diag.is_nan() || diag <= 0.0 {
            return false;
        }
        if d <= 1e-13 * diag {
            for i in j..k {
                l[i + j * k] = 0.0;
            }
            continue;
        }
        let d = d.sqrt();
        l[j + j * k] = d;
        for i in j + 1..k {
            let mut v = l[i + j * k];
            for p in 0..j {
                v -= l[i + p * k] * l[j + p * k];
            }
            l[i + j * k] = v / d;
        }
    }
    for (i, &ai) in active.iter().enumerate() {
        if l[i + i * k] == 0.0 {
            x[i] = 0.0;
            continue;
        }
        let mut v = -c[ai];
        for p in 0..i {
            v -= l[i + p * k] * x[p];
        }
        x[i] = v / l[i + i * k];
    }
    for i in (0..k).rev() {
        if l[i + i * k] == 0.0 {
            continue;
        }
        let mut v = x[i];
        for p in i + 1..k {
            v -= l[p + i * k] * x[p];
        }
        x[i] = v / l[i + i * k];
    }
    for (i, &ai) in active.iter().enumerate() {
        lambda[ai] = x[i];
    }
    true
}

/// The condensed dual QP with a solver kept between solves of the same size.
#[derive(Default)]
pub(crate) struct DualQp {
    solver: Option<(usize, DefaultSolver<f64>)>,
}

impl DualQp {
    /// Solves `min ½ λᵀWλ + λᵀc, λ ≥ 0` (`w` column-major `m x m`) into `lambda`.
    pub fn solve(
        &mut self,
        w: &[f64],
        c: &[f64],
        lambda: &mut Vec<f64>,
    ) -> Result<QpStats, String> {
        let m = c.len();
        lambda.clear();
        lambda.resize(m, 0.0);
        // λ = 0 is optimal when no gap would close: ½λᵀWλ + λᵀc ≥ 0 for λ ≥ 0.
        if c.iter().all(|&x| x >= 0.0) {
            return Ok(QpStats::default());
        }
        let w_bar = (0..m).map(|i| w[i + i * m]).sum::<f64>() / m as f64;
        let ell = c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if !(w_bar > 0.0 && w_bar.is_finite() && ell.is_finite()) {
            return Err(format!(
                "the condensed matrix is not positive (mean diagonal {w_bar:e})"
            ));
        }
        let q: Vec<f64> = c.iter().map(|x| x / ell).collect();
        let p = dense_upper(w, m, 1.0 / w_bar);
        let reuse = matches!(&self.solver, Some((k, _)) if *k == m);
        if reuse {
            let (_, s) = self.solver.as_mut().expect("checked");
            s.update_P(&p.nzval)
                .map_err(|e| format!("Clarabel update: {e:?}"))?;
            s.update_q(&q)
                .map_err(|e| format!("Clarabel update: {e:?}"))?;
        } else {
            let a = CscMatrix::new(m, m, (0..=m).collect(), (0..m).collect(), vec![-1.0; m]);
            let b = vec![0.0; m];
            let cones = [SupportedConeT::NonnegativeConeT(m)];
            let s = DefaultSolver::new(&p, &q, &a, &b, &cones, settings())
                .map_err(|e| format!("Clarabel setup: {e}"))?;
            self.solver = Some((m, s));
        }
        let (_, s) = self.solver.as_mut().expect("set above");
        s.solve();
        accept(s.solution.status)?;
        let f = ell / w_bar;
        for (l, mu) in lambda.iter_mut().zip(&s.solution.x) {
            *l = (f * mu).max(0.0);
        }
        Ok(QpStats {
            iterations: s.solution.iterations,
            solve_s: s.solution.solve_time,
            programs: 1,
        })
    }
}

/// The upper triangle of the symmetric matrix whose lower triangle is `a`, in CSC.
fn upper_of(a: &LowerCsc) -> CscMatrix<f64> {
    let n = a.n;
    let mut count = vec![0usize; n + 1];
    for &i in &a.row_idx {
        count[i + 1] += 1;
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let colptr = count.clone();
    let mut fill = count;
    let mut rowval = vec![0usize; a.row_idx.len()];
    let mut nzval = vec![0.0; a.row_idx.len()];
    for j in 0..n {
        for p in a.col_ptr[j]..a.col_ptr[j + 1] {
            let i = a.row_idx[p];
            // (i, j) with i ≥ j in the lower triangle is (j, i) in the upper one:
            // column i, row j.
            rowval[fill[i]] = j;
            nzval[fill[i]] = a.values[p];
            fill[i] += 1;
        }
    }
    CscMatrix::new(n, n, colptr, rowval, nzval)
}

/// The primal QP `min ½ δᵀAδ + rᵀδ`, `g + Gδ ≥ 0` over the free dofs: `g_rows[i]` is
/// the row `i` of `G` as `(free equation, coefficient)` pairs. Writes `δ` and the
/// multipliers `λ`.
///
/// Scaled before Clarabel sees it: with `σ` the size of the displacement change (the
/// unconstrained one) and `κ = σ² ā` (`ā` the mean diagonal of `A`), it solves for
/// `δ̂ = δ/σ` with `P̂ = σ²A/κ`, `q̂ = σr/κ` and the gaps `g/σ`, all of order one; the
/// forces are `λ = (κ/σ) ẑ` from its duals `ẑ`.
pub(crate) fn primal_qp(
    a: &LowerCsc,
    r: &[f64],
    gaps: &[f64],
    g_rows: &[Vec<(usize, f64)>],
    sigma: f64,
    delta: &mut Vec<f64>,
    lambda: &mut Vec<f64>,
) -> Result<QpStats, String> {
    let (n, m) = (a.n, gaps.len());
    let a_bar = (0..n).map(|j| a.diagonal(j)).sum::<f64>() / n.max(1) as f64;
    let kappa = sigma * sigma * a_bar;
    if !(kappa > 0.0 && kappa.is_finite()) {
        return Err(format!(
            "cannot scale the primal QP (σ = {sigma:e}, mean diagonal {a_bar:e})"
        ));
    }
    let mut p = upper_of(a);
    for v in p.nzval.iter_mut() {
        *v *= sigma * sigma / kappa;
    }
    let q: Vec<f64> = r.iter().map(|x| sigma * x / kappa).collect();
    let b: Vec<f64> = gaps.iter().map(|x| x / sigma).collect();
    // Constraint rows −G δ + s = g, s ≥ 0, as a CSC matrix (columns = dofs).
    let mut triplets: Vec<(usize, usize, f64)> = Vec::new();
    for (i, row) in g_rows.iter().enumerate() {
        for &(j, v) in row {
            triplets.push((i, j, -v));
        }
    }
    triplets.sort_by_key(|t| (t.1, t.0));
    let mut colptr = vec![0usize; n + 1];
    for t in &triplets {
        colptr[t.1 + 1] += 1;
    }
    for j in 0..n {
        colptr[j + 1] += colptr[j];
    }
    let rowval = triplets.iter().map(|t| t.0).collect();
    let nzval = triplets.iter().map(|t| t.2).collect();
    let g = CscMatrix::new(m, n, colptr, rowval, nzval);
    let cones = [SupportedConeT::NonnegativeConeT(m)];
    let mut s = DefaultSolver::new(&p, &q, &g, &b, &cones, settings())
        .map_err(|e| format!("Clarabel setup: {e}"))?;
    s.solve();
    accept(s.solution.status)?;
    delta.clear();
    delta.extend(s.solution.x.iter().map(|x| sigma * x));
    lambda.clear();
    lambda.extend(s.solution.z.iter().map(|z| (kappa / sigma * z).max(0.0)));
    Ok(QpStats {
        iterations: s.solution.iterations,
        solve_s: s.solution.solve_time,
        programs: 1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_two_contact_dual_qp_has_its_closed_form() {
        // W = [[2, 1], [1, 2]] (compliance 1e-10 scale), c = [−3, 1]e-6: the second
        // contact stays open, λ₁ = 3e-6 / 2e-10 = 1.5e4 and the gap of the second is
        // c₂ + W₂₁ λ₁ > 0.
        let s = 1e-10;
        let w = [2.0 * s, 1.0 * s, 1.0 * s, 2.0 * s];
        let c = [-3e-6, 1e-6];
        let mut qp = DualQp::default();
        let mut l = Vec::new();
        qp.solve(&w, &c, &mut l).unwrap();
        assert!((l[0] - 1.5e4).abs() < 1e-6 * 1.5e4, "{l:?}");
        assert!(l[1].abs() < 1e-6 * 1.5e4, "{l:?}");
        // Reuse the solver with new data of the same size: both close.
        let c2 = [-3e-6, -3e-6];
        qp.solve(&w, &c2, &mut l).unwrap();
        // W λ = 3e-6 for both: λ = 1e4 each.
        assert!(
            (l[0] - 1e4).abs() < 1e-6 * 1e4 && (l[1] - 1e4).abs() < 1e-6 * 1e4,
            "{l:?}"
        );
        // No gap closes: no force, no QP.
        qp.solve(&w, &[1e-6, 2e-6], &mut l).unwrap();
        assert_eq!(l, vec![0.0, 0.0]);
    }

    #[test]
    fn the_active_set_method_finds_the_solution_from_any_guess() {
        let s = 1e-10;
        let w = [2.0 * s, 1.0 * s, 1.0 * s, 2.0 * s];
        let c = [-3e-6, 1e-6];
        let (mut l, mut work) = (Vec::new(), Vec::new());
        // From every guess: only the first row is active, λ₁ = 1.5e4.
        for guess in [vec![0], vec![0, 1], vec![], vec![1]] {
            let mut active = guess.clone();
            assert!(
                solve_by_active_set(&w, &c, &mut active, 1e-15, &mut l, &mut work),
                "from {guess:?}"
            );
            assert_eq!(active, vec![0], "from {guess:?}");
            assert!((l[0] - 1.5e4).abs() < 1e-9 * 1.5e4 && l[1] == 0.0, "{l:?}");
        }
        // Clarabel agrees.
        let mut qp = DualQp::default();
        let mut lc = Vec::new();
        qp.solve(&w, &c, &mut lc).unwrap();
        assert!((lc[0] - l[0]).abs() < 1e-6 * l[0]);
        // Two identical rows (a flat notch): one carries the force, the KKT test
        // holds for the other.
        let w2 = [s, s, s, s];
        let mut active = vec![0, 1];
        assert!(solve_by_active_set(
            &w2,
            &[-1e-6, -1e-6],
            &mut active,
            1e-15,
            &mut l,
            &mut work
        ));
        assert!((l[0] + l[1] - 1e4).abs() < 1e-9 * 1e4, "{l:?}");
    }

    #[test]
    fn the_primal_qp_gives_the_dual_multipliers() {
        // A = diag(2, 4) (lower CSC), r = [−2, 0]: unconstrained δ = (1, 0). The
        // constraint 0.5 − δ₀ ≥ 0 (g = 0.5, G = [−1, 0]) holds with λ = 1:
        // A δ + r = Gᵀλ → 2·0.5 − 2 = −λ.
        let a = LowerCsc {
            n: 2,
            col_ptr: vec![0, 1, 2],
            row_idx: vec![0, 1],
            values: vec![2.0, 4.0],
        };
        let (mut d, mut l) = (Vec::new(), Vec::new());
        primal_qp(
            &a,
            &[-2.0, 0.0],
            &[0.5],
            &[vec![(0, -1.0)]],
            1.0,
            &mut d,
            &mut l,
        )
        .unwrap();
        assert!((d[0] - 0.5).abs() < 1e-8 && d[1].abs() < 1e-8, "{d:?}");
        assert!((l[0] - 1.0).abs() < 1e-8, "{l:?}");
    }
}
