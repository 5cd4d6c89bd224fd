//! Backward Euler (Rothe) dynamics in displacement form, eq. (9) of the paper:
//!
//! `M (u_s − 2u_{s−1} + u_{s−2})/h² + C (u_s − u_{s−1})/h + f_int(u_s) = f_ext(t_s)`,
//! `C = (zeta + a_m) M + a_k K`, with `v_s = (u_s − u_{s−1})/h` carried as state so
//! `u_{−1} = u_0 − h v_0` holds for an initial velocity `v_0`.
//!
//! Every step goes through the equilibrium loop of [`crate::nonlinear`] with the
//! effective matrix `K_eff = (1/h² + (zeta+a_m)/h) M + (1 + a_k/h) K` (linear
//! elasticity; with history materials `a_k/h K + K_t`), factorised once while it does
//! not change. For linear elasticity and linear viscoelasticity the step is affine:
//! the residual at the start is predicted from the carried forces, one solve is
//! exact, and one evaluation (a fused `K Δu, M v` pass, or one Gauss-point pass)
//! confirms it and gives the new state. See `theory/scheme.md` and
//! `theory/energy.md`.

use super::implicit::{Dynamic, Implicit};

/// The implicit dynamic integrator: backward Euler, or the trapezoidal rule and
/// generalized-α when `analysis.scheme` says so (the same matrices, loop, contact
/// and ledger; only the step's weights differ).
pub type BackwardEuler<'m> = Implicit<'m, Dynamic>;
