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

/// Longest name part of a chart file (well inside the usual 255-byte limit of a file
/// name, with the prefix, a hash and the extension).
const NAME_PART: usize = 96;

/// File names (without extension) `<prefix>_<name>` for the charts of `names`
/// (probes, contact pairs): characters other than ASCII letters, digits, `-`, `_`
/// and `.` become `_`, a long name is cut, and a name that was cut or that would meet
/// another one (also when only their case differs, for case-insensitive file
/// systems) gets `_` and a hash of the original, so no two charts share a file.
pub fn chart_names<S: AsRef<str>>(prefix: &str, names: &[S]) -> Vec<String> {
    let safe: Vec<String> = names
        .iter()
        .map(|n| {
            n.as_ref()
                .chars()
                .map(|c| {
                    if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                        c
                    } else {
                        '_'
                    }
                })
                .take(NAME_PART)
                .collect()
        })
        .collect();
    let lower: Vec<String> = safe.iter().map(|s| s.to_ascii_lowercase()).collect();
    names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let cut = n.as_ref().chars().count() > NAME_PART;
            let clash = lower
                .iter()
                .enumerate()
                .any(|(j, l)| j != i && *l == lower[i]);
            if cut || clash {
                format!("{prefix}_{}_{:08x}", safe[i], fnv(n.as_ref()))
            } else {
                format!("{prefix}_{}", safe[i])
            }
        })
        .collect()
}

/// 32-bit FNV-1a of `s` (stable across runs and platforms).
fn fnv(s: &str) -> u32 {
    s.bytes().fold(0x811c_9dc5u32, |h, b| {
        (h ^ b as u32).wrapping_mul(0x0100_0193)
    })
}

#[cfg(test)]
mod tests {
    use super::chart_names;

    #[test]
    fn chart_names_never_meet_and_stay_short() {
        let long = "p".repeat(400);
        let names = ["a b", "a_b", "A_B", "mid", long.as_str(), "x/../../y"];
        let files = chart_names("probe", &names);
        assert_eq!(files[3], "probe_mid");
        assert_eq!(files[5], "probe_x_.._.._y");
        let mut unique: Vec<String> = files.iter().map(|f| f.to_ascii_lowercase()).collect();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{files:?}");
        assert!(
            files.iter().all(|f| f.len() < 120 && !f.contains('/')),
            "{files:?}"
        );
    }
}
