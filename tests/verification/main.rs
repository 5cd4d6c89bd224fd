//! Verification: analytic solutions, observed orders, conservation laws and the paper's benchmarks, plane and solid, implicit and explicit, with and without contact.
//!
//! One test binary, one module per topic (see ARCHITECTURE.md, "Tests by kind").

#[path = "../common/mod.rs"]
mod common;
#[path = "../../benches/common/workload.rs"]
mod workload;

mod adaptive;
mod benchmarks;
mod contact;
mod contact3d;
mod equilibrium;
mod explicit;
mod friction;
mod impacts;
mod modal;
mod mortar;
mod nonlinear_dynamics;
mod nonlocal;
mod solids;
mod studies;
mod trapezoidal;
mod verification;
mod viscoelastic;
