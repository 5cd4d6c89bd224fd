//! `rothe study mesh`: one scenario for a sequence of mesh sizes (the key
//! `meshing.element_size`, which every rectangle body without its own `divisions`
//! takes): probe histories, peak values and dissipation per mechanism for each mesh,
//! and the peak's change against the finest mesh with its observed order.

use std::path::Path;

use super::orders::observed_from_differences;
use super::plan::{Plan, PlannedRun, StudyKind};
use super::run_data::{RunData, DISSIPATION_LINES};
use super::table::{num, Table};
use crate::config::Overrides;
use crate::error::{Error, Result};
use crate::plot::{draw, Figure, Series, Style};

/// The plan of a mesh study over `sizes` (sorted coarse to fine).
pub fn plan(scenario: &Path, base: &Overrides, sizes: &[f64]) -> Result<Plan> {
    let scenario = super::plan::absolute(scenario)?;
    super::plan::check_sizes("--sizes", sizes, true)?;
    let mut sizes = sizes.to_vec();
    sizes.sort_by(|a, b| b.total_cmp(a));
    sizes.dedup();
    let runs = sizes
        .iter()
        .enumerate()
        .map(|(i, s)| PlannedRun {
            id: format!("m{i}"),
            scenario: scenario.clone(),
            overrides: base.then(
                &Overrides::none()
                    .set(&format!("meshing.element_size={s}"))
                    .expect("k=v"),
            ),
            param: *s,
            label: format!("{s} m"),
            record_fields: false,
        })
        .collect();
    Ok(Plan {
        kind: StudyKind::Mesh,
        runs,
    })
}

/// The dissipation columns of a study table: each line over `E_kin⁰` (or in J when
/// there is no initial kinetic energy).
pub fn dissipation_cells(r: &RunData) -> Vec<String> {
    let k0 = r.kinetic_0();
    let scale = if k0 > 0.0 { k0 } else { 1.0 };
    let mut cells: Vec<String> = DISSIPATION_LINES
        .iter()
        .map(|l| num(Some(r.dissipated(l) / scale)))
        .collect();
    cells.push(num(Some(r.dissipated_total() / scale)));
    cells
}

/// The header of [`dissipation_cells`].
pub fn dissipation_header() -> Vec<String> {
    let mut h: Vec<String> = DISSIPATION_LINES
        .iter()
        .map(|l| format!("D_{l}/E_kin0"))
        .collect();
    h.push("D_total/E_kin0".into());
    h
}

/// One chart per probe with every run's `u_y` against time (`plots/probe_<name>`),
/// and one of the total dissipation over `E_kin⁰` (`plots/dissipation`).
pub fn probe_overlay(dir: &Path, runs: &[&RunData], what: &str) -> Result<()> {
    let Some(first) = runs.first() else {
        return Ok(());
    };
    let plots = dir.join("plots");
    let probes = first.probes();
    let files = crate::plot::chart_names("probe", &probes);
    for (p, file) in probes.iter().zip(&files) {
        let mut fig = Figure::new(format!("Probe {p}, {what} study"), "t [ms]", "u_y [mm]");
        for r in runs {
            fig = fig.with(Series::new(
                r.run.label.clone(),
                r.series(&format!("{p}_uy"), 1e3),
                Style::Line,
            ));
        }
        draw(&fig, &plots.join(file))?;
    }
    let mut fig = Figure::new(
        format!("Total dissipation, {what} study"),
        "t [ms]",
        "D / E_kin⁰ [-]",
    );
    for r in runs {
        let k0 = r.kinetic_0();
        if k0 > 0.0 {
            fig = fig.with(Series::new(
                r.run.label.clone(),
                r.dissipation_series(k0),
                Style::Line,
            ));
        }
    }
    draw(&fig, &plots.join("dissipation"))?;
    Ok(())
}

/// Tables, plots and summary of a collected mesh study.
pub fn collect(dir: &Path, runs: &[RunData]) -> Result<String> {
    let done: Vec<&RunData> = runs.iter().filter(|r| r.completed()).collect();
    let Some(finest) = done.last() else {
        return Err(Error::Stepping("no run of the mesh study completed".into()));
    };
    let probes = finest.probes();
    let mut header = vec![
        "size".to_string(),
        "dofs".into(),
        "steps".into(),
        "seconds".into(),
    ];
    for p in &probes {
        header.push(format!("{p}_min_uy_mm"));
        header.push(format!("{p}_change_mm"));
        header.push(format!("{p}_order"));
    }
    header.extend(dissipation_header());
    let mut table = Table::new(&header);
    let sizes: Vec<f64> = done.iter().map(|r| r.run.param).collect();
    let changes: Vec<Vec<f64>> = probes
        .iter()
        .map(|p| {
            done.iter()
                .map(|r| (r.probe_min(p) - finest.probe_min(p)).abs())
                .collect()
        })
        .collect();
    let n = done.len();
    // Orders from successive differences of the probe (theory/studies.md).
    let orders: Vec<Vec<Option<f64>>> = probes
        .iter()
        .map(|p| {
            let d: Vec<f64> = done
                .windows(2)
                .map(|w| (w[0].probe_min(p) - w[1].probe_min(p)).abs())
                .collect();
            observed_from_differences(&sizes, &d)
        })
        .collect();
    for (i, r) in done.iter().enumerate() {
        let mut row = vec![
            format!("{}", r.run.param),
            num(r.number("/dofs")),
            num(r.number("/steps")),
            num(Some(r.seconds())),
        ];
        for (k, p) in probes.iter().enumerate() {
            row.push(num(Some(r.probe_min(p) * 1e3)));
            row.push(num(Some(changes[k][i] * 1e3)));
            let o = if i > 0 && i < n - 1 {
                orders[k][i - 1]
            } else {
                None
            };
            row.push(num(o));
        }
        row.extend(dissipation_cells(r));
        table.push(row);
    }
    table.write_csv(&dir.join("study.csv"))?;
    probe_overlay(dir, &done, "mesh")?;
    let mut fig = Figure::new(
        "Peak probe deflection against mesh size",
        "element size [m]",
        "min u_y [mm]",
    );
    for p in &probes {
        let pts = done
            .iter()
            .map(|r| (r.run.param, r.probe_min(p) * 1e3))
            .collect();
        fig = fig.with(Series::new(p.clone(), pts, Style::LineWithMarkers));
    }
    draw(&fig, &dir.join("plots").join("peaks"))?;
    let mut md = format!(
        "# Mesh study: {}\n\nPeak (most downward) probe displacement per mesh, its change \
         against the finest mesh and the observed order of that change; dissipation per \
         mechanism over the initial kinetic energy. Table: `study.csv`; plots: \
         `plots/probe_*`, `plots/dissipation`, `plots/peaks`.\n\n",
        finest.run.scenario.display()
    );
    md.push_str(&table.markdown());
    for p in &probes {
        md.push_str(&format!("\n![probe {p}](plots/probe_{p}.png)\n"));
    }
    md.push_str("\n![dissipation](plots/dissipation.png)\n");
    Ok(md)
}
