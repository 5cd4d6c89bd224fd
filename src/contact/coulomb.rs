//! Coulomb friction in the condensed dual: a sequence of second-order cone programs
//! (De Saxcé's fixed point), solved with Clarabel.
//!
//! The rows are the normal gaps (`n` of them, first) and, for the pressed nodes of
//! frictional pairs, their tangential slips (after them). With `W = G A⁻¹ Gᵀ` and
//! `c` the predicted gaps and slips, the forces `Λ` give the gaps and slips
//! `y = c + WΛ`. Coulomb's law at a frictional node (`λ_N`, `λ_T`, gap `g`, slip `s`):
//! `λ_N ≥ 0`, `g ≥ 0`, `λ_N g = 0`; `|λ_T| ≤ μ λ_N`; sticking (`|λ_T| < μ λ_N`) means
//! `s = 0`, slipping means `s = −α λ_T` with `α ≥ 0`.
//!
//! With the shift `σ = μ |s|` fixed, the program
//!
//! `min ½ ΛᵀWΛ + Λᵀ(c + σ e_N)   over   Λ ∈ K = {λ_N ≥ 0, |λ_T| ≤ μ λ_N}`
//!
//! has the optimality conditions `K ∋ Λ ⊥ y + σ e_N ∈ K*`, `K* = {μ |y_T| ≤ y_N}`:
//! with `σ = μ|s|` they are exactly Coulomb's law (the modified velocity of De
//! Saxcé and Feng). The shift is updated from the slips of the solution until it
//! settles (`theory/contact.md`); each cone `(μ λ_N, λ_T)` is Clarabel's second-order
//! cone of dimension 2, the frictionless rows its nonnegative cone. Data scaled to
//! order one as the frictionless dual.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, IPSolver, SupportedConeT};

use super::qp::{accept, dense_upper, settings, QpStats};

/// Fixed-point iterations on the shift before the solve is given up.
pub const MAX_SHIFT_ITERATIONS: usize = 100;

/// The shift has settled when no entry moved by more than this fraction of the
/// largest predicted gap or slip between two solves (Clarabel's own tolerance is
/// 1e-9 of it).
pub const SHIFT_TOLERANCE: f64 = 1e-8;

