//! `rothe study time`: one scenario for a sequence of steps `h`, the Rothe
//! interpolants of each run against a reference run `2^K` times finer than the
//! finest studied step (`--reference-halvings K`, default 2; `K = 0` takes the finest
//! studied run itself).
//!
//! For a run with states `u_k` at `t_k`, the piecewise-constant interpolant is
//! `ū(t) = u_k` on `(t_{k−1}, t_k]` and the piecewise-linear one `û` joins the
//! states. Both are compared with the reference run's piecewise-linear interpolant,
//! on the reference's intervals: there the difference is linear in `t` (the coarse
//! steps are multiples of the finest), so `sup_t ‖e‖` is attained at an interval's
//! end and `∫ ‖e‖² dt = τ/3 (‖e_a‖² + (e_a, e_b) + ‖e_b‖²)` exactly. The norms are
//! `L∞(0,T; L2(Ω))` and `L2(0,T; H1(Ω))` ([`super::norms`]). Fields stream from each
//! run's `fields.bin`, one state at a time. Theory: `theory/studies.md`.

use std::path::Path;

use super::norms::{Norms, Products};
use super::orders::{observed, observed_from_differences, richardson, richardson_order};
use super::plan::{Plan, PlannedRun, StudyKind};
use super::run_data::RunData;
use super::table::{num, Table};
use crate::config::{load_with_overrides, LoadOptions, Overrides};
use crate::error::{Error, Result};
use crate::output::fields::FieldReader;
use crate::plot::{draw, reference_slope, Figure, Series, Style};

/// The id of the reference run of a time study.
pub const REFERENCE_ID: &str = "reference";

/// Reference halvings beyond the finest studied step, by default: the errors of the
/// finest studied run against a reference four times finer.
pub const DEFAULT_REFERENCE_HALVINGS: usize = 2;

/// The plan of a time study: `hs` (any order; sorted coarse to fine) and, for
/// `reference_halvings > 0`, the reference run at `min(hs) / 2^reference_halvings`.
pub fn plan(
    scenario: &Path,
    base: &Overrides,
    hs: &[f64],
    reference_halvings: usize,
) -> Result<Plan> {
    let scenario = super::plan::absolute(scenario)?;
    let model = load_with_overrides(&scenario, &LoadOptions::default(), base)?;
    if model.analysis.time.adaptive.is_some() {
        return Err(Error::config(
            "analysis.adaptive",
            "a time study compares runs at fixed steps h, and the scenario chooses its              steps from an error estimate: remove the key (--unset analysis.adaptive), or              study the tolerance instead (rothe study tolerance)",
        ));
    }
    let mut hs: Vec<f64> = hs.to_vec();
    if hs.len() < 2 || hs.iter().any(|h| !(h.is_finite() && *h > 0.0)) {
        return Err(Error::config(
            "--h",
            format!("a time study needs at least two positive steps, got {hs:?}"),
        ));
    }
    if hs.len() > super::plan::MAX_SIZES {
        return Err(Error::config(
            "--h",
            format!("{} steps: at most {}", hs.len(), super::plan::MAX_SIZES),
        ));
    }
    hs.sort_by(|a, b| b.total_cmp(a));
    hs.dedup();
    if reference_halvings > 20 {
        return Err(Error::config(
            "--reference-halvings",
            format!("at most 20 (a reference 2^20 times finer), got {reference_halvings}"),
        ));
    }
    let run = |id: String, h: f64, label: String| PlannedRun {
        id,
        scenario: scenario.clone(),
        overrides: base.then(
            &Overrides::none()
                .set(&format!("analysis.dt={h:e}"))
                .expect("k=v"),
        ),
        param: h,
        label,
        record_fields: true,
    };
    let mut runs: Vec<PlannedRun> = hs
        .iter()
        .enumerate()
        .map(|(i, &h)| run(format!("h{i}"), h, format!("h = {h:.3e} s")))
        .collect();
    if reference_halvings > 0 {
        let h = hs[hs.len() - 1] / f64::powi(2.0, reference_halvings as i32);
        runs.push(run(
            REFERENCE_ID.into(),
            h,
            format!("reference, h = {h:.3e} s"),
        ));
    }
    Ok(Plan {
        kind: StudyKind::Time,
        runs,
    })
}

/// Most halvings a time study takes (`h / 2^20`: a million times the steps).
pub const MAX_HALVINGS: usize = 20;

/// The steps `h, h/2, ..., h/2^n` from the scenario's own `h` (`1 ≤ n ≤ 20`).
pub fn halvings(scenario: &Path, base: &Overrides, n: usize) -> Result<Vec<f64>> {
    if !(1..=MAX_HALVINGS).contains(&n) {
        return Err(Error::config(
            "--halvings",
            format!("{n}: give 1 to {MAX_HALVINGS} (a study needs two steps)"),
        ));
    }
    let model = load_with_overrides(scenario, &LoadOptions::default(), base)?;
    let h = model.analysis.time.dt;
    Ok((0..=n).map(|k| h / f64::powi(2.0, k as i32)).collect())
}

