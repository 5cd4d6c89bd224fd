//! The recorder of a run: `history.csv` (ledger, solver and probe columns, one
//! flushed row per step), VTK files at the chosen cadence, and the probes' extremes.
//! It reads what a step left behind: displacements, velocities, the ledger and the
//! committed Gauss-point states.

use std::collections::BTreeMap;
use std::path::Path;

use super::history::History;
use super::post::{cell_history_fields, cell_stress};
use super::summary::{ContactSummary, ProbeSummary};
use super::vtk::VtkSeries;
use crate::contact::{ContactState, PairRecord};
use crate::energy::Ledger;
use crate::error::{Error, Result};
use crate::material::store::StateStore;
use crate::model::Model;

/// What the recorder reads of a state.
#[derive(Clone, Copy, Debug)]
pub struct Snapshot<'a> {
    /// Step number.
    pub step: usize,
    /// Time.
    pub t: f64,
    /// Displacements.
    pub u: &'a [f64],
    /// Velocities.
    pub v: &'a [f64],
    /// Ledger.
    pub ledger: &'a Ledger,
    /// Committed Gauss-point states (empty for elastic-only models).
    pub points: &'a [StateStore],
    /// The contact state.
    pub contact: &'a ContactState,
    /// Corrections of the step.
    pub iterations: usize,
    /// Final relative residual of the step.
    pub nl_residual: f64,
}

/// When the VTK series writes a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cadence {
    /// Every this many steps (0: never).
    Steps(usize),
    /// At the first state at or past each multiple of `every` (s); `next` is the
    /// next such time.
    Time {
        /// The interval (s).
        every: f64,
        /// The next frame's time (s).
        next: f64,
    },
}

impl Cadence {
    /// The cadence `analysis.vtk_every_time` (else `vtk_every`) asks for.
    pub fn of(o: &crate::model::OutputSettings) -> Self {
        match o.vtk_every_time {
            Some(every) => Cadence::Time { every, next: 0.0 },
            None => Cadence::Steps(o.vtk_every),
        }
    }

    /// Whether the state of `step` at `t` gets a frame.
    pub fn due(&self, step: usize, t: f64) -> bool {
        match *self {
            Cadence::Steps(k) => k > 0 && step.is_multiple_of(k),
            Cadence::Time { every, next } => t >= next - 1e-9 * every,
        }
    }

    /// A frame was written at `t`: the next is at the following multiple.
    pub fn written(&mut self, t: f64) {
        if let Cadence::Time { every, next } = self {
            *next = ((t / *every + 1e-9).floor() + 1.0) * *every;
        }
    }
}

/// Writes a run's history, VTK series and probe extremes as it goes.
pub struct Recorder {
    history: History,
    vtk: Option<VtkSeries>,
    cadence: Cadence,
    probes: BTreeMap<String, ProbeSummary>,
    samples: Vec<[f64; 3]>,
    contact: BTreeMap<String, ContactSummary>,
    pair_names: Vec<String>,
    last_t: f64,
    empty_pairs: Vec<PairRecord>,
    fields: Option<super::fields::FieldWriter>,
    /// Every recorded displacement, one state after the other, when kept in memory.
    kept_fields: Option<Vec<f64>>,
}

impl Recorder {
    /// Creates `out/history.csv` (and `out/vtk/` when VTK is on).
    pub fn new(model: &Model, out: &Path) -> Result<Self> {
        Self::with_sinks(model, Some(out), false)
    }

    /// A recorder writing into `out` when given (else no file at all) and keeping
    /// the history's columns in memory when `keep`.
    pub fn with_sinks(model: &Model, out: Option<&Path>, keep: bool) -> Result<Self> {
        if let Some(out) = out {
            std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
        }
        let names: Vec<String> = model.probes.iter().map(|p| p.name.clone()).collect();
        let pair_names: Vec<String> = model.contacts.iter().map(|p| p.name.clone()).collect();
        let history = History::with_sinks(
            out.map(|o| o.join("history.csv")).as_deref(),
            &names,
            &pair_names,
            model.mesh.dim,
            keep,
        )?;
        let vtk = match out {
            Some(out)
                if model.analysis.output.vtk_every > 0
                    || model.analysis.output.vtk_every_time.is_some() =>
            {
                Some(VtkSeries::new(out, &model.mesh)?)
            }
            _ => None,
        };
        let probes = names
            .iter()
            .map(|n| (n.clone(), ProbeSummary::default()))
            .collect();
        Ok(Recorder {
            history,
            vtk,
            cadence: Cadence::of(&model.analysis.output),
            probes,
            samples: Vec::with_capacity(model.probes.len()),
            contact: pair_names
                .iter()
                .map(|n| (n.clone(), ContactSummary::default()))
                .collect(),
            empty_pairs: vec![PairRecord::default(); pair_names.len()],
            pair_names,
            last_t: 0.0,
            fields: None,
            kept_fields: None,
        })
    }