/// Solves Coulomb's law for the rows: `w` column-major `m x m`, `c` the predicted
/// gaps then slips, the first `n` rows normal, `cones[k] = (j, μ)` the normal row
/// `j` and coefficient of the tangential rows `n + tdim k + i`, `i < tdim` (one
/// tangent in the plane, two in a solid: the cone `|λ_T| ≤ μ λ_N` of dimension
/// `tdim + 1`). Writes the forces into `lambda` and returns the Clarabel iterations
/// summed over the shift iterations.
pub(crate) fn solve(
    w: &[f64],
    c: &[f64],
    (n, tdim): (usize, usize),
    cones: &[(usize, f64)],
    lambda: &mut Vec<f64>,
) -> Result<QpStats, String> {
    let m = c.len();
    debug_assert_eq!(m, n + tdim * cones.len());
    lambda.clear();
    lambda.resize(m, 0.0);
    // No force when no gap would close: Λ = 0 with σ = μ|c_T| satisfies the law.
    if c[..n].iter().all(|&x| x >= 0.0) {
        return Ok(QpStats::default());
    }
    let w_bar = (0..m).map(|i| w[i + i * m]).sum::<f64>() / m as f64;
    let ell = c.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if !(w_bar > 0.0 && w_bar.is_finite() && ell.is_finite()) {
        return Err(format!(
            "the condensed matrix is not positive (mean diagonal {w_bar:e})"
        ));
    }
    let p = dense_upper(w, m, 1.0 / w_bar);
    // Constraints s = b − AΛ ∈ K: the frictionless normal rows in the nonnegative
    // cone, then (μ λ_N, λ_T) per frictional node.
    let mut frictional = vec![false; n];
    for &(j, _) in cones {
        frictional[j] = true;
    }
    let mut entries: Vec<(usize, usize, f64)> = Vec::with_capacity(m);
    let mut row = 0;
    for (j, &f) in frictional.iter().enumerate() {
        if !f {
            entries.push((row, j, -1.0));
            row += 1;
        }
    }
    let free = row;
    for (k, &(j, mu)) in cones.iter().enumerate() {
        entries.push((row, j, -mu));
        for i in 0..tdim {
            entries.push((row + 1 + i, n + tdim * k + i, -1.0));
        }
        row += 1 + tdim;
    }
    let a = csc(row, m, &mut entries);
    let b = vec![0.0; row];
    let mut kinds = Vec::with_capacity(1 + cones.len());
    if free > 0 {
        kinds.push(SupportedConeT::NonnegativeConeT(free));
    }
    kinds.extend(
        cones
            .iter()
            .map(|_| SupportedConeT::SecondOrderConeT(1 + tdim)),
    );
    let mut shift = vec![0.0; cones.len()];
    let mut q: Vec<f64> = c.iter().map(|x| x / ell).collect();
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &kinds, settings())
        .map_err(|e| format!("Clarabel setup: {e}"))?;
    let mut stats = QpStats::default();
    let f = ell / w_bar;
    // The shift is μ times a slip Clarabel gives to about 1e-9 of `ell`: it settles to
    // the tolerance scaled by the largest μ (theory/friction.md, "large μ").
    let mu_max = cones.iter().fold(1.0f64, |a, &(_, mu)| a.max(mu));
    let mut last_moved = f64::INFINITY;
    let mut by_status = Vec::new();
    for _ in 0..MAX_SHIFT_ITERATIONS {
        solver.solve();
        accept(solver.solution.status)?;
        stats.iterations += solver.solution.iterations;
        stats.programs += 1;
        stats.solve_s += solver.solution.solve_time;
        for (l, x) in lambda.iter_mut().zip(&solver.solution.x) {
            *l = f * x;
        }
        // The slips of the solution, and the shift they ask for.
        let mut moved: f64 = 0.0;
        for (k, &(j, mu)) in cones.iter().enumerate() {
            let slip = |t: usize| c[t] + (0..m).map(|i| w[t + i * m] * lambda[i]).sum::<f64>();
            let size = if tdim == 1 {
                slip(n + k).abs()
            } else {
                (0..tdim)
                    .map(|i| slip(n + tdim * k + i).powi(2))
                    .sum::<f64>()
                    .sqrt()
            };
            let s = mu * size;
            moved = moved.max((s - shift[k]).abs());
            shift[k] = s;
            q[j] = (c[j] + s) / ell;
        }
        if moved <= SHIFT_TOLERANCE * mu_max * ell {
            // With μ > 1 the cone's two entries differ by μ and Clarabel's tolerance on
            // the larger one is a tolerance of μ on the tangential force: in the plane
            // the statuses polish it to the law's solution.
            if mu_max > 1.0 && by_statuses(w, c, (n, tdim, cones), lambda, ell, &mut by_status) {
                lambda.copy_from_slice(&by_status);
                return Ok(stats);
            }
            for l in &mut lambda[..n] {
                *l = l.max(0.0);
            }
            return Ok(stats);
        }
        // Not contracting by half: in the plane the law is linear on statuses, and
        // an iteration on them from where this program ended finds its solution.
        if moved > 0.5 * last_moved
            && by_statuses(w, c, (n, tdim, cones), lambda, ell, &mut by_status)
        {
            lambda.copy_from_slice(&by_status);
            return Ok(stats);
        }
        last_moved = moved;
        solver
            .update_q(&q)
            .map_err(|e| format!("Clarabel update: {e:?}"))?;
    }
    Err(format!(
        "the friction shift did not settle in {MAX_SHIFT_ITERATIONS} cone programs"
    ))
}

/// Rounds of the status iteration before it is given up.
const MAX_STATUS_ROUNDS: usize = 16;

