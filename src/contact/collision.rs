//! Collision times of the explicit kinematic contact method: within a time step of
//! length `h` every position moves at constant velocity, `x(t) = x + t·v` for
//! `t ∈ [0, h]`, and the question is the earliest `t` at which a node reaches a
//! master facet (a segment in 2D, a triangle in 3D) from outside. Pure functions on
//! plain arrays; nothing allocates.
//!
//! # Conventions
//!
//! - **2D, [`node_segment`].** The segment `a → b` has its body on its *left*, so its
//!   outward unit normal is `n = (d.y, −d.x)/|d|` with `d = b − a`. With `e = p − a`
//!   and `cross(u, v) = u.x v.y − u.y v.x`, the signed gap of the node is
//!   `gap(t) = e(t)·n(t) = q(t)/|d(t)|` with `q(t) = −cross(d(t), e(t))`, a quadratic
//!   in `t` ([`segment_quadratic`]). The projection parameter is
//!   `ξ(t) = e(t)·d(t)/|d(t)|²` (0 at `a`, 1 at `b`).
//! - **3D, [`node_triangle`].** The triangle `a, b, c` is counter-clockwise seen from
//!   outside: its outward normal is `N = (b − a) × (c − a)` (not normalised). The
//!   signed volume `V(t) = N(t)·(p(t) − a(t))` is a cubic in `t`
//!   ([`triangle_cubic`]) and `gap(t) = V(t)/|N(t)|`. The barycentric coordinates
//!   `[λ_a, λ_b, λ_c]` are those of the projection of `p(t)` on the triangle's plane.
//! - Polynomial coefficients are returned in ascending order: index `k` holds the
//!   coefficient of `t^k` (so `triangle_cubic(..) = [C0, C1, C2, C3]` for
//!   `V = C3 t³ + C2 t² + C1 t + C0`).
//! - Velocities enter only relative to `a` (`v − v_a`), so a common translation of
//!   the whole configuration changes nothing.
//!
//! # What counts as a hit
//!
//! A hit is the earliest `t ∈ [0, h]` at which the gap goes from `≥ 0` to `< 0` (a
//! crossing from outside) with the projection inside the facet, i.e. `ξ` within
//! `[−XI_TOL, 1 + XI_TOL]` or every barycentric coordinate within
//! `[−BARY_TOL, 1 + BARY_TOL]`; the reported `ξ` is clamped to `[0, 1]`, the
//! barycentric coordinates clamped to `[0, 1]` and renormalised to sum 1. Hitting an
//! end point, an edge or a vertex exactly is a hit. A crossing beyond the facet is no
//! hit, but the search goes on to later crossings in the step. The degenerate cases:
//!
//! - **No valid step or data**: `h ≤ 0`, `h` or any coordinate not finite: `None`.
//! - **Collapsed facet**: a segment shorter than `COLLAPSE_TOL·ℓ`, or a triangle with
//!   `|N| ≤ COLLAPSE_TOL·ℓ²` (a point or a sliver), at `t = 0` or at the crossing,
//!   where `ℓ` bounds the facet's edge lengths over the step (`|edge| + h·|Δv|`):
//!   the normal and the projection are undefined there, so `None` (or, at a
//!   crossing, no hit at that crossing).
//! - **Already penetrating**: `gap(0) < −GAP_TOL·L` with the projection inside the
//!   facet at `t = 0`: `None`; the node is inside already and the caller deals with
//!   it. A node on the inner side of the facet's line or plane but *beside* the
//!   facet is not penetrating it, and a later crossing is still found.
//! - **On the facet at `t = 0`** (`|gap(0)| ≤ GAP_TOL·L`): the gap is taken as
//!   exactly 0. If the motion stays within that tolerance over the whole step
//!   (`Σ_k |c_k| h^k ≤ GAP_TOL·L·|d(0)|`, resp. `|N(0)|`), the node slides on the
//!   facet: `None`. Otherwise it is *approaching* when the first term
//!   `c_k h^k` (k = 1, 2, 3) beyond that tolerance is negative; approaching with the
//!   projection inside: `t = 0`. Separating or tangential: no hit at `t = 0`; since
//!   the gap is a polynomial of degree two or three, the motion can still bring the
//!   node back within the step, and such a later crossing from outside is reported.
//! - **Grazing**: where the gap reaches a local minimum within `GAP_TOL·L` of zero
//!   (a double root: the node touches without going in), there is no crossing; a
//!   local maximum within the tolerance (touching from inside) is none either. A
//!   triple root (an inflection on zero) is a crossing.
//! - **Parallel or no relative motion**: the polynomial degenerates to a lower degree
//!   or a constant; it then crosses or it does not, and the root finders below handle
//!   any degree without a threshold on the leading coefficient.
//!
//! # Tolerances
//!
//! All are relative. The length scale is
//! `L = max(longest facet edge at t = 0, h·|Δv|)` over the relative velocities
//! `Δv` of the node and of the facet's vertices with respect to `a`: the larger of the
//! facet's size and the motion over the step, so that neither a tiny facet nor a
//! fast node makes round-off look like contact. [`GAP_TOL`] = 1e-9 of it decides
//! "on the facet", "penetrating" and "grazing": about four million ulps of the
//! coordinates' relative precision (round-off of a gap computed from coordinates of
//! size `L` is ~1e-16·L) and still far below any physically meaningful gap.
//! [`XI_TOL`] = [`BARY_TOL`] = 1e-9 extend the facet by a billionth of its size so
//! that a hit exactly on an end point, edge or vertex survives round-off.
//! [`COLLAPSE_TOL`] = 1e-9 declares a facet collapsed when its length (area) is a
//! billionth of its size over the step.
//!
//! # Method
//!
//! 2D: the roots of `q` by the cancellation-free ("citardauq") quadratic formula,
//! `Q = −(c1 + sign(c1)·√(c1² − 4c0c2))/2`, roots `Q/c2` and `c0/Q`, which degrades
//! gracefully to the linear root `−c0/c1` as `c2 → 0`, then one guarded Newton step
//! on `q`. Which root enters (`+` to `−`) follows from the sign of `c2`.
//!
//! 3D: the real roots of `V′` (a quadratic, same formula) split `[0, h]` into pieces
//! on which `V` is monotone; a piece whose start is outside and whose end is inside
//! holds exactly one crossing, found by bisection with safeguarded Newton steps
//! (Newton only while it stays inside the bracket and halves its step). Double and
//! triple roots sit at piece ends and need no special case; the grazing rule is
//! applied at the piece ends.

/// Relative tolerance on the gap (times the length scale `L`, see the module doc):
/// "on the facet" at `t = 0`, "penetrating", and the depth of a graze.
pub const GAP_TOL: f64 = 1e-9;

/// Tolerance on the projection parameter `ξ` of a segment: a crossing counts while
/// `ξ ∈ [−XI_TOL, 1 + XI_TOL]`.
pub const XI_TOL: f64 = 1e-9;

/// Tolerance on the barycentric coordinates of a triangle: a crossing counts while
/// each lies in `[−BARY_TOL, 1 + BARY_TOL]`.
pub const BARY_TOL: f64 = 1e-9;

/// A segment shorter than `COLLAPSE_TOL·ℓ`, or a triangle with `|N| ≤ COLLAPSE_TOL·ℓ²`,
/// counts as collapsed (`ℓ` bounds the edge lengths over the step).
pub const COLLAPSE_TOL: f64 = 1e-9;

/// When a node meets a segment within a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentHit {
    /// Time of impact from the start of the step, in `[0, h]`.
    pub t: f64,
    /// Projection parameter of the node on the segment at `t` (0 at `a`, 1 at `b`),
    /// clamped to `[0, 1]`.
    pub xi: f64,
}

/// When a node meets a triangle within a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Time of impact from the start of the step, in `[0, h]`.
    pub t: f64,
    /// Barycentric coordinates `[λ_a, λ_b, λ_c]` of the node's projection on the
    /// triangle at `t`, clamped to `[0, 1]` and summing to 1.
    pub bary: [f64; 3],
}

type V2 = [f64; 2];
type V3 = [f64; 3];

use crate::geometry::{axpy, cross, det3, dot, perp_dot, sub};

/// `|x|` of a plane vector, as `hypot`.
fn norm2(x: V2) -> f64 {
    x[0].hypot(x[1])
}

/// The coefficients `[c0, c1, c2]` of `q(t) = c0 + c1 t + c2 t² = −cross(d(t), e(t))`,
/// `d = b − a`, `e = p − a`, positions moving at constant velocity: `q(t)/|d(t)|` is
/// the node's signed gap to the line of the segment (positive outside, the body being
/// on the segment's left).
pub fn segment_quadratic(
    p: [f64; 2],
    vp: [f64; 2],
    a: [f64; 2],
    va: [f64; 2],
    b: [f64; 2],
    vb: [f64; 2],
) -> [f64; 3] {
    let (d0, dd) = (sub(b, a), sub(vb, va));
    let (e0, de) = (sub(p, a), sub(vp, va));
    [
        -perp_dot(d0, e0),
        -(perp_dot(d0, de) + perp_dot(dd, e0)),
        -perp_dot(dd, de),
    ]
}

