//! Sweeps of runs and what is learnt from them: convergence in the time step
//! ([`time_study`]), error-controlled steps against fixed ones ([`tolerance_study`]) and in the mesh ([`mesh_study`]), the implicit path against the
//! explicit one ([`compare`]), and the paper's benchmarks ([`report`]).
//!
//! Every sweep is a [`plan::Plan`] of independent `rothe run`s, each into its own
//! directory `runs/<id>`. [`sweep::sweep`] runs them on the machine's cores; `--emit`
//! writes them as commands and a Slurm job array instead; [`collect::collect`] reads
//! the outputs back ([`run_data`]), however they were made, and writes the tables
//! (`study.csv`), the plots (`plots/`) and the summary (`study.md`, or `report.md`).
//! The study kinds read runs through [`run_data`] and are called by [`collect()`]
//! alone, so no module of a kind imports the one that dispatches to it. Theory:
//! `theory/studies.md` and `theory/benchmarks.md`.

pub mod collect;
pub mod compare;
pub mod mesh_study;
pub mod norms;
pub mod orders;
pub mod plan;
pub mod report;
pub mod run_data;
pub mod sweep;
pub mod table;
pub mod time_study;
pub mod tolerance_study;

pub use collect::collect;
pub use plan::{Plan, PlannedRun, StudyKind};
pub use sweep::{sweep, SweepOptions};