/// Coulomb's law in the plane by an iteration on statuses, started from those a cone
/// program's forces `lambda` end in (a normal row pressed if its force exceeds a
/// millionth of the largest; a node sticking inside the cone, or slipping against
/// its tangential force): each round solves the linear law of its statuses and
/// changes those the result breaks. True, with the forces in `out`, when a round's
/// result satisfies the whole law.
fn by_statuses(
    w: &[f64],
    c: &[f64],
    (n, tdim, cones): (usize, usize, &[(usize, f64)]),
    lambda: &[f64],
    ell: f64,
    out: &mut Vec<f64>,
) -> bool {
    let largest = lambda[..n].iter().fold(0.0f64, |a, x| a.max(*x));
    let mut pressed: Vec<bool> = lambda[..n].iter().map(|&l| l > 1e-6 * largest).collect();
    let mut guess: Vec<Guess> = cones
        .iter()
        .enumerate()
        .map(|(k, &(j, mu))| {
            let t = &lambda[n + tdim * k..n + tdim * (k + 1)];
            if t.iter().map(|x| x * x).sum::<f64>().sqrt() < (1.0 - 1e-6) * mu * lambda[j] {
                Guess::Stick
            } else {
                Guess::slip_along(t)
            }
        })
        .collect();
    for _ in 0..MAX_STATUS_ROUNDS {
        match law_on_guess(
            w,
            c,
            (n, cones),
            (&mut pressed, &mut guess),
            1e-9 * ell,
            out,
        ) {
            Verdict::Holds => return true,
            Verdict::Singular => return false,
            Verdict::Changed => {}
        }
    }
    false
}

/// A CSC matrix from `(row, column, value)` triplets (distinct positions).
fn csc(rows: usize, cols: usize, entries: &mut [(usize, usize, f64)]) -> CscMatrix<f64> {
    entries.sort_unstable_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; cols + 1];
    for &(_, c, _) in entries.iter() {
        colptr[c + 1] += 1;
    }
    for j in 0..cols {
        colptr[j + 1] += colptr[j];
    }
    CscMatrix::new(
        rows,
        cols,
        colptr,
        entries.iter().map(|e| e.0).collect(),
        entries.iter().map(|e| e.2).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One node on a rigid support, compliance `w_n` normal and `w_t` tangential (no
    /// coupling): pressed by a predicted penetration and pushed sideways by a
    /// predicted slip.
    fn one(mu: f64, c_n: f64, c_t: f64) -> (f64, f64, f64) {
        let (wn, wt) = (2.0e-9, 3.0e-9);
        let w = [wn, 0.0, 0.0, wt];
        let mut l = Vec::new();
        solve(&w, &[c_n, c_t], (1, 1), &[(0, mu)], &mut l).unwrap();
        let slip = c_t + wt * l[1];
        (l[0], l[1], slip)
    }

    #[test]
    fn a_pressed_node_sticks_below_the_cone_and_slides_on_it() {
        // Normal force 1e6 N from the penetration; sticking needs 1e5 N sideways.
        let (n, t, s) = one(0.5, -2.0e-3, 3.0e-4);
        assert!((n - 1.0e6).abs() < 1e-3 * 1e6, "{n}");
        assert!(
            (t + 1.0e5).abs() < 1e-3 * 1e5 && s.abs() < 1e-9,
            "stick: {t} {s}"
        );
        // With μ = 0.05 the cone allows 5e4 N: it slides, the force opposes the slip.
        let (n, t, s) = one(0.05, -2.0e-3, 3.0e-4);
        assert!((n - 1.0e6).abs() < 1e-3 * 1e6, "{n}");
        assert!((t + 5.0e4).abs() < 1e-6 * 5e4, "slide: {t}");
        let expect = 3.0e-4 - 3.0e-9 * 5.0e4;
        // Clarabel stops at 1e-9 of the scaled data: the slip to 1e-7 of itself.
        assert!(
            (s - expect).abs() < 1e-7 * 3e-4,
            "slip {s} against {expect}"
        );
        // Open: no force at all.
        let (n, t, _) = one(0.5, 1.0e-3, 3.0e-4);
        assert_eq!((n, t), (0.0, 0.0));
    }

    #[test]
    fn a_right_guess_gives_the_cone_programs_answer_and_a_wrong_one_is_refused() {
        // Two coupled frictional nodes: the cone programs' answer, then the same
        // from the statuses it ended in, and a wrong guess refused.
        let w = [
            2.0e-9, 0.5e-9, 0.1e-9, 0.0, //
            0.5e-9, 2.5e-9, 0.0, 0.2e-9, //
            0.1e-9, 0.0, 3.0e-9, 0.4e-9, //
            0.0, 0.2e-9, 0.4e-9, 2.0e-9,
        ];
        let c = [-2.0e-3, -1.0e-3, 3.0e-4, -1.0e-5];
        let cones = [(0, 0.1), (1, 0.5)];
        let mut reference = Vec::new();
        solve(&w, &c, (2, 1), &cones, &mut reference).unwrap();
        let status = |k: usize| {
            let (ln, lt, mu) = (reference[cones[k].0], reference[2 + k], cones[k].1);
            if lt.abs() < (1.0 - 1e-6) * mu * ln {
                Guess::Stick
            } else {
                Guess::slip_along(&[lt])
            }
        };
        let guess = [status(0), status(1)];
        assert!(
            matches!(guess[0], Guess::Slip(_)) && guess[1] == Guess::Stick,
            "{guess:?}"
        );
        let mut l = Vec::new();
        assert!(solve_by_guess(
            &w,
            &c,
            2,
            &cones,
            &[true, true],
            &guess,
            1e-12,
            &mut l
        ));
        for (a, b) in l.iter().zip(&reference) {
            assert!(
                (a - b).abs() < 1e-6 * reference[0],
                "{l:?} against {reference:?}"
            );
        }
        // Guessing the slipping node sticks puts its force outside the cone.
        assert!(!solve_by_guess(
            &w,
            &c,
            2,
            &cones,
            &[true, true],
            &[Guess::Stick; 2],
            1e-12,
            &mut l
        ));
    }
}

/// How a frictional node is guessed to end: inside the cone, or on it along a
/// direction of its tangential force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Guess {
    /// `|λ_T| < μ λ_N`, no slip.
    Stick,
    /// `λ_T = μ λ_N d` along the unit direction `d` in the row's tangents (in the
    /// plane `[±1, 0]`), the slip opposite to it.
    Slip([f64; 2]),
}

