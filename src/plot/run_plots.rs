//! The standard charts of a run, from its output directory.

use std::path::{Path, PathBuf};

use super::chart_names;
use super::draw::draw;
use super::figure::{Figure, Series, Style};
use super::history::History;
use crate::error::{Error, Result};

/// The dissipation lines of the ledger, with their legend labels.
const DISSIPATION: [(&str, &str); 8] = [
    ("D_viscous", "D_viscous (viscous)"),
    ("D_damage", "D_damage (damage)"),
    ("D_plastic", "D_plastic (plastic)"),
    ("D_contact", "D_contact (contact)"),
    ("D_friction", "D_friction (friction)"),
    ("D_predictor", "D_predictor (contact predictor)"),
    ("D_mass", "D_mass (mass damping)"),
    ("D_num", "D_num (numerical)"),
];

/// The time column `t` in milliseconds (empty when the file has none).
pub fn time_ms(h: &History) -> Vec<f64> {
    scaled(h, "t", 1e3).unwrap_or_default()
}

/// Column `name` times `factor`.
fn scaled(h: &History, name: &str, factor: f64) -> Option<Vec<f64>> {
    h.column(name)
        .map(|c| c.into_iter().map(|v| v * factor).collect())
}

/// Reads `dir/history.csv` (and `dir/summary.json` for `energy.kinetic_0`, when
/// present; else the initial kinetic energy is `E_kin` of the first row) and writes
/// PNG and SVG charts into `dir/plots/`:
/// - `probe_<name>`: the probe's vertical displacement `u_y` in mm against t in ms
///   (in file names, characters other than ASCII letters, digits, `-`, `_` and `.`
///   become `_`);
/// - `energies`: E_kin, E_el, W_ext, generalized-α's E_alg where not identically
///   zero, each dissipation line that is not identically zero and the total
///   dissipation, in J against t in ms;
/// - `dissipation`: those dissipation lines and the total over the initial kinetic
///   energy (skipped when that is zero or unknown);
/// - `contact_<pair>`: the pair's total normal force in kN against t in ms, with its
///   net tangential (friction) force where it has one.
///
/// Returns the paths of all files written. A history without a `t` column, or a
/// `summary.json` that is not JSON, is an error.
pub fn plot_run(dir: &Path) -> Result<Vec<PathBuf>> {
    let csv = dir.join("history.csv");
    let h = History::read(&csv)?;
    if h.column("t").is_none() {
        return Err(Error::io(
            &csv,
            std::io::Error::new(std::io::ErrorKind::InvalidData, "no column 't'"),
        ));
    }
    let t = time_ms(&h);
    let out = dir.join("plots");
    let mut written = Vec::new();
    let mut emit = |fig: Figure, name: &str| -> Result<()> {
        written.extend(draw(&fig, &out.join(name))?);
        Ok(())
    };

    let probe_files = chart_names("probe", &h.probes());
    for (p, file) in h.probes().iter().zip(&probe_files) {
        let uy = scaled(&h, &format!("{p}_uy"), 1e3).unwrap_or_default();
        let fig = Figure::new(format!("Probe {p}"), "t [ms]", "u_y [mm]").with(Series::from_xy(
            format!("{p}: u_y"),
            &t,
            &uy,
            Style::Line,
        ));
        emit(fig, file)?;
    }

    // Dissipation lines that are present and not identically zero, and the total.
    let lines: Vec<(&str, Vec<f64>)> = DISSIPATION
        .iter()
        .filter_map(|(name, label)| Some((*label, h.column(name)?)))
        .filter(|(_, v)| v.iter().any(|x| *x != 0.0))
        .collect();
    let total: Vec<f64> = (0..h.rows.len())
        .map(|i| lines.iter().map(|(_, v)| v[i]).sum())
        .collect();

    let mut energies = Figure::new("Energies", "t [ms]", "energy [J]");
    // Unlabelled series without points in the relative chart hold the colours of
    // these lines, so each dissipation line has the same colour in both charts.
    let mut slots = Figure::new("", "", "");
    for (name, label) in [
        ("E_kin", "E_kin (kinetic)"),
        ("E_el", "E_el (stored elastic)"),
        ("W_ext", "W_ext (external work)"),
        ("E_alg", "E_alg (generalized-α's stored)"),
    ] {
        // E_alg only where the scheme stores some.
        let column = h
            .column(name)
            .filter(|v| name != "E_alg" || v.iter().any(|x| *x != 0.0));
        if let Some(v) = column {
            energies = energies.with(Series::from_xy(label, &t, &v, Style::Line));
            slots = slots.with(Series::new("", vec![], Style::Line));
        }
    }
    for (label, v) in &lines {
        energies = energies.with(Series::from_xy(*label, &t, v, Style::Line));
    }
    energies = energies.with(Series::from_xy("D total", &t, &total, Style::Line));
    emit(energies, "energies")?;

    let e0 = initial_kinetic(dir, &h)?;
    if e0.is_finite() && e0 != 0.0 {
        let rel = |v: &[f64]| v.iter().map(|x| x / e0).collect::<Vec<f64>>();
        let mut fig = Figure {
            series: slots.series,
            ..Figure::new(
                "Dissipation relative to the initial kinetic energy",
                "t [ms]",
                "D / E_kin⁰ [-]",
            )
        };
        for (label, v) in &lines {
            fig = fig.with(Series::from_xy(*label, &t, &rel(v), Style::Line));
        }
        fig = fig.with(Series::from_xy("D total", &t, &rel(&total), Style::Line));
        emit(fig, "dissipation")?;
    }

    let pair_files = chart_names("contact", &h.pairs());
    for (p, file) in h.pairs().iter().zip(&pair_files) {
        let f = scaled(&h, &format!("{p}_force"), 1e-3).unwrap_or_default();
        let mut fig = Figure::new(format!("Contact {p}"), "t [ms]", "force [kN]").with(
            Series::from_xy(format!("{p}: total normal force"), &t, &f, Style::Line),
        );
        // With friction: the net tangential force beside it.
        if let Some(ft) = scaled(&h, &format!("{p}_tangential_force"), 1e-3) {
            if ft.iter().any(|&x| x != 0.0) {
                fig = fig.with(Series::from_xy(
                    format!("{p}: net tangential (friction) force"),
                    &t,
                    &ft,
                    Style::Line,
                ));
            }
        }
        emit(fig, file)?;
    }
    Ok(written)
}

