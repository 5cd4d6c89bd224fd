//! Output files, written as the run goes so a run stopped part way leaves valid files:
//! `history.csv` (one flushed row per step), VTK `.vtu` files with a `.pvd`
//! collection rewritten after each, and `summary.json` at the end (also on failure,
//! with the error).

pub mod checks;
pub mod fields;
pub mod history;
pub mod post;
pub mod recorder;
pub mod summary;
pub mod vtk;