impl Guess {
    /// Whether it is [`Guess::Stick`].
    pub(crate) fn is_stick(&self) -> bool {
        matches!(self, Guess::Stick)
    }

    /// The slip of a node whose tangential force is `t` (`tdim` components): along
    /// `t`'s direction (its sign in the plane); sticking when `t` is zero in a
    /// solid, where it has no direction.
    pub(crate) fn slip_along(t: &[f64]) -> Guess {
        if t.len() == 1 {
            return Guess::Slip([t[0].signum(), 0.0]);
        }
        let size = t[0].hypot(t[1]);
        if size > 0.0 && size.is_finite() {
            Guess::Slip([t[0] / size, t[1] / size])
        } else {
            Guess::Stick
        }
    }
}

/// Solves Coulomb's law for the rows of [`solve`] on a guess of how it ends: the
/// normal rows `pressed` (the others open) and each frictional node's [`Guess`]. On
/// the guess the law is linear: pressed gaps and sticking slips vanish, a slipping
/// node's tangential force is `μ λ_N d` along its guessed direction `d` (`sign` in
/// the plane); the unknowns solve that by dense elimination. True, with the forces
/// in `lambda`, when the result satisfies the whole law (pressed forces
/// non-negative, open gaps non-negative to `tol`, sticking forces inside the cone,
/// slips opposite to their forces to `tol`, in a solid along the same line to `tol`):
/// then it is the law's solution and no cone program is needed. In persistent
/// contact the last iterate's statuses and directions hold, and a step costs one
/// small elimination.
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_by_guess(
    w: &[f64],
    c: &[f64],
    n: usize,
    cones: &[(usize, f64)],
    pressed: &[bool],
    guess: &[Guess],
    tol: f64,
    lambda: &mut Vec<f64>,
) -> bool {
    let mut p = pressed.to_vec();
    let mut g = guess.to_vec();
    // In the plane one round; in a solid more while only slip directions turn.
    let tdim = if cones.is_empty() {
        1
    } else {
        (c.len() - n) / cones.len()
    };
    let rounds = if tdim == 1 { 1 } else { GUESS_ROUNDS };
    for _ in 0..rounds {
        let statuses = (p.clone(), g.iter().map(Guess::is_stick).collect::<Vec<_>>());
        match law_on_guess(w, c, (n, cones), (&mut p, &mut g), tol, lambda) {
            Verdict::Holds => return true,
            Verdict::Singular => return false,
            // A status the last QP got wrong (a node pressed or released, sticking
            // or slipping): the contact is changing, the cone programs' case (taking
            // the statuses the elimination asks for cut the first step of an impact
            // in `solid_contact_friction`).
            Verdict::Changed
                if statuses != (p.clone(), g.iter().map(Guess::is_stick).collect()) =>
            {
                return false
            }
            Verdict::Changed => {}
        }
    }
    false
}