/// The errors of one run against the reference.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// `‖ū − u_ref‖` in `L∞(0,T; L2)`.
    pub constant_linf_l2: f64,
    /// `‖ū − u_ref‖` in `L2(0,T; H1)`.
    pub constant_l2_h1: f64,
    /// `‖û − u_ref‖` in `L∞(0,T; L2)`.
    pub linear_linf_l2: f64,
    /// `‖û − u_ref‖` in `L2(0,T; H1)`.
    pub linear_l2_h1: f64,
}

/// A coarse run's reader with the two states around the current time.
struct Coarse {
    reader: FieldReader,
    prev: (f64, Vec<f64>),
    next: (f64, Vec<f64>),
    done: bool,
    sup: [f64; 2],
    int: [f64; 2],
}

impl Coarse {
    fn open(path: &Path) -> Result<Coarse> {
        let mut reader = FieldReader::open(path)?;
        let mut u = Vec::new();
        let t = reader
            .next_into(&mut u)?
            .ok_or_else(|| Error::io(path, std::io::Error::other("no states in fields.bin")))?;
        Ok(Coarse {
            reader,
            prev: (t, u.clone()),
            next: (t, u),
            done: false,
            sup: [0.0; 2],
            int: [0.0; 2],
        })
    }

    /// Advances so that `prev.t < t ≤ next.t` (or to the end of the file).
    fn advance_to(&mut self, t: f64, eps: f64) -> Result<()> {
        while !self.done && self.next.0 < t - eps {
            let mut u = std::mem::take(&mut self.prev.1);
            match self.reader.next_into(&mut u)? {
                Some(tn) => {
                    std::mem::swap(&mut self.prev, &mut self.next);
                    self.next = (tn, u);
                }
                None => {
                    self.prev.1 = u;
                    self.done = true;
                }
            }
        }
        Ok(())
    }