/// The coefficients `[C0, C1, C2, C3]` of the signed volume
/// `V(t) = C0 + C1 t + C2 t² + C3 t³ = ((b − a) × (c − a))·(p − a)` at time `t`,
/// positions moving at constant velocity: `V(t)/|(b − a) × (c − a)|` is the node's
/// signed gap to the triangle's plane (positive on the side of the outward normal).
#[allow(clippy::too_many_arguments)]
pub fn triangle_cubic(
    p: [f64; 3],
    vp: [f64; 3],
    a: [f64; 3],
    va: [f64; 3],
    b: [f64; 3],
    vb: [f64; 3],
    c: [f64; 3],
    vc: [f64; 3],
) -> [f64; 4] {
    let (u0, du) = (sub(b, a), sub(vb, va));
    let (w0, dw) = (sub(c, a), sub(vc, va));
    let (e0, de) = (sub(p, a), sub(vp, va));
    [
        det3(u0, w0, e0),
        det3(du, w0, e0) + det3(u0, dw, e0) + det3(u0, w0, de),
        det3(u0, dw, de) + det3(du, w0, de) + det3(du, dw, e0),
        det3(du, dw, de),
    ]
}

/// The earliest time in `[0, h]` at which node `p` (velocity `vp`) reaches the
/// segment `a → b` (velocities `va`, `vb`) from outside, with the projection
/// parameter there; `None` if it does not within the step. See the module doc for
/// the conventions (body on the segment's left), the degenerate cases and the
/// tolerances.
pub fn node_segment(
    p: [f64; 2],
    vp: [f64; 2],
    a: [f64; 2],
    va: [f64; 2],
    b: [f64; 2],
    vb: [f64; 2],
    h: f64,
) -> Option<SegmentHit> {
    let valid = h > 0.0
        && h.is_finite()
        && [p, vp, a, va, b, vb]
            .iter()
            .flatten()
            .all(|x| x.is_finite());
    if !valid {
        return None;
    }
    let (d0, dd) = (sub(b, a), sub(vb, va));
    let (e0, de) = (sub(p, a), sub(vp, va));
    let len0 = norm2(d0);
    let len_bound = h.mul_add(norm2(dd), len0);
    let gap_tol = GAP_TOL * len0.max(h * norm2(de)).max(h * norm2(dd));
    let at = |t: f64| (axpy(d0, t, dd), axpy(e0, t, de));
    let collapsed = |d: V2| norm2(d) <= COLLAPSE_TOL * len_bound;
    let xi_of = |d: V2, e: V2| dot(e, d) / dot(d, d);
    let in_range = |xi: f64| (-XI_TOL..=1.0 + XI_TOL).contains(&xi);
    if collapsed(d0) {
        return None;
    }

    let [mut c0, c1, c2] = segment_quadratic(p, vp, a, va, b, vb);
    let xi0 = xi_of(d0, e0);
    let gap0 = c0 / len0;
    if gap0 < -gap_tol && in_range(xi0) {
        return None; // penetrating already
    }
    let on_line = gap0.abs() <= gap_tol;
    if on_line {
        c0 = 0.0;
        let q_tol = gap_tol * len0;
        let (s1, s2) = (c1 * h, c2 * h * h);
        if s1.abs() + s2.abs() <= q_tol {
            return None; // stays on the line over the step
        }
        let approaching = s1 < -q_tol || (s1.abs() <= q_tol && s2 < -q_tol);
        if approaching && in_range(xi0) {
            return Some(SegmentHit {
                t: 0.0,
                xi: xi0.clamp(0.0, 1.0),
            });
        }
    }

    let c = [c0, c1, c2];
    let (roots, n) = quadratic_roots(c0, c1, c2);
    if n == 2 {
        // Both roots belong to the extremum of q at -c1/(2 c2): a graze (touching from
        // outside or from inside) when the extremum is within the tolerance of zero.
        let t_ext = (-c1 / (2.0 * c2)).clamp(0.0, h);
        let ext = -discriminant(c0, c1, c2) / (4.0 * c2);
        if ext.abs() <= gap_tol * norm2(at(t_ext).0) {
            return None;
        }
    }
    let max_step = if n == 2 {
        0.25 * (roots[1] - roots[0])
    } else {
        f64::INFINITY
    };
    for (i, &r) in roots[..n].iter().enumerate() {
        // q goes from + to − at the smaller root when c2 > 0, at the larger one when
        // c2 < 0, at the only one (linear q) when c1 < 0.
        let entering = if n == 1 {
            c1 < 0.0
        } else if c2 > 0.0 {
            i == 0
        } else {
            i == 1
        };
        if !entering {
            continue;
        }
        let r = polish_quadratic(c, r, max_step);
        if r < 0.0 || (on_line && r <= 0.0) || r > h * (1.0 + 8.0 * f64::EPSILON) {
            continue;
        }
        let t = r.min(h);
        let (d, e) = at(t);
        if collapsed(d) {
            continue;
        }
        let xi = xi_of(d, e);
        if in_range(xi) {
            return Some(SegmentHit {
                t,
                xi: xi.clamp(0.0, 1.0),
            });
        }
    }
    None
}

/// The earliest time in `[0, h]` at which node `p` (velocity `vp`) reaches the
/// triangle `a, b, c` (velocities `va`, `vb`, `vc`; counter-clockwise seen from
/// outside) from outside, with the barycentric coordinates of the node's projection
/// there; `None` if it does not within the step. See the module doc for the
/// conventions, the degenerate cases and the tolerances.
#[allow(clippy::too_many_arguments)]
pub fn node_triangle(
    p: [f64; 3],
    vp: [f64; 3],
    a: [f64; 3],
    va: [f64; 3],
    b: [f64; 3],
    vb: [f64; 3],
    c: [f64; 3],
    vc: [f64; 3],
    h: f64,
) -> Option<TriangleHit> {
    let valid = h > 0.0
        && h.is_finite()
        && [p, vp, a, va, b, vb, c, vc]
            .iter()
            .flatten()
            .all(|x| x.is_finite());
    if !valid {
        return None;
    }
    let (u0, du) = (sub(b, a), sub(vb, va));
    let (w0, dw) = (sub(c, a), sub(vc, va));
    let (e0, de) = (sub(p, a), sub(vp, va));
    let (f0, df) = (sub(w0, u0), sub(dw, du));
    let edge0 = crate::geometry::norm(u0)
        .max(crate::geometry::norm(w0))
        .max(crate::geometry::norm(f0));
    let ell = h
        .mul_add(crate::geometry::norm(du), crate::geometry::norm(u0))
        .max(h.mul_add(crate::geometry::norm(dw), crate::geometry::norm(w0)))
        .max(h.mul_add(crate::geometry::norm(df), crate::geometry::norm(f0)));
    let gap_tol = GAP_TOL
        * edge0
            .max(h * crate::geometry::norm(de))
            .max(h * crate::geometry::norm(du))
            .max(h * crate::geometry::norm(dw));
    let area_min = COLLAPSE_TOL * ell * ell;
    let frame = |t: f64| {
        let (u, w) = (axpy(u0, t, du), axpy(w0, t, dw));
        (u, w, axpy(e0, t, de), cross(u, w))
    };
    let bary_of = |u: V3, w: V3, e: V3, n: V3| {
        let nn = dot(n, n);
        let beta = dot(cross(e, w), n) / nn;
        let gamma = dot(cross(u, e), n) / nn;
        [1.0 - beta - gamma, beta, gamma]
    };
    let in_range = |l: [f64; 3]| l.iter().all(|x| (-BARY_TOL..=1.0 + BARY_TOL).contains(x));
    let normalise = |l: [f64; 3]| {
        let l = l.map(|x| x.clamp(0.0, 1.0));
        let s = l[0] + l[1] + l[2];
        l.map(|x| x / s)
    };

    let n0 = cross(u0, w0);
    let area0 = crate::geometry::norm(n0);
    if area0 <= area_min {
        return None;
    }
    let mut cc = triangle_cubic(p, vp, a, va, b, vb, c, vc);
    let bary0 = bary_of(u0, w0, e0, n0);
    let gap0 = cc[0] / area0;
    if gap0 < -gap_tol && in_range(bary0) {
        return None; // penetrating already
    }
    if gap0.abs() <= gap_tol {
        cc[0] = 0.0;
        let v_tol = gap_tol * area0;
        let s = [cc[1] * h, cc[2] * h * h, cc[3] * h * h * h];
        if s.iter().map(|x| x.abs()).sum::<f64>() <= v_tol {
            return None; // stays on the plane over the step
        }
        let approaching = s.iter().find(|x| x.abs() > v_tol).is_some_and(|&x| x < 0.0);
        if approaching && in_range(bary0) {
            return Some(TriangleHit {
                t: 0.0,
                bary: normalise(bary0),
            });
        }
    }

    first_crossing_cubic(
        cc,
        h,
        |t| gap_tol * crate::geometry::norm(frame(t).3),
        |t| {
            let (u, w, e, n) = frame(t);
            if crate::geometry::norm(n) <= area_min {
                return None;
            }
            let l = bary_of(u, w, e, n);
            in_range(l).then(|| TriangleHit {
                t,
                bary: normalise(l),
            })
        },
    )
}

