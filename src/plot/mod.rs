//! Line charts of a run, as PNG (1200x800 px) and SVG, drawn with plotters.
//!
//! [`Figure`] holds what a chart shows ([`Series`] of points with a [`Style`], axis
//! labels and [`Scale`]s); [`draw`] writes it. [`History`] reads a run's
//! `history.csv` back and [`plot_run`] draws the standard charts of a run (probe
//! displacements, energies, dissipation, contact forces) into its `plots/` folder.
//! Text is set in DejaVu Sans, embedded in the binary, so the charts look the same
//! on machines without fonts.

mod axis;
mod draw;
mod figure;
pub mod history;
pub mod run_plots;
mod text;

pub use draw::{draw, SIZE};
pub use figure::{reference_slope, Figure, Scale, Series, Style};
pub use history::History;
pub use run_plots::{plot_run, time_ms};