    /// The linear interpolant at `t`.
    fn linear(&self, t: f64, out: &mut [f64]) {
        let (t0, t1) = (self.prev.0, self.next.0);
        let s = if t1 > t0 {
            ((t - t0) / (t1 - t0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        for ((o, a), b) in out.iter_mut().zip(&self.prev.1).zip(&self.next.1) {
            *o = a + s * (b - a);
        }
    }
}

fn diff(a: &[f64], b: &[f64], out: &mut [f64]) {
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        *o = x - y;
    }
}

/// Accumulates one interval's linear error `e_a → e_b` of length `tau`.
fn accumulate(norms: &Norms, ea: &[f64], eb: &[f64], tau: f64, sup: &mut f64, int: &mut f64) {
    let [aa, ab, bb]: [Products; 3] = norms.triple(ea, eb);
    *sup = sup.max(aa.l2.max(bb.l2).max(0.0).sqrt());
    *int += tau / 3.0 * (aa.h1 + ab.h1 + bb.h1);
}

/// The errors of every run of `runs` against `reference`, streaming the fields.
pub fn errors(norms: &Norms, runs: &[&Path], reference: &Path) -> Result<Vec<Errors>> {
    let mut fine = FieldReader::open(reference)?;
    let n = fine.dofs();
    let mut coarse: Vec<Coarse> = runs
        .iter()
        .map(|p| Coarse::open(p))
        .collect::<Result<_>>()?;
    for (c, p) in coarse.iter().zip(runs) {
        if c.reader.dofs() != n {
            return Err(Error::io(
                p,
                std::io::Error::other(format!(
                    "{} dofs, the reference has {n}: a time study compares one mesh",
                    c.reader.dofs()
                )),
            ));
        }
    }
    let (mut ua, mut ub) = (Vec::new(), Vec::new());
    let Some(mut ta) = fine.next_into(&mut ua)? else {
        return Ok(vec![Errors::default(); runs.len()]);
    };
    let (mut ea, mut eb, mut w) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    while let Some(tb) = fine.next_into(&mut ub)? {
        let tau = tb - ta;
        let eps = 1e-6 * tau.abs().max(f64::MIN_POSITIVE);
        for c in coarse.iter_mut() {
            c.advance_to(tb, eps)?;
            if c.done && c.next.0 < tb - eps {
                continue; // the coarse run ended (failed) before the reference
            }
            // Piecewise constant: the coarse state at the right end of its interval.
            diff(&c.next.1, &ua, &mut ea);
            diff(&c.next.1, &ub, &mut eb);
            accumulate(norms, &ea, &eb, tau, &mut c.sup[0], &mut c.int[0]);
            // Piecewise linear.
            c.linear(ta, &mut w);
            diff(&w, &ua, &mut ea);
            c.linear(tb, &mut w);
            diff(&w, &ub, &mut eb);
            accumulate(norms, &ea, &eb, tau, &mut c.sup[1], &mut c.int[1]);
        }
        std::mem::swap(&mut ua, &mut ub);
        ta = tb;
    }
    Ok(coarse
        .iter()
        .map(|c| Errors {
            constant_linf_l2: c.sup[0],
            constant_l2_h1: c.int[0].max(0.0).sqrt(),
            linear_linf_l2: c.sup[1],
            linear_l2_h1: c.int[1].max(0.0).sqrt(),
        })
        .collect())
}

/// The errors of `runs` against `reference` (their recorded fields), with the norms
/// of the reference's mesh: each run's `fields.bin` is checked to hold one whole
/// state per row of its history on that mesh first.
pub(super) fn against_reference(
    reference: &RunData,
    runs: &[&RunData],
) -> Result<(Norms, Vec<Errors>)> {
    let model = load_with_overrides(
        &reference.run.scenario,
        &LoadOptions::unlimited(),
        &reference.run.overrides,
    )?;
    let norms = Norms::new(&model.mesh);
    for r in runs.iter().chain(std::iter::once(&reference)) {
        let states = r.column("t").len() as u64;
        FieldReader::open(&r.dir.join("fields.bin"))?.expect(states, model.mesh.n_dofs())?;
    }
    let paths: Vec<std::path::PathBuf> = runs.iter().map(|r| r.dir.join("fields.bin")).collect();
    let refs: Vec<&Path> = paths.iter().map(|p| p.as_path()).collect();
    let errs = errors(&norms, &refs, &reference.dir.join("fields.bin"))?;
    Ok((norms, errs))
}

/// Largest `E_kin + E_el` over the run: the discrete energy bound `max_s E_s`.
fn max_energy(r: &RunData) -> f64 {
    r.column("E_kin")
        .iter()
        .zip(r.column("E_el"))
        .map(|(k, e)| k + e)
        .fold(f64::NAN, f64::max)
}

/// Tables, plots and summary of a collected time study.
pub fn collect(dir: &Path, runs: &[RunData]) -> Result<String> {
    let done: Vec<&RunData> = runs.iter().filter(|r| r.completed()).collect();
    if done.len() < 2 {
        return Err(Error::Stepping(format!(
            "a time study needs two completed runs, {} of {} completed",
            done.len(),
            runs.len()
        )));
    }
    // The reference run when the plan has one (and it completed), else the finest.
    let (reference, coarse): (&RunData, Vec<&RunData>) =
        match done.iter().position(|r| r.run.id == REFERENCE_ID) {
            Some(i) => (
                done[i],
                done.iter()
                    .enumerate()
                    .filter(|(k, _)| *k != i)
                    .map(|(_, r)| *r)
                    .collect(),
            ),
            None => (done[done.len() - 1], done[..done.len() - 1].to_vec()),
        };
    let separate = reference.run.id == REFERENCE_ID;
    if coarse.len() < 2 && separate || coarse.is_empty() {
        return Err(Error::Stepping(format!(
            "a time study needs two completed runs besides its reference, {} of {} completed",
            coarse.len(),
            runs.len()
        )));
    }
    let (norms, errs) = against_reference(reference, &coarse)?;
    let paths: Vec<std::path::PathBuf> = coarse.iter().map(|r| r.dir.join("fields.bin")).collect();
    let refs: Vec<&Path> = paths.iter().map(|p| p.as_path()).collect();
    let h: Vec<f64> = coarse.iter().map(|r| r.run.param).collect();
    let h_ref = reference.run.param;
    let names = [
        "constant_Linf_L2",
        "constant_L2_H1",
        "linear_Linf_L2",
        "linear_L2_H1",
    ];
    let cols: [Vec<f64>; 4] = [
        errs.iter().map(|e| e.constant_linf_l2).collect(),
        errs.iter().map(|e| e.constant_l2_h1).collect(),
        errs.iter().map(|e| e.linear_linf_l2).collect(),
        errs.iter().map(|e| e.linear_l2_h1).collect(),
    ];
    // Orders from successive differences: each studied run against the next finer
    // one, the finest against the reference (theory/studies.md).
    let reference_path = reference.dir.join("fields.bin");
    let mut chain = refs.clone();
    chain.push(reference_path.as_path());
    let diffs: Vec<Errors> = chain
        .windows(2)
        .map(|w| errors(&norms, &w[..1], w[1]).map(|e| e[0]))
        .collect::<Result<_>>()?;
    let mut steps = h.clone();
    steps.push(h_ref);
    let dcols: [Vec<f64>; 4] = [
        diffs.iter().map(|e| e.constant_linf_l2).collect(),
        diffs.iter().map(|e| e.constant_l2_h1).collect(),
        diffs.iter().map(|e| e.linear_linf_l2).collect(),
        diffs.iter().map(|e| e.linear_l2_h1).collect(),
    ];
    // The piecewise-constant interpolants' error is their own `O(h)` interpolation
    // error, not correlated with the reference's: their plain ratio is unbiased.
    let orders: Vec<Vec<Option<f64>>> = (0..4)
        .map(|k| {
            if k < 2 {
                observed(&h, &cols[k])
            } else {
                observed_from_differences(&steps, &dcols[k])
            }
        })
        .collect();
    let rich: Vec<Vec<f64>> = cols
        .iter()
        .zip(&orders)
        .map(|(e, o)| richardson(&h, e, h_ref, richardson_order(o)))
        .collect();
    let mut header = vec![
        "h".to_string(),
        "steps".into(),
        "iterations".into(),
        "step_cuts".into(),
        "max_energy".into(),
        "D_total".into(),
        "seconds".into(),
    ];
    for n in names {
        header.push(format!("err_{n}"));
        header.push(format!("order_{n}"));
        header.push(format!("richardson_{n}"));
    }
    let mut table = Table::new(&header);
    let rows: Vec<&RunData> = if separate {
        coarse.clone()
    } else {
        done.clone()
    };
    for (i, r) in rows.iter().enumerate() {
        let mut row = vec![
            format!("{:e}", r.run.param),
            num(r.number("/steps")),
            num(r.number("/solver/iterations")),
            num(r.number("/solver/step_cuts")),
            num(Some(max_energy(r))),
            num(Some(r.dissipated_total())),
            num(Some(r.seconds())),
        ];
        for k in 0..4 {
            let e = cols[k].get(i).copied();
            let o = if i > 0 {
                orders[k].get(i - 1).copied().flatten()
            } else {
                None
            };
            row.push(num(e));
            row.push(num(o));
            row.push(num(rich[k].get(i).copied()));
        }
        table.push(row);
    }
    table.write_csv(&dir.join("study.csv"))?;
    // Convergence plot with reference slopes of order 1 and 1/2.
    let mut fig = Figure::new(
        if separate {
            "Rothe interpolants against the reference run"
        } else {
            "Rothe interpolants against the finest run"
        },
        "h [s]",
        "error norm (SI units)",
    )
    .log_log();
    let labels = [
        "piecewise constant, L∞(0,T;L2)",
        "piecewise constant, L2(0,T;H1)",
        "piecewise linear, L∞(0,T;L2)",
        "piecewise linear, L2(0,T;H1)",
    ];
    for (k, l) in labels.iter().enumerate() {
        fig = fig.with(Series::from_xy(*l, &h, &cols[k], Style::LineWithMarkers));
    }
    let range = (h[h.len() - 1], h[0]);
    if let Some(&e0) = cols[1].first().filter(|e| **e > 0.0) {
        fig = fig.with(reference_slope("order 1", 1.0, range, (h[0], e0)));
        fig = fig.with(reference_slope("order 1/2", 0.5, range, (h[0], e0)));
    }
    draw(&fig, &dir.join("plots").join("convergence"))?;
    super::mesh_study::probe_overlay(dir, &done, "time")?;
    let which = if separate {
        format!("a run of its own, h = {h_ref:e} s, finer than every studied step")
    } else {
        format!(
            "the finest run, h = {h_ref:e} s (no separate reference; the orders come \
             from successive differences, theory/studies.md)"
        )
    };
    let mut md = format!(
        "# Time study: {}\n\nReference: {which}. Errors of the Rothe interpolants \
         against its piecewise-linear interpolant; observed order between consecutive \
         runs from successive differences (no run taken as the truth); Richardson's estimate of the true error (order of the two finest runs). \
         `max_energy` is the discrete energy bound max_s (E_kin + E_el). Table: \
         `study.csv`; plots: `plots/convergence.png`, `plots/probe_*`.\n\n",
        reference.run.scenario.display()
    );
    let mut short = Table::new(&[
        "h [s]",
        "iterations",
        "max_s E_s [J]",
        "ū: L∞L2",
        "order",
        "ū: L2H1",
        "order",
        "û: L∞L2",
        "order",
        "û: L2H1",
        "order",
    ]);
    for row in &table.rows {
        let mut r = vec![row[0].clone(), row[2].clone(), row[4].clone()];
        for k in 0..4 {
            r.push(row[7 + 3 * k].clone());
            r.push(row[8 + 3 * k].clone());
        }
        short.push(r);
    }
    md.push_str(&short.markdown());
    md.push_str("\n![convergence](plots/convergence.png)\n");
    Ok(md)
}
