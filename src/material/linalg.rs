//! Tiny dense solves for material-point and driver systems, on fixed-size arrays so
//! the Gauss-point loop allocates nothing: a system of dimension `n ≤ MAX_DIM` lives
//! in the leading `n x n` block of a [`Small`] matrix.

/// Largest system these routines handle (the Rankine-Hill return in a solid: three
/// principal stresses and up to four multipliers).
pub const MAX_DIM: usize = 7;

/// A dense matrix whose leading `n x n` block is used.
pub type Small = [[f64; MAX_DIM]; MAX_DIM];

/// Solves `a x = b` (leading `n x n` block) by Gaussian elimination with partial
/// pivoting, overwriting `b` with `x`; `false` if the matrix is singular or not finite.
/// Each size is its own instance with loops of known length (the same operations in
/// the same order, so the same bits as a loop over `n`).
pub fn solve_in_place(a: Small, b: &mut [f64; MAX_DIM], n: usize) -> bool {
    match n {
        1 => solve_n::<1>(a, b),
        2 => solve_n::<2>(a, b),
        3 => solve_n::<3>(a, b),
        4 => solve_n::<4>(a, b),
        5 => solve_n::<5>(a, b),
        6 => solve_n::<6>(a, b),
        7 => solve_n::<7>(a, b),
        _ => n == 0,
    }
}

/// [`solve_in_place`] for `N` unknowns.
#[inline]
fn solve_n<const N: usize>(mut a: Small, b: &mut [f64; MAX_DIM]) -> bool {
    let n = N;
    for c in 0..n {
        let mut p = c;
        for i in c + 1..n {
            if a[i][c].abs() > a[p][c].abs() {
                p = i;
            }
        }
        if a[p][c] == 0.0 || !a[p][c].is_finite() {
            return false;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    for c in (0..n).rev() {
        let mut s = b[c];
        for k in c + 1..n {
            s -= a[c][k] * b[k];
        }
        b[c] = s / a[c][c];
    }
    true
}

/// Inverse of the leading `n x n` block, `None` if singular.
pub fn inverse(a: &Small, n: usize) -> Option<Small> {
    let mut inv = [[0.0; MAX_DIM]; MAX_DIM];
    for j in 0..n {
        let mut e = [0.0; MAX_DIM];
        e[j] = 1.0;
        if !solve_in_place(*a, &mut e, n) {
            return None;
        }
        for i in 0..n {
            inv[i][j] = e[i];
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_inverts_a_pivoting_system() {
        // A system that needs a row swap (zero leading pivot).
        let mut a = [[0.0; MAX_DIM]; MAX_DIM];
        a[0][..3].copy_from_slice(&[0.0, 2.0, 1.0]);
        a[1][..3].copy_from_slice(&[1.0, 1.0, 0.0]);
        a[2][..3].copy_from_slice(&[3.0, 0.0, 4.0]);
        let x_true = [1.0, -2.0, 0.5];
        let mut b = [0.0; MAX_DIM];
        for i in 0..3 {
            b[i] = (0..3).map(|k| a[i][k] * x_true[k]).sum();
        }
        assert!(solve_in_place(a, &mut b, 3));
        for i in 0..3 {
            assert!((b[i] - x_true[i]).abs() < 1e-14);
        }
        let inv = inverse(&a, 3).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let p: f64 = (0..3).map(|k| a[i][k] * inv[k][j]).sum();
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        let mut singular = a;
        singular[2] = singular[0];
        assert!(inverse(&singular, 3).is_none());
    }
}