/// `c1² − 4 c0 c2`, with one rounding less.
fn discriminant(c0: f64, c1: f64, c2: f64) -> f64 {
    c1.mul_add(c1, -4.0 * c0 * c2)
}

/// The real roots of `c0 + c1 t + c2 t²`, ascending, and how many there are (a double
/// root counts twice). Cancellation-free: `Q = −(c1 + sign(c1)√disc)/2`, roots `Q/c2`
/// and `c0/Q`; a vanishing `c2` leaves the linear root `c0/Q → −c0/c1` accurate and
/// sends the other to infinity. `c2 = 0` exactly: the linear root (none if `c1 = 0`).
fn quadratic_roots(c0: f64, c1: f64, c2: f64) -> ([f64; 2], usize) {
    if c2 == 0.0 {
        if c1 == 0.0 {
            return ([0.0; 2], 0);
        }
        return ([-c0 / c1, 0.0], 1);
    }
    let disc = discriminant(c0, c1, c2);
    if disc < 0.0 {
        return ([0.0; 2], 0);
    }
    let q = -0.5 * (c1 + disc.sqrt().copysign(c1));
    if q == 0.0 {
        // c1 = 0 and disc = 0, hence c0 = 0: a double root at zero.
        return ([0.0; 2], 2);
    }
    let (r1, r2) = (q / c2, c0 / q);
    if r1 <= r2 {
        ([r1, r2], 2)
    } else {
        ([r2, r1], 2)
    }
}

/// One Newton step on `c0 + c1 t + c2 t²` from the root `r`, kept only if it lowers
/// `|q|` without moving more than `max_step` (so it cannot jump to the other root).
fn polish_quadratic(c: [f64; 3], r: f64, max_step: f64) -> f64 {
    let q = |t: f64| c[2].mul_add(t, c[1]).mul_add(t, c[0]);
    let (v, dv) = (q(r), (2.0 * c[2]).mul_add(r, c[1]));
    if v == 0.0 || dv == 0.0 {
        return r;
    }
    let rn = r - v / dv;
    if rn.is_finite() && (rn - r).abs() <= max_step && q(rn).abs() < v.abs() {
        rn
    } else {
        r
    }
}

/// The first crossing from `V ≥ 0` to `V < 0` of the cubic `c` (ascending) in
/// `[0, h]` that `accept` takes (it returns `Some` for a crossing that counts).
/// `tol(t)` is the tolerance on `V` at time `t` for the grazing rule: at a piece end
/// where `|V| ≤ tol`, the side is decided by the direction `V` moves in there
/// (rising: outside, falling: inside), so that touching zero from either side is no
/// crossing. `V(0) ≥ 0` is outside as it stands (the caller snaps it).
fn first_crossing_cubic<T>(
    c: [f64; 4],
    h: f64,
    tol: impl Fn(f64) -> f64,
    mut accept: impl FnMut(f64) -> Option<T>,
) -> Option<T> {
    let val = |t: f64| c[3].mul_add(t, c[2]).mul_add(t, c[1]).mul_add(t, c[0]);
    let der = |t: f64| (3.0 * c[3]).mul_add(t, 2.0 * c[2]).mul_add(t, c[1]);
    let curv = |t: f64| (6.0 * c[3]).mul_add(t, 2.0 * c[2]);
    let side = |t: f64, dir: f64| {
        let v = val(t);
        if v.abs() <= tol(t) && dir != 0.0 {
            dir > 0.0
        } else {
            v >= 0.0
        }
    };
    let (crit, nc) = quadratic_roots(c[1], 2.0 * c[2], 3.0 * c[3]);
    let mut pts = [0.0; 4];
    let mut outside = [c[0] >= 0.0; 4];
    let mut m = 1;
    for &s in &crit[..nc] {
        if s > pts[m - 1] && s < h {
            pts[m] = s;
            outside[m] = side(s, curv(s));
            m += 1;
        }
    }
    let dh = der(h);
    pts[m] = h;
    outside[m] = side(h, if dh != 0.0 { dh } else { curv(h) });
    m += 1;
    for i in 0..m - 1 {
        if outside[i] && !outside[i + 1] {
            let r = bracket_root(val, der, pts[i], pts[i + 1], h);
            if let Some(hit) = accept(r) {
                return Some(hit);
            }
        }
    }
    None
}