/// Rounds a guess may take in a solid: a slip direction taken from the last QP is
/// off by the change of the motion since (a millionth in a block accelerating down a
/// slope), and each round turns it to the slip the last one gave (by a factor of
/// about four a round) until the law holds to the QP's tolerance. Each round is one
/// elimination of the pressed rows, far cheaper than a cone program.
const GUESS_ROUNDS: usize = 16;

/// What the law says of the forces a guess of statuses gives.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    /// They satisfy the whole law: the law's solution.
    Holds,
    /// Some statuses were wrong and have been changed to what the forces say.
    Changed,
    /// The linear system of the guess is singular.
    Singular,
}

/// [`solve_by_guess`]'s elimination and check; where the law is broken, the statuses
/// are changed to what the forces and gaps say (a pressed row pulling opens, an open
/// row penetrating is pressed, a sticking force outside the cone slips with its
/// sign, a slip along its force sticks), the step of a status iteration.
fn law_on_guess(
    w: &[f64],
    c: &[f64],
    (n, cones): (usize, &[(usize, f64)]),
    (pressed, guess): (&mut [bool], &mut [Guess]),
    tol: f64,
    lambda: &mut Vec<f64>,
) -> Verdict {
    let m = c.len();
    // One tangential row per node in the plane, two in a solid (a slip linear on
    // its guessed direction).
    let tdim = if cones.is_empty() {
        1
    } else {
        (m - n) / cones.len()
    };
    // Unknowns: λ_N of the pressed rows, then λ_T of their sticking nodes.
    let mut rows = Vec::new();
    for j in (0..n).filter(|&j| pressed[j]) {
        rows.push(j);
    }
    for (k, &(j, _)) in cones.iter().enumerate() {
        if pressed[j] && guess[k] == Guess::Stick {
            rows.extend((0..tdim).map(|i| n + tdim * k + i));
        }
    }
    let q = rows.len();
    if q == 0 {
        return Verdict::Singular;
    }
    // dΛ/dx: a pressed row's λ_N also drives its slipping node's λ_T, `μ d_i` per
    // tangential row `t + i`.
    let mut slip_of: Vec<Option<(usize, [f64; 2])>> = vec![None; n];
    for (k, &(j, mu)) in cones.iter().enumerate() {
        if let Guess::Slip(d) = guess[k] {
            slip_of[j] = Some((n + tdim * k, [mu * d[0], mu * d[1]]));
        }
    }
    let mut b = vec![0.0; q * q];
    let mut rhs = vec![0.0; q];
    for (e, &r) in rows.iter().enumerate() {
        rhs[e] = -c[r];
        for (v, &i) in rows.iter().enumerate() {
            let mut x = w[r + i * m];
            if let Some(Some((t, f))) = slip_of.get(i) {
                for (a, fa) in f.iter().enumerate().take(tdim) {
                    x += fa * w[r + (t + a) * m];
                }
            }
            b[e + v * q] = x;
        }
    }
    if !eliminate(&mut b, &mut rhs, q) {
        return Verdict::Singular;
    }
    lambda.clear();
    lambda.resize(m, 0.0);
    for (v, &i) in rows.iter().enumerate() {
        lambda[i] = rhs[v];
        if let Some(Some((t, f))) = slip_of.get(i) {
            for (a, fa) in f.iter().enumerate().take(tdim) {
                lambda[t + a] = fa * rhs[v];
            }
        }
    }
    // The whole law.
    let scale = lambda.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let y = |r: usize, lambda: &[f64]| c[r] + (0..m).map(|i| w[r + i * m] * lambda[i]).sum::<f64>();
    let mut changed = false;
    for j in 0..n {
        if pressed[j] {
            if lambda[j] < -1e-12 * scale {
                pressed[j] = false;
                changed = true;
            }
        } else if y(j, lambda) < -tol {
            pressed[j] = true;
            changed = true;
        }
    }
    for (k, &(j, mu)) in cones.iter().enumerate() {
        if !pressed[j] {
            continue;
        }
        let ln = lambda[j];
        let lt = lambda[n + tdim * k..n + tdim * (k + 1)]
            .iter()
            .map(|x| x * x)
            .sum::<f64>()
            .sqrt();
        match guess[k] {
            Guess::Stick if lt > mu * ln * (1.0 + 1e-12) + 1e-12 * scale => {
                guess[k] = Guess::slip_along(&lambda[n + tdim * k..n + tdim * (k + 1)]);
                changed = true;
            }
            Guess::Slip(d) => {
                // The slip `s` must be opposite to the force: `s · d ≤ 0`, and in a
                // solid along the same line.
                let mut s = [0.0; 2];
                for (i, si) in s.iter_mut().enumerate().take(tdim) {
                    *si = y(n + tdim * k + i, lambda);
                }
                let along = if tdim == 1 {
                    d[0] * s[0]
                } else {
                    d[0] * s[0] + d[1] * s[1]
                };
                if along > tol {
                    guess[k] = Guess::Stick;
                    changed = true;
                } else if tdim > 1 {
                    // Across the direction the same tolerance as along it.
                    let across = (s[0] - along * d[0]).hypot(s[1] - along * d[1]);
                    if across > tol {
                        guess[k] = Guess::slip_along(&[-s[0], -s[1]]);
                        changed = true;
                    }
                }
            }
            _ => {}
        }
    }
    if changed {
        return Verdict::Changed;
    }
    for l in &mut lambda[..n] {
        *l = l.max(0.0);
    }
    Verdict::Holds
}

/// Solves the dense `q x q` system `b x = rhs` (column-major) by Gaussian elimination
/// with partial pivoting, into `rhs`. False when a pivot vanishes.
fn eliminate(b: &mut [f64], rhs: &mut [f64], q: usize) -> bool {
    let norm = b.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    for col in 0..q {
        let p = (col..q)
            .max_by(|&x, &y| b[x + col * q].abs().total_cmp(&b[y + col * q].abs()))
            .expect("a row");
        let pivot = b[p + col * q];
        // A NaN pivot fails too.
        if pivot.abs().partial_cmp(&(1e-13 * norm)) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        if p != col {
            for k in 0..q {
                b.swap(p + k * q, col + k * q);
            }
            rhs.swap(p, col);
        }
        for r in col + 1..q {
            let f = b[r + col * q] / pivot;
            if f != 0.0 {
                for k in col..q {
                    b[r + k * q] -= f * b[col + k * q];
                }
                rhs[r] -= f * rhs[col];
            }
        }
    }
    for col in (0..q).rev() {
        let mut v = rhs[col];
        for k in col + 1..q {
            v -= b[col + k * q] * rhs[k];
        }
        rhs[col] = v / b[col + col * q];
    }
    true
}