/// `energy.kinetic_0` of `dir/summary.json` when the file has it, else `E_kin` of
/// the first row (NaN when there is neither).
fn initial_kinetic(dir: &Path, h: &History) -> Result<f64> {
    let path = dir.join("summary.json");
    let from_history = || {
        h.column("E_kin")
            .and_then(|v| v.first().copied())
            .unwrap_or(f64::NAN)
    };
    let text = match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(from_history()),
        Err(e) => return Err(Error::io(&path, e)),
    };
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        Error::io(
            &path,
            std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string()),
        )
    })?;
    Ok(json
        .pointer("/energy/kinetic_0")
        .and_then(serde_json::Value::as_f64)
        .unwrap_or_else(from_history))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A made-up run: a damped oscillation at probe `tip`, a contact pulse on pair
    /// `floor`, energies that add up.
    fn sample_history(n: usize) -> String {
        let mut s = String::from(
            "t,E_kin,E_int,W_ext,E_el,D_viscous,D_damage,D_plastic,D_contact,D_mass,D_num,\
             residual,iterations,nl_residual,tip_ux,tip_uy,floor_force,floor_active\n",
        );
        let e0 = 12.5;
        for i in 0..n {
            let t = i as f64 * 2e-5; // up to 20 ms
            let w = 2.0 * std::f64::consts::PI * 250.0;
            let decay = (-120.0 * t).exp();
            let uy = -2.5e-3 * decay * (w * t).sin();
            let lost = e0 * (1.0 - (-240.0 * t).exp());
            let (visc, num, cont) = (0.55 * lost, 0.15 * lost, 0.3 * lost);
            let mech = e0 - lost;
            let phase = (w * t).cos().powi(2);
            let (ek, eel) = (mech * phase, mech * (1.0 - phase));
            let force = if (0.002..0.004).contains(&t) {
                45e3 * ((t - 0.002) / 0.002 * std::f64::consts::PI).sin()
            } else {
                0.0
            };
            let active = if force > 0.0 { 4 } else { 0 };
            s.push_str(&format!(
                "{t:.9e},{ek:.12e},{:.12e},0,{eel:.12e},{visc:.12e},0,0,{cont:.12e},0,{num:.12e},\
                 1e-15,3,1e-10,{:.12e},{uy:.12e},{force:.12e},{active}\n",
                -eel,
                1e-4 * uy
            ));
        }
        s
    }

    #[test]
    fn plot_run_writes_every_chart() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("history.csv"), sample_history(1001)).unwrap();
        let files = plot_run(dir.path()).unwrap();
        let names: Vec<String> = files
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        for n in [
            "probe_tip.png",
            "probe_tip.svg",
            "energies.png",
            "energies.svg",
            "dissipation.png",
            "dissipation.svg",
            "contact_floor.png",
            "contact_floor.svg",
        ] {
            assert!(names.contains(&n.to_string()), "{n} not in {names:?}");
        }
        for f in &files {
            assert!(f.starts_with(dir.path().join("plots")));
            assert!(std::fs::metadata(f).unwrap().len() > 0);
        }
        let svg = std::fs::read_to_string(dir.path().join("plots/energies.svg")).unwrap();
        assert!(svg.contains("D_viscous") && svg.contains("D total"));
        assert!(!svg.contains("D_damage"), "an all-zero line is drawn");
        assert_eq!(
            time_ms(&History::read(&dir.path().join("history.csv")).unwrap())[1],
            0.02
        );
    }

    #[test]
    fn no_initial_kinetic_energy_skips_the_relative_chart() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("history.csv"),
            "t,E_kin,W_ext,E_el,D_num\n0,0,0,0,0\n1e-3,0,1,0.5,0.5\n",
        )
        .unwrap();
        std::fs::write(
            dir.path().join("summary.json"),
            r#"{"energy": {"kinetic_0": 0.0}}"#,
        )
        .unwrap();
        let files = plot_run(dir.path()).unwrap();
        assert_eq!(files.len(), 2, "{files:?}"); // energies.png, energies.svg
        std::fs::write(dir.path().join("summary.json"), "{").unwrap();
        assert!(plot_run(dir.path()).is_err());
    }

    /// Writes the sample into `plotdemo` under the temporary directory and plots it
    /// there, to look at.
    #[test]
    #[ignore]
    fn demo() {
        let dir = std::env::temp_dir().join("plotdemo");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("history.csv"), sample_history(1001)).unwrap();
        for f in plot_run(&dir).unwrap() {
            println!("{}", f.display());
        }
    }
}
