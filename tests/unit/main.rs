//! Unit tests: material points against closed forms and finite-difference tangents, identification, the solvers and backends, the nodal-field path, a law registered from outside the crate.
//!
//! One test binary, one module per topic (see ARCHITECTURE.md, "Tests by kind").

#[path = "../common/mod.rs"]
mod common;
#[path = "../../benches/common/workload.rs"]
mod workload;

mod backends;
mod damage_plasticity;
mod extension;
mod gauss_point_pass;
mod identification;
mod material_point;
mod nodal_fields;
mod solid_plasticity;
mod solves;