    /// Whether the state of `step` at `t` gets a VTK frame.
    pub fn vtk_due(&self, step: usize, t: f64) -> bool {
        self.vtk.is_some() && self.cadence.due(step, t)
    }

    /// Also keeps every recorded state's displacement in memory.
    pub fn keep_fields(&mut self) {
        self.kept_fields = Some(Vec::new());
    }

    /// The history's kept columns and the kept displacements (empty when none).
    pub fn take_kept(&mut self) -> (Vec<(String, Vec<f64>)>, Vec<f64>) {
        (
            self.history.take_columns(),
            self.kept_fields.take().unwrap_or_default(),
        )
    }

    /// Also writes every recorded state's displacement to `out/fields.bin`.
    pub fn record_fields(&mut self, model: &Model, out: &Path) -> Result<()> {
        self.fields = Some(super::fields::FieldWriter::create(
            &out.join("fields.bin"),
            model.mesh.n_dofs(),
        )?);
        Ok(())
    }

    /// Records one state: a history row, and a VTK file when the step is on the
    /// cadence.
    pub fn record(&mut self, model: &Model, s: &Snapshot) -> Result<()> {
        self.samples.clear();
        let d = model.mesh.dim;
        for p in &model.probes {
            let x = [
                s.u[d * p.node],
                s.u[d * p.node + 1],
                if d == 3 { s.u[d * p.node + 2] } else { 0.0 },
            ];
            if let Some(summary) = self.probes.get_mut(&p.name) {
                summary.sample(x[1]);
            }
            self.samples.push(x);
        }
        let pairs = if s.contact.pairs.len() == self.pair_names.len() {
            &s.contact.pairs
        } else {
            &self.empty_pairs
        };
        let dt = s.t - self.last_t;
        for (name, p) in self.pair_names.iter().zip(pairs) {
            if let Some(c) = self.contact.get_mut(name) {
                c.sample(p, dt);
            }
        }
        self.last_t = s.t;
        self.history.row(
            s.t,
            s.ledger,
            s.iterations,
            s.nl_residual,
            &self.samples,
            pairs,
        )?;
        if let Some(f) = &mut self.fields {
            f.append(s.t, s.u)?;
        }
        if let Some(f) = &mut self.kept_fields {
            f.extend_from_slice(s.u);
        }
        if let Some(vtk) = &mut self.vtk {
            if self.cadence.due(s.step, s.t) {
                self.cadence.written(s.t);
                let extra = if s.points.is_empty() {
                    Vec::new()
                } else {
                    cell_history_fields(model, s.points)
                };
                let point_extra: Vec<(&str, &[f64])> =
                    if model.contacts.is_empty() || s.contact.gap.len() != model.mesh.n_nodes() {
                        Vec::new()
                    } else {
                        let mut f = vec![
                            ("contact_gap", &s.contact.gap[..]),
                            ("contact_pressure", &s.contact.pressure[..]),
                        ];
                        if model.contacts.iter().any(|p| p.mu > 0.0)
                            && s.contact.traction.len() == model.mesh.n_nodes()
                        {
                            f.push(("contact_traction", &s.contact.traction[..]));
                            f.push(("contact_slip", &s.contact.slip[..]));
                        }
                        f
                    };
                vtk.write(
                    s.step,
                    s.t,
                    s.u,
                    s.v,
                    &point_extra,
                    &cell_stress(model, s.u, s.points),
                    &extra,
                )?;
            }
        }
        Ok(())
    }

    /// The probes' extremes so far.
    pub fn probes(&self) -> &BTreeMap<String, ProbeSummary> {
        &self.probes
    }

    /// The contact pairs' extremes and impulses so far.
    pub fn contact(&self) -> &BTreeMap<String, ContactSummary> {
        &self.contact
    }
}
