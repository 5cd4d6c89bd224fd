//! The applications as a user meets them: the command line, bad input named by its field, the fuzz campaign over scenarios and material files.
//!
//! One test binary, one module per topic (see ARCHITECTURE.md, "Tests by kind").

#[path = "../common/mod.rs"]
mod common;
#[path = "../../benches/common/workload.rs"]
mod workload;

mod cli;
mod fuzz;
mod robustness;
mod settings;