/// The root of `f` in `[lo, hi]`, `f(lo)` taken as `≥ 0` and `f(hi)` as `< 0`
/// (whatever they evaluate to: the ends may have been snapped), by bisection with
/// Newton steps while they stay inside the bracket and at least halve the previous
/// step; to `4ε·h` in `t`.
fn bracket_root(
    f: impl Fn(f64) -> f64,
    df: impl Fn(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
    h: f64,
) -> f64 {
    let tol = 4.0 * f64::EPSILON * h;
    let mut x = 0.5 * (lo + hi);
    let mut last_step = hi - lo;
    for _ in 0..200 {
        let v = f(x);
        if v == 0.0 {
            return x;
        }
        if v > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        if hi - lo <= tol {
            break;
        }
        let newton = x - v / df(x);
        let step = (newton - x).abs();
        if newton > lo && newton < hi && step < 0.5 * last_step {
            last_step = step;
            x = newton;
            if step <= tol {
                return x;
            }
        } else {
            last_step = hi - lo;
            x = 0.5 * (lo + hi);
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(x: f64, y: f64, tol: f64) -> bool {
        (x - y).abs() <= tol
    }

    // ------------------------------------------------------------------ 2D --------

    /// Horizontal segment on y = 0 from x = 2 to x = 0 (right to left): the body is
    /// below, the outward normal +y.
    const A: [f64; 2] = [2.0, 0.0];
    const B: [f64; 2] = [0.0, 0.0];
    const Z2: [f64; 2] = [0.0, 0.0];

    #[test]
    fn segment_quadratic_matches_direct_evaluation() {
        let (p, vp) = ([0.3, 0.7], [-0.2, 0.5]);
        let (a, va) = ([1.0, -0.4], [0.3, 0.1]);
        let (b, vb) = ([-0.5, 0.2], [-0.7, 0.9]);
        let c = segment_quadratic(p, vp, a, va, b, vb);
        for t in [0.0, 0.3, 1.0, 2.5] {
            let at = |x: [f64; 2], v: [f64; 2]| [x[0] + t * v[0], x[1] + t * v[1]];
            let (pt, at_, bt) = (at(p, vp), at(a, va), at(b, vb));
            let d = [bt[0] - at_[0], bt[1] - at_[1]];
            let e = [pt[0] - at_[0], pt[1] - at_[1]];
            let direct = -(d[0] * e[1] - d[1] * e[0]);
            let poly = c[0] + c[1] * t + c[2] * t * t;
            assert!(close(direct, poly, 1e-13), "t={t}: {direct} vs {poly}");
        }
    }

    #[test]
    fn falling_node_hits_static_segment() {
        // Height 0.3, speed 2: t = 0.15; x = 0.5 is at ξ = (2 − 0.5)/2 = 0.75.
        let hit = node_segment([0.5, 0.3], [0.0, -2.0], A, Z2, B, Z2, 1.0).unwrap();
        assert!(close(hit.t, 0.15, 1e-15), "{hit:?}");
        assert!(close(hit.xi, 0.75, 1e-15), "{hit:?}");
        // The step ends before the node arrives.
        assert_eq!(
            node_segment([0.5, 0.3], [0.0, -2.0], A, Z2, B, Z2, 0.1),
            None
        );
        // The node arrives exactly at the end of the step: a hit at t = h.
        let hit = node_segment([0.5, 0.5], [0.0, -1.0], A, Z2, B, Z2, 0.5).unwrap();
        assert_eq!(hit.t, 0.5);
    }

    #[test]
    fn rising_segment_meets_static_node() {
        let v = [0.0, 4.0];
        let hit = node_segment([1.5, 0.2], Z2, A, v, B, v, 1.0).unwrap();
        assert!(close(hit.t, 0.05, 1e-15), "{hit:?}");
        assert!(close(hit.xi, 0.25, 1e-15), "{hit:?}");
        // A common translation of everything changes nothing.
        let w = [3.0, -7.0];
        let hit2 = node_segment(
            [1.5, 0.2],
            w,
            A,
            [w[0], w[1] + 4.0],
            B,
            [w[0], w[1] + 4.0],
            1.0,
        )
        .unwrap();
        assert!(close(hit2.t, hit.t, 1e-15) && close(hit2.xi, hit.xi, 1e-15));
    }

    /// Segment a = (0, 0) fixed, b = (1, 0) moving down at 1 (turning clockwise about
    /// a; the outward normal points down, −y, so the node is outside below).
    const RA: [f64; 2] = [0.0, 0.0];
    const RB: [f64; 2] = [1.0, 0.0];
    const RVB: [f64; 2] = [0.0, -1.0];

    /// ξ(t) for the turning segment and a node at `p + t vp`.
    fn turning_xi(p: [f64; 2], vp: [f64; 2], t: f64) -> f64 {
        let e = [p[0] + t * vp[0], p[1] + t * vp[1]];
        let d = [1.0, -t];
        (e[0] * d[0] + e[1] * d[1]) / (d[0] * d[0] + d[1] * d[1])
    }

    #[test]
    fn turning_segment_meets_moving_node_quadratic() {
        // Node at (0.5, −0.3) moving right at 0.5: q = 0.3 − 0.5 t − 0.5 t², genuinely
        // quadratic; root of t² + t − 0.6: t = (−1 + √3.4)/2.
        let (p, vp) = ([0.5, -0.3], [0.5, 0.0]);
        let c = segment_quadratic(p, vp, RA, Z2, RB, RVB);
        assert_eq!(c, [0.3, -0.5, -0.5]);
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        let t = (-1.0 + 3.4f64.sqrt()) / 2.0;
        assert!(close(hit.t, t, 1e-15), "{hit:?} vs {t}");
        assert!(close(hit.xi, turning_xi(p, vp, t), 1e-14), "{hit:?}");
    }

    #[test]
    fn two_roots_in_step_first_crossing_taken() {
        // q = 0.16 − t + t²: in at 0.2, out at 0.8; ξ(0.2) = 0.8.
        let (p, vp) = ([1.0, -0.16], [-1.0, 0.0]);
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        assert!(close(hit.t, 0.2, 1e-15), "{hit:?}");
        assert!(close(hit.xi, 0.8, 1e-14), "{hit:?}");
    }

    #[test]
    fn crossing_beyond_end_then_later_crossing_found() {
        // The node starts on the inner side of the line but beside the segment
        // (ξ = −0.5: not penetrating), leaves through the line beyond the end a and
        // comes back in over the segment: q = −0.05 + 1.2 t − 2 t².
        let (p, vp) = ([-0.5, 0.05], [2.0, -0.7]);
        let t1 = (1.2 - 1.04f64.sqrt()) / 4.0;
        let t2 = (1.2 + 1.04f64.sqrt()) / 4.0;
        assert!(turning_xi(p, vp, t1) < -0.1); // the first crossing is beside a
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        assert!(close(hit.t, t2, 1e-15), "{hit:?} vs {t2}");
        assert!(close(hit.xi, turning_xi(p, vp, t2), 1e-14));
        // With the step ending between the two: nothing.
        assert_eq!(node_segment(p, vp, RA, Z2, RB, RVB, 0.5), None);
    }

    #[test]
    fn crossing_beyond_end_point_is_no_hit() {
        // Falling beside the segment, just beyond b (x < 0) and beyond a (x > 2).
        assert_eq!(
            node_segment([-1e-6, 0.3], [0.0, -1.0], A, Z2, B, Z2, 1.0),
            None
        );
        assert_eq!(
            node_segment([2.0 + 1e-6, 0.3], [0.0, -1.0], A, Z2, B, Z2, 1.0),
            None
        );
    }

    #[test]
    fn hitting_end_points_exactly_is_a_hit() {
        let hit = node_segment([2.0, 0.3], [0.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit.xi, 0.0);
        assert!(close(hit.t, 0.3, 1e-15));
        let hit = node_segment([0.0, 0.3], [0.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit.xi, 1.0);
        // Arriving obliquely exactly at b.
        let hit = node_segment([-0.3, 0.3], [1.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert!(
            close(hit.t, 0.3, 1e-15) && close(hit.xi, 1.0, 1e-15),
            "{hit:?}"
        );
    }

    #[test]
    fn nearly_linear_quadratic() {
        // b drifts sideways by 1e-14 per unit time: c2 ≈ 1e-14 times the other
        // coefficients; the root must be the linear one, not garbage from a small
        // leading coefficient.
        let vb = [1e-14, 0.0];
        let c = segment_quadratic([0.5, 0.3], [0.0, -2.0], A, Z2, B, vb);
        assert!(c[2] != 0.0 && c[2].abs() < 1e-13);
        let hit = node_segment([0.5, 0.3], [0.0, -2.0], A, Z2, B, vb, 1.0).unwrap();
        assert!(close(hit.t, 0.15, 1e-13), "{hit:?}");
    }

    #[test]
    fn parallel_and_no_relative_motion_is_no_hit() {
        // Parallel motion above the segment: q constant > 0.
        assert_eq!(
            node_segment([0.5, 0.3], [1.0, 0.0], A, Z2, B, Z2, 1.0),
            None
        );
        // Node and segment moving together: q constant > 0.
        let v = [0.3, -2.0];
        assert_eq!(node_segment([0.5, 0.3], v, A, v, B, v, 1.0), None);
        // Segment sliding along its own line under a node: q constant.
        assert_eq!(
            node_segment([0.5, 0.3], Z2, A, [5.0, 0.0], B, [5.0, 0.0], 1.0),
            None
        );
        // The same while on the segment: constant zero gap, no hit.
        assert_eq!(node_segment([0.5, 0.0], v, A, v, B, v, 1.0), None);
    }

    #[test]
    fn grazing_double_root_is_no_hit() {
        // q = 0.25 − t + t² = (t − 0.5)²: the node touches the turning segment at
        // t = 0.5 (ξ = 0.3) and leaves.
        let (p, vp) = ([0.8, -0.25], [-1.0, 0.2]);
        assert_eq!(segment_quadratic(p, vp, RA, Z2, RB, RVB), [0.25, -1.0, 1.0]);
        assert_eq!(node_segment(p, vp, RA, Z2, RB, RVB, 1.0), None);
        // Closer by 1e-12 (dips 1e-12 deep, far within the tolerance): still a graze.
        let p = [0.8, -0.25 + 1e-12];
        assert_eq!(node_segment(p, vp, RA, Z2, RB, RVB, 1.0), None);
        // Closer by 1e-6: a genuine crossing, just before the touch point.
        let p = [0.8, -0.25 + 1e-6];
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        assert!(close(hit.t, 0.5 - 1e-3, 1e-9), "{hit:?}");
        // Closer by 0.01: q = 0.24 − t + t², in at 0.4 with ξ = 0.4.
        let p = [0.8, -0.24];
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        assert!(
            close(hit.t, 0.4, 1e-15) && close(hit.xi, 0.4, 1e-14),
            "{hit:?}"
        );
    }

    #[test]
    fn on_segment_at_start_and_approaching_is_t0() {
        let hit = node_segment([1.0, 0.0], [0.3, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit, SegmentHit { t: 0.0, xi: 0.5 });
        // Within the tolerance above it (1e-12 < 1e-9·2): also t = 0.
        let hit = node_segment([1.0, 1e-12], [0.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit.t, 0.0);
        // Within the tolerance below it: also t = 0 (not "penetrating").
        let hit = node_segment([1.0, -1e-12], [0.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit.t, 0.0);
        // On an end point.
        let hit = node_segment([2.0, 0.0], [0.0, -1.0], A, Z2, B, Z2, 1.0).unwrap();
        assert_eq!(hit, SegmentHit { t: 0.0, xi: 0.0 });
        // Tangential in first order but the turning segment curves into the node:
        // q = −t² (approaching in second order).
        assert_eq!(
            segment_quadratic([0.5, 0.0], [1.0, -0.5], RA, Z2, RB, RVB),
            [0.0, 0.0, -1.0]
        );
        let hit = node_segment([0.5, 0.0], [1.0, -0.5], RA, Z2, RB, RVB, 1.0).unwrap();
        assert_eq!(hit.t, 0.0);
    }

    #[test]
    fn on_segment_at_start_separating_or_tangential_is_no_hit() {
        // Separating.
        assert_eq!(
            node_segment([1.0, 0.0], [0.0, 1.0], A, Z2, B, Z2, 1.0),
            None
        );
        // Tangential (sliding along the segment).
        assert_eq!(
            node_segment([1.0, 0.0], [0.7, 0.0], A, Z2, B, Z2, 1.0),
            None
        );
        // At rest on it.
        assert_eq!(node_segment([1.0, 0.0], Z2, A, Z2, B, Z2, 1.0), None);
        // On the line beyond the end, approaching: not on the segment.
        assert_eq!(
            node_segment([3.0, 0.0], [0.0, -1.0], A, Z2, B, Z2, 1.0),
            None
        );
    }

    #[test]
    fn on_segment_separating_then_caught_later_in_step() {
        // On the turning segment at t = 0 and moving out (down, at 0.7) but the segment
        // turns down faster: q = 0.5 t − t², back in at t = 0.5 with ξ = 0.7. A crossing
        // from outside later in the step, so it is reported.
        let (p, vp) = ([0.2, 0.0], [1.0, -0.7]);
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        assert!(
            close(hit.t, 0.5, 1e-15) && close(hit.xi, 0.7, 1e-14),
            "{hit:?}"
        );
        // Not within a step of 0.4.
        assert_eq!(node_segment(p, vp, RA, Z2, RB, RVB, 0.4), None);
    }

    #[test]
    fn penetrating_at_start_is_no_hit() {
        // Inside (below the segment) beyond the tolerance, moving in or out.
        assert_eq!(
            node_segment([1.0, -0.01], [0.0, -1.0], A, Z2, B, Z2, 1.0),
            None
        );
        assert_eq!(
            node_segment([1.0, -0.01], [0.0, 1.0], A, Z2, B, Z2, 1.0),
            None
        );
        assert_eq!(
            node_segment([1.0, -1e-8], [0.0, -1.0], A, Z2, B, Z2, 1.0),
            None
        );
    }

    #[test]
    fn collapsing_segment_is_no_hit() {
        // a and b run into each other at (1, 0) at t = 0.3 (not a float), where q
        // changes sign with the segment's orientation; the node sits above.
        let (va, vb) = ([-10.0 / 3.0, 0.0], [10.0 / 3.0, 0.0]);
        let c = segment_quadratic([1.0, 0.5], Z2, A, va, B, vb);
        assert!(c[0] > 0.0 && c[1] < 0.0); // q crosses zero at the collapse
        assert_eq!(node_segment([1.0, 0.5], Z2, A, va, B, vb, 1.0), None);
        // A segment of length zero at the start.
        assert_eq!(
            node_segment([1.0, 0.5], [0.0, -1.0], A, Z2, A, Z2, 1.0),
            None
        );
    }

    #[test]
    fn invalid_step_or_data_is_no_hit() {
        let (p, vp) = ([0.5, 0.3], [0.0, -2.0]);
        for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(node_segment(p, vp, A, Z2, B, Z2, h), None);
        }
        assert_eq!(node_segment([f64::NAN, 0.3], vp, A, Z2, B, Z2, 1.0), None);
        assert_eq!(
            node_segment(p, [0.0, f64::INFINITY], A, Z2, B, Z2, 1.0),
            None
        );
    }

    #[test]
    fn segment_scale_invariance() {
        // Lengths ×1e-6, times ×1e3 (velocities ×1e-9): same t/h and ξ.
        let (p, vp) = ([0.5, -0.3], [0.5, 0.0]);
        let hit = node_segment(p, vp, RA, Z2, RB, RVB, 1.0).unwrap();
        let (l, s) = (1e-6, 1e3);
        let sc = |x: [f64; 2], f: f64| [x[0] * f, x[1] * f];
        let hit2 = node_segment(
            sc(p, l),
            sc(vp, l / s),
            sc(RA, l),
            Z2,
            sc(RB, l),
            sc(RVB, l / s),
            s,
        )
        .unwrap();
        assert!(close(hit2.t / s, hit.t, 1e-14) && close(hit2.xi, hit.xi, 1e-12));
        // The on-segment tolerance scales too: 1e-12·l above the scaled segment.
        let hit3 = node_segment([l, 1e-12 * l], [0.0, -l / s], sc(A, l), Z2, sc(B, l), Z2, s);
        assert_eq!(hit3.map(|h| h.t), Some(0.0));
    }

    #[test]
    fn quadratic_roots_are_cancellation_free() {
        // t² − 1e8 t + 1: roots ≈ 1e-8 and 1e8; the textbook formula loses the small one.
        let (r, n) = quadratic_roots(1.0, -1e8, 1.0);
        assert_eq!(n, 2);
        assert!(close(r[0], 1e-8, 1e-22), "{r:?}");
        assert!(close(r[1], 1e8, 1e-6), "{r:?}");
        // Linear, constant, no real root, double root at zero.
        assert_eq!(quadratic_roots(2.0, -4.0, 0.0), ([0.5, 0.0], 1));
        assert_eq!(quadratic_roots(2.0, 0.0, 0.0).1, 0);
        assert_eq!(quadratic_roots(1.0, 0.0, 1.0).1, 0);
        assert_eq!(quadratic_roots(0.0, 0.0, 3.0), ([0.0, 0.0], 2));
    }

    // ------------------------------------------------------------------ 3D --------

    /// Triangle in z = 0, counter-clockwise seen from above: outward normal +z.
    const TA: [f64; 3] = [0.0, 0.0, 0.0];
    const TB: [f64; 3] = [1.0, 0.0, 0.0];
    const TC: [f64; 3] = [0.0, 1.0, 0.0];
    const Z3: [f64; 3] = [0.0, 0.0, 0.0];

    fn static_tri(p: [f64; 3], vp: [f64; 3], h: f64) -> Option<TriangleHit> {
        node_triangle(p, vp, TA, Z3, TB, Z3, TC, Z3, h)
    }

    fn close3(x: [f64; 3], y: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| close(x[i], y[i], tol))
    }

    /// Direct signed volume from positions (independent of `triangle_cubic`).
    #[allow(clippy::too_many_arguments)]
    fn direct_volume(
        p: [f64; 3],
        vp: [f64; 3],
        a: [f64; 3],
        va: [f64; 3],
        b: [f64; 3],
        vb: [f64; 3],
        c: [f64; 3],
        vc: [f64; 3],
        t: f64,
    ) -> f64 {
        let at = |x: [f64; 3], v: [f64; 3]| [x[0] + t * v[0], x[1] + t * v[1], x[2] + t * v[2]];
        let (pt, at_, bt, ct) = (at(p, vp), at(a, va), at(b, vb), at(c, vc));
        let u = [bt[0] - at_[0], bt[1] - at_[1], bt[2] - at_[2]];
        let w = [ct[0] - at_[0], ct[1] - at_[1], ct[2] - at_[2]];
        let e = [pt[0] - at_[0], pt[1] - at_[1], pt[2] - at_[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        n[0] * e[0] + n[1] * e[1] + n[2] * e[2]
    }

    /// Barycentric coordinates of the projection of `e` on span(u, w) by the 2×2
    /// normal equations (independent of the cross-product formula in the module).
    fn gram_bary(u: [f64; 3], w: [f64; 3], e: [f64; 3]) -> [f64; 3] {
        let (uu, uw, ww) = (dot(u, u), dot(u, w), dot(w, w));
        let (eu, ew) = (dot(e, u), dot(e, w));
        let det = uu * ww - uw * uw;
        let beta = (eu * ww - ew * uw) / det;
        let gamma = (ew * uu - eu * uw) / det;
        [1.0 - beta - gamma, beta, gamma]
    }

    #[allow(clippy::too_many_arguments)]
    fn bary_at(
        p: [f64; 3],
        vp: [f64; 3],
        a: [f64; 3],
        va: [f64; 3],
        b: [f64; 3],
        vb: [f64; 3],
        c: [f64; 3],
        vc: [f64; 3],
        t: f64,
    ) -> [f64; 3] {
        let at = |x: [f64; 3], v: [f64; 3]| [x[0] + t * v[0], x[1] + t * v[1], x[2] + t * v[2]];
        let (pt, at_, bt, ct) = (at(p, vp), at(a, va), at(b, vb), at(c, vc));
        gram_bary(sub(bt, at_), sub(ct, at_), sub(pt, at_))
    }

    #[test]
    fn triangle_cubic_matches_direct_evaluation() {
        let (p, vp) = ([0.3, 0.2, 0.7], [-0.2, 0.5, 0.4]);
        let (a, va) = ([0.1, -0.4, 0.2], [0.3, 0.1, -0.6]);
        let (b, vb) = ([1.2, 0.2, -0.1], [-0.7, 0.9, 0.2]);
        let (c, vc) = ([-0.3, 1.1, 0.4], [0.5, -0.2, 0.8]);
        let k = triangle_cubic(p, vp, a, va, b, vb, c, vc);
        assert!(k[3].abs() > 0.05); // genuinely cubic
        for t in [0.0, 0.3, 1.0, 2.5] {
            let direct = direct_volume(p, vp, a, va, b, vb, c, vc, t);
            let poly = k[0] + k[1] * t + k[2] * t * t + k[3] * t * t * t;
            assert!(close(direct, poly, 1e-13), "t={t}: {direct} vs {poly}");
        }
    }

    #[test]
    fn falling_node_hits_static_triangle() {
        let hit = static_tri([0.2, 0.3, 0.3], [0.0, 0.0, -2.0], 1.0).unwrap();
        assert!(close(hit.t, 0.15, 1e-15), "{hit:?}");
        assert!(close3(hit.bary, [0.5, 0.2, 0.3], 1e-15), "{hit:?}");
        assert_eq!(static_tri([0.2, 0.3, 0.3], [0.0, 0.0, -2.0], 0.1), None);
        // Obliquely.
        let hit = static_tri([0.0, 0.0, 0.4], [0.5, 0.25, -1.0], 1.0).unwrap();
        assert!(close(hit.t, 0.4, 1e-15), "{hit:?}");
        assert!(close3(hit.bary, [0.7, 0.2, 0.1], 1e-15), "{hit:?}");
    }

    #[test]
    fn rising_triangle_meets_static_node() {
        let v = [0.0, 0.0, 4.0];
        let hit = node_triangle([0.6, 0.2, 0.2], Z3, TA, v, TB, v, TC, v, 1.0).unwrap();
        assert!(close(hit.t, 0.05, 1e-15), "{hit:?}");
        assert!(close3(hit.bary, [0.2, 0.6, 0.2], 1e-15), "{hit:?}");
    }

    /// c = (0, 1, 0) moving down at 1: the triangle turns about its edge a b (the x
    /// axis); N = (0, t, 1), V = e_z + t e_y.
    const TVC: [f64; 3] = [0.0, 0.0, -1.0];

    fn tilting(p: [f64; 3], vp: [f64; 3], h: f64) -> Option<TriangleHit> {
        node_triangle(p, vp, TA, Z3, TB, Z3, TC, TVC, h)
    }

    #[test]
    fn tilting_triangle_quadratic_volume() {
        // V = 0.24 − t + t²: in at 0.4, where the projection is at β = 0.1, γ = 0.6.
        let (p, vp) = ([0.1, 0.2, 0.24], [0.0, 1.0, -1.2]);
        let k = triangle_cubic(p, vp, TA, Z3, TB, Z3, TC, TVC);
        assert!(close3([k[0], k[1], k[2]], [0.24, -1.0, 1.0], 1e-15) && k[3] == 0.0);
        let hit = tilting(p, vp, 1.0).unwrap();
        assert!(close(hit.t, 0.4, 1e-14), "{hit:?}");
        assert!(close3(hit.bary, [0.3, 0.1, 0.6], 1e-13), "{hit:?}");
    }

    #[test]
    fn genuinely_cubic_volume_against_bisection() {
        // All vertices and the node move in different directions.
        let (p, vp) = ([0.3, 0.3, 0.4], [0.2, 0.1, -0.9]);
        let (a, va) = ([0.0, 0.0, 0.0], [0.1, 0.0, 0.2]);
        let (b, vb) = ([1.0, 0.0, 0.0], [0.0, 0.6, -0.6]);
        let (c, vc) = ([0.0, 1.0, 0.0], [0.4, -0.3, 0.9]);
        let h = 1.0;
        let k = triangle_cubic(p, vp, a, va, b, vb, c, vc);
        let scale = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(k[3].abs() > 0.05 * scale, "{k:?}"); // the cubic term matters
                                                     // The first sign change of the direct volume on a grid, then bisection.
        let v = |t: f64| direct_volume(p, vp, a, va, b, vb, c, vc, t);
        assert!(v(0.0) > 0.0);
        let n = 1000;
        let k0 = (0..n)
            .find(|&i| v(h * (i + 1) as f64 / n as f64) < 0.0)
            .unwrap();
        let (mut lo, mut hi) = (h * k0 as f64 / n as f64, h * (k0 + 1) as f64 / n as f64);
        for _ in 0..100 {
            let m = 0.5 * (lo + hi);
            if v(m) >= 0.0 {
                lo = m
            } else {
                hi = m
            }
        }
        let t = 0.5 * (lo + hi);
        let l = bary_at(p, vp, a, va, b, vb, c, vc, t);
        assert!(l.iter().all(|x| (0.05..0.95).contains(x)), "{l:?}");
        let hit = node_triangle(p, vp, a, va, b, vb, c, vc, h).unwrap();
        assert!(close(hit.t, t, 1e-13), "{hit:?} vs {t}");
        assert!(close3(hit.bary, l, 1e-12), "{hit:?} vs {l:?}");
    }

    #[test]
    fn triangle_parallel_and_no_relative_motion_is_no_hit() {
        assert_eq!(static_tri([0.2, 0.3, 0.3], [1.0, -0.5, 0.0], 1.0), None);
        let v = [0.3, -2.0, -1.0];
        assert_eq!(
            node_triangle([0.2, 0.3, 0.3], v, TA, v, TB, v, TC, v, 1.0),
            None
        );
        // On the triangle and moving with it.
        assert_eq!(
            node_triangle([0.2, 0.3, 0.0], v, TA, v, TB, v, TC, v, 1.0),
            None
        );
    }

    #[test]
    fn triangle_grazing_double_root_is_no_hit() {
        // V = 0.25 − t + t² = (t − 0.5)², touching over the triangle (β = 0.1, γ = 0.7).
        let vp = [0.0, 1.0, -1.2];
        assert_eq!(tilting([0.1, 0.2, 0.25], vp, 1.0), None);
        // Within the tolerance.
        assert_eq!(tilting([0.1, 0.2, 0.25 - 1e-12], vp, 1.0), None);
        // Beyond it: a genuine crossing just before the touch point.
        let hit = tilting([0.1, 0.2, 0.25 - 1e-6], vp, 1.0).unwrap();
        assert!(close(hit.t, 0.5 - 1e-3, 1e-9), "{hit:?}");
    }

    #[test]
    fn on_triangle_at_start() {
        // Approaching: t = 0.
        let hit = static_tri([0.2, 0.3, 0.0], [0.1, 0.0, -1.0], 1.0).unwrap();
        assert_eq!(hit.t, 0.0);
        assert!(close3(hit.bary, [0.5, 0.2, 0.3], 1e-15));
        // Within the tolerance above and below: t = 0.
        assert_eq!(
            static_tri([0.2, 0.3, 1e-12], [0.0, 0.0, -1.0], 1.0).map(|h| h.t),
            Some(0.0)
        );
        assert_eq!(
            static_tri([0.2, 0.3, -1e-12], [0.0, 0.0, -1.0], 1.0).map(|h| h.t),
            Some(0.0)
        );
        // Tangential in first order on the tilting triangle (V = e_z + t e_y): with
        // e = (0.2, 0.3 ∓ t, −0.3 t), V = ∓t²: curving in (t = 0) or away (None).
        let hit = tilting([0.2, 0.3, 0.0], [0.0, -1.0, -0.3], 1.0).unwrap();
        assert_eq!(hit.t, 0.0);
        assert_eq!(tilting([0.2, 0.3, 0.0], [0.0, 1.0, -0.3], 1.0), None);
    }

    #[test]
    fn on_triangle_separating_or_tangential_is_no_hit() {
        assert_eq!(static_tri([0.2, 0.3, 0.0], [0.0, 0.0, 1.0], 1.0), None);
        assert_eq!(static_tri([0.2, 0.3, 0.0], [0.5, 0.2, 0.0], 1.0), None);
        assert_eq!(static_tri([0.2, 0.3, 0.0], Z3, 1.0), None);
        // In the plane beyond an edge, approaching: not on the triangle.
        assert_eq!(static_tri([0.8, 0.8, 0.0], [0.0, 0.0, -1.0], 1.0), None);
    }

    #[test]
    fn triangle_penetrating_at_start_is_no_hit() {
        assert_eq!(static_tri([0.2, 0.3, -0.01], [0.0, 0.0, -1.0], 1.0), None);
        assert_eq!(static_tri([0.2, 0.3, -0.01], [0.0, 0.0, 1.0], 1.0), None);
    }

    #[test]
    fn triangle_edges_and_vertices() {
        // Beyond the edge b c (x + y > 1) and beyond a b (y < 0): no hit.
        assert_eq!(
            static_tri([0.5 + 1e-6, 0.5, 0.3], [0.0, 0.0, -1.0], 1.0),
            None
        );
        assert_eq!(static_tri([0.5, -1e-6, 0.3], [0.0, 0.0, -1.0], 1.0), None);
        // Exactly on the edge b c and on the vertex b: hits.
        let hit = static_tri([0.5, 0.5, 0.3], [0.0, 0.0, -1.0], 1.0).unwrap();
        assert!(close3(hit.bary, [0.0, 0.5, 0.5], 1e-15), "{hit:?}");
        assert_eq!(hit.bary.iter().sum::<f64>(), 1.0);
        let hit = static_tri([1.0, 0.0, 0.3], [0.0, 0.0, -1.0], 1.0).unwrap();
        assert!(close3(hit.bary, [0.0, 1.0, 0.0], 1e-15), "{hit:?}");
        let hit = static_tri([0.0, 0.0, 0.3], [0.0, 0.0, -1.0], 1.0).unwrap();
        assert!(close3(hit.bary, [1.0, 0.0, 0.0], 1e-15), "{hit:?}");
    }

    #[test]
    fn collapsing_triangle_is_no_hit() {
        // c runs onto the edge a b at t = 0.3, where V changes sign with the
        // orientation; the node sits above the triangle.
        let vc = [0.0, -10.0 / 3.0, 0.0];
        let k = triangle_cubic([0.2, 0.1, 0.5], Z3, TA, Z3, TB, Z3, TC, vc);
        assert!(k[0] > 0.0 && k[1] < 0.0);
        assert_eq!(
            node_triangle([0.2, 0.1, 0.5], Z3, TA, Z3, TB, Z3, TC, vc, 1.0),
            None
        );
        // Collinear vertices at the start.
        let c = [2.0, 0.0, 0.0];
        assert_eq!(
            node_triangle(
                [0.2, 0.1, 0.5],
                [0.0, 0.0, -1.0],
                TA,
                Z3,
                TB,
                Z3,
                c,
                Z3,
                1.0
            ),
            None
        );
    }

    #[test]
    fn triangle_shrinking_to_a_point_is_no_hit() {
        // Everything (node included) contracts homothetically onto the centroid g,
        // reaching it at t = 0.4: V = (1 − t/0.4)³·V(0) changes sign there (a triple
        // root) while the barycentric coordinates stay (0.5, 0.2, 0.3); the crossing is
        // at the collapse, so it is none.
        let g = [1.0 / 3.0, 1.0 / 3.0, 0.0];
        let v = |x: [f64; 3]| sub(x, g).map(|c| -c / 0.4);
        let p = [0.2, 0.3, 0.5];
        let k = triangle_cubic(p, v(p), TA, v(TA), TB, v(TB), TC, v(TC));
        assert!(k[0] > 0.0 && k[3] < 0.0);
        let hit = node_triangle(p, v(p), TA, v(TA), TB, v(TB), TC, v(TC), 1.0);
        assert_eq!(hit, None);
        // Stopping short of the collapse, with the node pushed down onto the plane
        // at t = 0.2 instead: a regular hit (the check does not reject a shrinking
        // triangle as such).
        let vp = [v(p)[0], v(p)[1], -2.5];
        let hit = node_triangle(p, vp, TA, v(TA), TB, v(TB), TC, v(TC), 0.3).unwrap();
        assert!(close(hit.t, 0.2, 1e-14), "{hit:?}");
        assert!(close3(hit.bary, [0.5, 0.2, 0.3], 1e-13), "{hit:?}");
    }

    #[test]
    fn triangle_invalid_step_or_data_is_no_hit() {
        for h in [0.0, -1.0, f64::NAN] {
            assert_eq!(static_tri([0.2, 0.3, 0.3], [0.0, 0.0, -2.0], h), None);
        }
        assert_eq!(
            static_tri([0.2, f64::NAN, 0.3], [0.0, 0.0, -2.0], 1.0),
            None
        );
    }

    fn crossing(c: [f64; 4], after: f64) -> Option<f64> {
        first_crossing_cubic(c, 1.0, |_| 1e-12, |t| (t > after).then_some(t))
    }

    #[test]
    fn cubic_crossings_multiple_roots_and_degenerate_degrees() {
        // Triple root, entering: −(t − 0.5)³.
        let t = crossing([0.125, -0.75, 1.5, -1.0], -1.0).unwrap();
        assert!(close(t, 0.5, 1e-5), "{t}");
        // Triple root, leaving: (t − 0.5)³ starts inside: no crossing.
        assert_eq!(crossing([-0.125, 0.75, -1.5, 1.0], -1.0), None);
        // Double root touching from outside: (t − 0.5)²(2 − t).
        assert_eq!(crossing([0.5, -2.25, 3.0, -1.0], -1.0), None);
        // Double root touching from inside: −(t − 0.5)²(2 − t), then nothing.
        assert_eq!(crossing([-0.5, 2.25, -3.0, 1.0], -1.0), None);
        // Three simple roots −(t − 0.3)(t − 0.6)(t − 0.9): the first, or, if that one
        // is refused, the next entering one (0.9, not 0.6 which leaves).
        let c = [0.162, -0.99, 1.8, -1.0];
        assert!(close(crossing(c, -1.0).unwrap(), 0.3, 1e-14));
        assert!(close(crossing(c, 0.5).unwrap(), 0.9, 1e-14));
        assert_eq!(crossing(c, 0.95), None);
        // Nearly quadratic (leading coefficient 1e-18): 0.24 − t + t², in at 0.4.
        assert!(close(
            crossing([0.24, -1.0, 1.0, 1e-18], -1.0).unwrap(),
            0.4,
            1e-14
        ));
        // Quadratic, linear, root at the end of the interval, constants, zero.
        assert!(close(
            crossing([0.24, -1.0, 1.0, 0.0], -1.0).unwrap(),
            0.4,
            1e-14
        ));
        assert!(close(
            crossing([0.3, -1.0, 0.0, 0.0], -1.0).unwrap(),
            0.3,
            1e-15
        ));
        assert!(close(
            crossing([1.0, -1.0, 0.0, 0.0], -1.0).unwrap(),
            1.0,
            1e-15
        ));
        assert_eq!(crossing([1.0, 0.0, 0.0, 0.0], -1.0), None);
        assert_eq!(crossing([-1.0, 0.0, 0.0, 0.0], -1.0), None);
        assert_eq!(crossing([0.0; 4], -1.0), None);
        // A local minimum just below zero (within the tolerance): a graze.
        assert_eq!(crossing([0.25 - 1e-13, -1.0, 1.0, 0.0], -1.0), None);
        // Rising to just below zero at the end of the interval: no crossing either.
        assert_eq!(crossing([-1e-13, -0.9e-12, 0.5e-12, 0.0], -1.0), None);
    }

    #[test]
    fn bracket_root_safeguards_newton() {
        // −atan(10(x − 0.7)): Newton from the midpoint overshoots out of [0, 1] and
        // then diverges; the safeguard must bisect instead.
        let f = |x: f64| -(10.0 * (x - 0.7)).atan();
        let df = |x: f64| -10.0 / (1.0 + (10.0 * (x - 0.7)).powi(2));
        let r = bracket_root(f, df, 0.0, 1.0, 1.0);
        assert!(close(r, 0.7, 1e-14), "{r}");
        // A vanishing derivative at the first iterate (Newton step infinite).
        let r = bracket_root(
            |x| 0.3 - x,
            |x| if x == 0.5 { 0.0 } else { -1.0 },
            0.0,
            1.0,
            1.0,
        );
        assert!(close(r, 0.3, 1e-15), "{r}");
    }

    // ------------------------------------------------------ randomised --------

    /// xorshift64*: a small deterministic generator.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        /// Uniform in [0, 1).
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.unit()
        }
        fn v2(&mut self, s: f64) -> [f64; 2] {
            [self.range(-s, s), self.range(-s, s)]
        }
        fn v3(&mut self, s: f64) -> [f64; 3] {
            [self.range(-s, s), self.range(-s, s), self.range(-s, s)]
        }
    }

    const SAMPLES: usize = 20_000;
    const CASES: usize = 3_000;

    /// What the brute-force sampler expects.
    #[derive(Debug)]
    enum Expect {
        /// A crossing in `[lo, hi]` with the projection parameter(s) there.
        Hit {
            lo: f64,
            hi: f64,
            at: [f64; 3],
            spread: f64,
        },
        Miss,
        /// Too close to a tolerance for the sampler to tell.
        Skip,
    }

    /// Near 0 or 1 within `m`.
    fn near_end(x: f64, m: f64) -> bool {
        x.abs() < m || (x - 1.0).abs() < m
    }

    /// The sampler's scan over `g(k)` (k = 0..=SAMPLES) for the first interval going
    /// from `≥ 0` to `< 0` with `proj(t)` inside; `proj` returns the coordinates and
    /// the facet's size (for collapse).
    fn scan(
        h: f64,
        g: impl Fn(f64) -> f64,
        proj: impl Fn(f64) -> ([f64; 3], f64),
        size0: f64,
        dims: usize,
    ) -> Expect {
        let ts = |k: usize| h * k as f64 / SAMPLES as f64;
        let inside = |l: &[f64; 3]| l[..dims].iter().all(|x| (0.0..=1.0).contains(x));
        let (l0, _) = proj(0.0);
        let g0 = g(0.0);
        if g0 < 0.0 && inside(&l0) {
            return if l0[..dims].iter().any(|&x| near_end(x, 1e-7)) {
                Expect::Skip
            } else {
                Expect::Miss
            };
        }
        let (mut gpp, mut gp) = (f64::NAN, g0);
        for k in 1..=SAMPLES {
            let gk = g(ts(k));
            // A local minimum of |g| without a sign change that is small against the
            // curvature: two crossings could hide inside one sample interval.
            if k >= 2
                && (gpp >= 0.0) == (gp >= 0.0)
                && (gp >= 0.0) == (gk >= 0.0)
                && gp.abs() <= gpp.abs()
                && gp.abs() <= gk.abs()
                && gp.abs() <= 2.0 * (gk - 2.0 * gp + gpp).abs()
            {
                return Expect::Skip;
            }
            if gp >= 0.0 && gk < 0.0 {
                if k == 1 || k == SAMPLES {
                    return Expect::Skip;
                }
                let (la, sa) = proj(ts(k - 1));
                let (lb, sb) = proj(ts(k));
                if sa.min(sb) < 1e-4 * size0 {
                    return Expect::Skip;
                }
                let spread = (0..dims).fold(0.0f64, |m, i| m.max((lb[i] - la[i]).abs()));
                let margin = spread + 1e-7;
                if (0..dims).any(|i| near_end(la[i], margin) || near_end(lb[i], margin)) {
                    return Expect::Skip;
                }
                if inside(&la) && inside(&lb) {
                    return Expect::Hit {
                        lo: ts(k - 1),
                        hi: ts(k),
                        at: la,
                        spread,
                    };
                }
            }
            (gpp, gp) = (gp, gk);
        }
        Expect::Miss
    }

    /// Tallies hits, misses and skips; checks a found `(t, coords)` against `e`.
    fn check(
        e: &Expect,
        got: Option<(f64, [f64; 3])>,
        dims: usize,
        tally: &mut [usize; 3],
        what: &str,
    ) {
        match e {
            Expect::Hit { lo, hi, at, spread } => {
                tally[0] += 1;
                let (t, l) = got.unwrap_or_else(|| panic!("missed a hit {e:?}: {what}"));
                let slack = 1e-9 * hi;
                assert!(
                    t >= lo - slack && t <= hi + slack,
                    "t = {t} outside {e:?}: {what}"
                );
                for i in 0..dims {
                    assert!(
                        (l[i] - at[i]).abs() <= spread + 1e-9,
                        "coords {l:?} vs {e:?}: {what}"
                    );
                }
            }
            Expect::Miss => {
                tally[1] += 1;
                assert!(got.is_none(), "spurious hit {got:?}: {what}");
            }
            Expect::Skip => tally[2] += 1,
        }
    }

    #[test]
    fn random_segments_against_sampler() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut tally = [0usize; 3];
        for case in 0..CASES {
            let ls = 10f64.powf(rng.range(-3.0, 3.0));
            let ts = 10f64.powf(rng.range(-2.0, 2.0));
            let h = ts * rng.range(0.5, 2.0);
            let vs = ls / ts;
            let a = rng.v2(ls);
            let mut b = rng.v2(ls);
            while norm2(sub(b, a)) < 0.05 * ls {
                b = rng.v2(ls);
            }
            let (va, vb) = match case % 4 {
                0 => (Z2, Z2),
                1 => {
                    let v = rng.v2(vs);
                    (v, v)
                }
                _ => (rng.v2(vs), rng.v2(vs)),
            };
            let speed = vs * rng.range(0.1, 2.0);
            let mut vp = rng.v2(speed);
            let p = if rng.unit() < 0.7 {
                // Aim the node at a point of the segment's line at a random time, most
                // often moving in there.
                let (t, xi) = (rng.range(0.0, h), rng.range(-0.3, 1.3));
                let at = axpy(a, t, va);
                let d = sub(axpy(b, t, vb), at);
                let target = axpy(at, xi, d);
                let vt = axpy(va, xi, sub(vb, va));
                let r = sub(vp, vt);
                if r[0] * d[1] - r[1] * d[0] > 0.0 && rng.unit() < 0.75 {
                    vp = sub(vt, r);
                }
                axpy(target, -t, vp)
            } else {
                rng.v2(2.0 * ls)
            };
            let pos = |x: [f64; 2], v: [f64; 2], t: f64| [x[0] + t * v[0], x[1] + t * v[1]];
            let g = |t: f64| {
                let (pa, pb, pp) = (pos(a, va, t), pos(b, vb, t), pos(p, vp, t));
                let (d, e) = (
                    [pb[0] - pa[0], pb[1] - pa[1]],
                    [pp[0] - pa[0], pp[1] - pa[1]],
                );
                e[0] * d[1] - e[1] * d[0]
            };
            let proj = |t: f64| {
                let (pa, pb, pp) = (pos(a, va, t), pos(b, vb, t), pos(p, vp, t));
                let (d, e) = (
                    [pb[0] - pa[0], pb[1] - pa[1]],
                    [pp[0] - pa[0], pp[1] - pa[1]],
                );
                ([dot(e, d) / dot(d, d), 0.0, 0.0], norm2(d))
            };
            let len0 = norm2(sub(b, a));
            let scale = len0.max(h * norm2(sub(vp, va))).max(h * norm2(sub(vb, va)));
            let expect = if (g(0.0) / len0).abs() < 1e-7 * scale {
                Expect::Skip
            } else {
                scan(h, g, proj, len0, 1)
            };
            let got = node_segment(p, vp, a, va, b, vb, h).map(|x| (x.t, [x.xi, 0.0, 0.0]));
            let what =
                format!("case {case}: p {p:?} vp {vp:?} a {a:?} va {va:?} b {b:?} vb {vb:?} h {h}");
            check(&expect, got, 1, &mut tally, &what);
        }
        eprintln!("hits, misses, skips: {tally:?}");
        assert!(tally[0] > CASES / 5 && tally[1] > CASES / 5, "{tally:?}");
        assert!(tally[2] < CASES / 10, "{tally:?}");
    }

    #[test]
    fn random_triangles_against_sampler() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut tally = [0usize; 3];
        for case in 0..CASES {
            let ls = 10f64.powf(rng.range(-3.0, 3.0));
            let ts = 10f64.powf(rng.range(-2.0, 2.0));
            let h = ts * rng.range(0.5, 2.0);
            let vs = ls / ts;
            let a = rng.v3(ls);
            let (mut b, mut c) = (rng.v3(ls), rng.v3(ls));
            while crate::geometry::norm(cross(sub(b, a), sub(c, a))) < 0.05 * ls * ls {
                (b, c) = (rng.v3(ls), rng.v3(ls));
            }
            let (va, vb, vc) = match case % 4 {
                0 => (Z3, Z3, Z3),
                1 => {
                    let v = rng.v3(vs);
                    (v, v, v)
                }
                _ => (rng.v3(vs), rng.v3(vs), rng.v3(vs)),
            };
            let speed = vs * rng.range(0.1, 2.0);
            let mut vp = rng.v3(speed);
            let p = if rng.unit() < 0.7 {
                // Aim the node at a point of the triangle's plane at a random time, most
                // often moving in there.
                let t = rng.range(0.0, h);
                let beta = rng.range(-0.2, 1.1);
                let gamma = rng.range(-0.2, 1.2 - beta);
                let at = axpy(a, t, va);
                let u = sub(axpy(b, t, vb), at);
                let w = sub(axpy(c, t, vc), at);
                let target = axpy(axpy(at, beta, u), gamma, w);
                let vt = axpy(axpy(va, beta, sub(vb, va)), gamma, sub(vc, va));
                let r = sub(vp, vt);
                if dot(cross(u, w), r) > 0.0 && rng.unit() < 0.75 {
                    vp = sub(vt, r);
                }
                axpy(target, -t, vp)
            } else {
                rng.v3(2.0 * ls)
            };
            let g = |t: f64| direct_volume(p, vp, a, va, b, vb, c, vc, t);
            let pos = |x: [f64; 3], v: [f64; 3], t: f64| axpy(x, t, v);
            let proj = |t: f64| {
                let (pa, pb, pc, pp) = (pos(a, va, t), pos(b, vb, t), pos(c, vc, t), pos(p, vp, t));
                let (u, w) = (sub(pb, pa), sub(pc, pa));
                (
                    gram_bary(u, w, sub(pp, pa)),
                    crate::geometry::norm(cross(u, w)).sqrt(),
                )
            };
            let area0 = crate::geometry::norm(cross(sub(b, a), sub(c, a)));
            let edge0 = crate::geometry::norm(sub(b, a))
                .max(crate::geometry::norm(sub(c, a)))
                .max(crate::geometry::norm(sub(c, b)));
            let scale = edge0
                .max(h * crate::geometry::norm(sub(vp, va)))
                .max(h * crate::geometry::norm(sub(vb, va)))
                .max(h * crate::geometry::norm(sub(vc, va)));
            let expect = if (g(0.0) / area0).abs() < 1e-7 * scale {
                Expect::Skip
            } else {
                scan(h, g, proj, area0.sqrt(), 3)
            };
            let got = node_triangle(p, vp, a, va, b, vb, c, vc, h).map(|x| (x.t, x.bary));
            let what = format!(
                "case {case}: p {p:?} vp {vp:?} a {a:?} va {va:?} b {b:?} vb {vb:?} c {c:?} vc {vc:?} h {h}"
            );
            check(&expect, got, 3, &mut tally, &what);
        }
        eprintln!("hits, misses, skips: {tally:?}");
        assert!(tally[0] > CASES / 5 && tally[1] > CASES / 5, "{tally:?}");
        assert!(tally[2] < CASES / 10, "{tally:?}");
    }
}
