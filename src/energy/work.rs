//! The work terms of a step that every scheme shares, from the step's vectors.
//!
//! For a step from `u_n` to `u_{n+1} = u_n + Δu` (all dofs), by the trapezoidal rule
//! of the paper (Section 4):
//! - internal work `½ Δu·(f_int,n + f_int,n+1)` (`E_int`),
//! - external work `½ Δu·(f_ext,n + f_ext,n+1)`, support reactions included in
//!   `f_ext` on the constrained dofs (`W_ext`),
//! - the load jump `½ Δu·(f_ext,n+1 − f_ext,n)`, which backward Euler's identity moves
//!   into the numerical loss (`theory/energy.md`),
//! - the damping work `Δu·f_damp,n+1` with `f_damp = C v_{n+1}` (`D_mass`).

/// A step's vectors, all over every dof.
#[derive(Clone, Copy, Debug)]
pub struct StepVectors<'a> {
    /// Displacement increment `u_{n+1} − u_n`.
    pub du: &'a [f64],
    /// Internal forces at the start of the step.
    pub f_int_n: &'a [f64],
    /// Internal forces at the end of the step.
    pub f_int_np1: &'a [f64],
    /// External forces (reactions included) at the start of the step.
    pub f_ext_n: &'a [f64],
    /// External forces (reactions included) at the end of the step.
    pub f_ext_np1: &'a [f64],
    /// Damping force `C v_{n+1}` at the end of the step, when there is damping.
    pub f_damp_np1: Option<&'a [f64]>,
}

/// The shared work terms of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepWork {
    /// `½ Δu·(f_int,n + f_int,n+1)`.
    pub internal: f64,
    /// `½ Δu·(f_ext,n + f_ext,n+1)`.
    pub external: f64,
    /// `½ Δu·(f_ext,n+1 − f_ext,n)`.
    pub load_jump: f64,
    /// `Δu·f_damp,n+1`.
    pub damping: f64,
}

/// The work terms' integrands at one dof, `[Δu(f_int,n + f_int,n+1),
/// Δu(f_ext,n + f_ext,n+1), Δu(f_ext,n+1 − f_ext,n), Δu f_damp,n+1]`: summed over the
/// dofs by [`step_work`], or inside a scheme's own pass over the step's vectors
/// (which then forms the terms with [`StepWork::from_sums`]), so there is one
/// definition of the work terms whichever pass sums them.
#[inline(always)]
pub fn work_integrands(
    du: f64,
    f_int_n: f64,
    f_int_np1: f64,
    f_ext_n: f64,
    f_ext_np1: f64,
    f_damp_np1: f64,
) -> [f64; 4] {
    [
        du * (f_int_n + f_int_np1),
        du * (f_ext_n + f_ext_np1),
        du * (f_ext_np1 - f_ext_n),
        du * f_damp_np1,
    ]
}

impl StepWork {
    /// The terms from the sums of [`work_integrands`] over the dofs.
    pub fn from_sums(sums: [f64; 4]) -> StepWork {
        StepWork {
            internal: 0.5 * sums[0],
            external: 0.5 * sums[1],
            load_jump: 0.5 * sums[2],
            damping: sums[3],
        }
    }
}

/// Forms the work terms of a step (one parallel pass over the dofs).
pub fn step_work(v: &StepVectors) -> StepWork {
    let n = v.du.len();
    debug_assert!([v.f_int_n, v.f_int_np1, v.f_ext_n, v.f_ext_np1]
        .iter()
        .all(|x| x.len() == n));
    // In halves of a fixed tree (`crate::halves`): the same sums in every run.
    let leaf = |r: std::ops::Range<usize>| {
        let mut acc = [0.0f64; 4];
        for i in r {
            let w = work_integrands(
                v.du[i],
                v.f_int_n[i],
                v.f_int_np1[i],
                v.f_ext_n[i],
                v.f_ext_np1[i],
                v.f_damp_np1.map_or(0.0, |c| c[i]),
            );
            for k in 0..4 {
                acc[k] += w[k];
            }
        }
        acc
    };
    let sums = crate::halves::in_ranges(n, crate::halves::VECTOR_LEAF, &leaf, &crate::halves::add);
    StepWork::from_sums(sums)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoidal_terms_of_a_two_dof_step() {
        let du = [1.0, -2.0];
        let w = step_work(&StepVectors {
            du: &du,
            f_int_n: &[1.0, 1.0],
            f_int_np1: &[3.0, 0.0],
            f_ext_n: &[2.0, 0.0],
            f_ext_np1: &[4.0, 1.0],
            f_damp_np1: Some(&[0.5, 0.25]),
        });
        assert_eq!(w.internal, 0.5 * (4.0 - 2.0));
        assert_eq!(w.external, 0.5 * (6.0 - 2.0));
        assert_eq!(w.load_jump, 0.5 * (2.0 - 2.0));
        assert_eq!(w.damping, 0.5 - 0.5);
    }
}
