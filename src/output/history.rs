//! `history.csv`: one row per step, flushed as it is written.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::energy::Ledger;
use crate::error::{Error, Result};

/// The fixed ledger columns.
pub const LEDGER_COLUMNS: [&str; 15] = [
    "t",
    "E_kin",
    "E_int",
    "W_ext",
    "E_el",
    "D_viscous",
    "D_damage",
    "D_plastic",
    "D_contact",
    "D_friction",
    "D_predictor",
    "D_mass",
    "D_num",
    "E_alg",
    "residual",
];

/// Writer of `history.csv`, and keeper of its columns in memory when asked.
pub struct History {
    path: PathBuf,
    out: Option<BufWriter<File>>,
    /// The mesh's dimension (a solid's probes have a z column).
    dim: usize,
    /// The column names, and each column's values when kept in memory.
    names: Vec<String>,
    columns: Option<Vec<Vec<f64>>>,
    /// One row's values, reused from row to row.
    values: Vec<f64>,
}

impl History {
    /// Creates the file and writes the header (ledger columns, solver columns, then
    /// `<probe>_ux, <probe>_uy` (and `<probe>_uz` in a solid, `dim = 3`) per probe, then `<pair>_force, <pair>_active`,
    /// `<pair>_tangential_force, <pair>_stick, <pair>_slip` per contact pair: the
    /// normal force, the pressed nodes, the friction force and how many pressed
    /// nodes stick and slip).
    pub fn create(path: &Path, probes: &[String], pairs: &[String], dim: usize) -> Result<Self> {
        Self::with_sinks(Some(path), probes, pairs, dim, false)
    }

    /// A history written to `path` (when given) and kept in memory column by column
    /// (when `keep`): the values themselves, not their rounded text.
    pub fn with_sinks(
        path: Option<&Path>,
        probes: &[String],
        pairs: &[String],
        dim: usize,
        keep: bool,
    ) -> Result<Self> {
        let out = match path {
            Some(p) => Some(BufWriter::new(
                File::create(p).map_err(|e| Error::io(p, e))?,
            )),
            None => None,
        };
        let mut cols: Vec<String> = LEDGER_COLUMNS.iter().map(|s| s.to_string()).collect();
        cols.push("iterations".into());
        cols.push("nl_residual".into());
        for p in probes {
            for c in &["ux", "uy", "uz"][..dim] {
                cols.push(format!("{p}_{c}"));
            }
        }
        for p in pairs {
            cols.push(format!("{p}_force"));
            cols.push(format!("{p}_active"));
            cols.push(format!("{p}_tangential_force"));
            cols.push(format!("{p}_stick"));
            cols.push(format!("{p}_slip"));
        }
        let n = cols.len();
        let mut h = History {
            path: path.map(Path::to_path_buf).unwrap_or_default(),
            out,
            dim,
            names: cols,
            columns: keep.then(|| vec![Vec::new(); n]),
            values: Vec::with_capacity(n),
        };
        h.write_header()?;
        Ok(h)
    }

    fn write_header(&mut self) -> Result<()> {
        if let Some(out) = &mut self.out {
            writeln!(out, "{}", self.names.join(",")).map_err(|e| Error::io(&self.path, e))?;
        }
        self.flush()
    }

    /// The column names and the kept columns (empty unless kept).
    pub fn take_columns(&mut self) -> Vec<(String, Vec<f64>)> {
        match self.columns.take() {
            Some(c) => self.names.iter().cloned().zip(c).collect(),
            None => Vec::new(),
        }
    }

    /// Appends one row and flushes it.
    pub fn row(
        &mut self,
        t: f64,
        l: &Ledger,
        iterations: usize,
        nl_residual: f64,
        probes: &[[f64; 3]],
        pairs: &[crate::contact::PairRecord],
    ) -> Result<()> {
        let d = l.dissipated();
        if let Some(cols) = &mut self.columns {
            let values = &mut self.values;
            values.clear();
            values.extend([
                t,
                l.kinetic(),
                l.internal(),
                l.external_work(),
                l.elastic(),
                d.viscous,
                d.damage,
                d.plastic,
                d.contact,
                d.friction,
                d.predictor,
                d.mass,
                d.numerical,
                l.algorithmic(),
                l.residual(),
                iterations as f64,
                nl_residual,
            ]);
            for p in probes {
                values.extend_from_slice(&p[..self.dim]);
            }
            for p in pairs {
                values.extend([
                    p.force,
                    p.active as f64,
                    p.tangential_force,
                    p.sticking as f64,
                    p.slipping as f64,
                ]);
            }
            debug_assert_eq!(values.len(), cols.len());
            for (c, v) in cols.iter_mut().zip(values.iter()) {
                c.push(*v);
            }
        }
        let Some(out) = &mut self.out else {
            return Ok(());
        };
        let mut line = format!(
            "{t:.9e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.6e},{iterations},{nl_residual:.3e}",
            l.kinetic(), l.internal(), l.external_work(), l.elastic(), d.viscous, d.damage, d.plastic,
            d.contact, d.friction, d.predictor, d.mass, d.numerical, l.algorithmic(), l.residual()
        );
        for p in probes {
            for x in &p[..self.dim] {
                line.push_str(&format!(",{x:.12e}"));
            }
        }
        for p in pairs {
            line.push_str(&format!(
                ",{:.12e},{},{:.12e},{},{}",
                p.force, p.active, p.tangential_force, p.sticking, p.slipping
            ));
        }
        let _hold = super::interrupt::hold();
        writeln!(out, "{line}").map_err(|e| Error::io(&self.path, e))?;
        self.flush()
    }

    fn flush(&mut self) -> Result<()> {
        match &mut self.out {
            Some(out) => out.flush().map_err(|e| Error::io(&self.path, e)),
            None => Ok(()),
        }
    }
}
