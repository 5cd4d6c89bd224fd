//! `history.csv`: one row per step, flushed as it is written.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::energy::Ledger;
use crate::error::{Error, Result};

/// The fixed ledger columns.
pub const LEDGER_COLUMNS: [&str; 14] = [
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
    "residual",
];

/// Writer of `history.csv`.
pub struct History {
    path: PathBuf,
    out: BufWriter<File>,
    /// The mesh's dimension (a solid's probes have a z column).
    dim: usize,
}

impl History {
    /// Creates the file and writes the header (ledger columns, solver columns, then
    /// `<probe>_ux, <probe>_uy` (and `<probe>_uz` in a solid, `dim = 3`) per probe, then `<pair>_force, <pair>_active`,
    /// `<pair>_tangential_force, <pair>_stick, <pair>_slip` per contact pair: the
    /// normal force, the pressed nodes, the friction force and how many pressed
    /// nodes stick and slip).
    pub fn create(path: &Path, probes: &[String], pairs: &[String], dim: usize) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut h = History {
            path: path.into(),
            out: BufWriter::new(file),
            dim,
        };
        let mut cols: Vec<String> = LEDGER_COLUMNS.iter().map(|s| s.to_string()).collect();
        cols.push("iterations".into());
        cols.push("nl_residual".into());
        for p in probes {
            cols.push(format!("{p}_ux"));
            cols.push(format!("{p}_uy"));
            if dim == 3 {
                cols.push(format!("{p}_uz"));
            }
        }
        for p in pairs {
            cols.push(format!("{p}_force"));
            cols.push(format!("{p}_active"));
            cols.push(format!("{p}_tangential_force"));
            cols.push(format!("{p}_stick"));
            cols.push(format!("{p}_slip"));
        }
        writeln!(h.out, "{}", cols.join(",")).map_err(|e| Error::io(&h.path, e))?;
        h.flush()?;
        Ok(h)
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
        let mut line = format!(
            "{t:.9e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.12e},{:.6e},{iterations},{nl_residual:.3e}",
            l.kinetic(), l.internal(), l.external_work(), l.elastic(), d.viscous, d.damage, d.plastic,
            d.contact, d.friction, d.predictor, d.mass, d.numerical, l.residual()
        );
        for p in probes {
            line.push_str(&format!(",{:.12e},{:.12e}", p[0], p[1]));
            if self.dim == 3 {
                line.push_str(&format!(",{:.12e}", p[2]));
            }
        }
        for p in pairs {
            line.push_str(&format!(
                ",{:.12e},{},{:.12e},{},{}",
                p.force, p.active, p.tangential_force, p.sticking, p.slipping
            ));
        }
        writeln!(self.out, "{line}").map_err(|e| Error::io(&self.path, e))?;
        self.flush()
    }

    fn flush(&mut self) -> Result<()> {
        self.out.flush().map_err(|e| Error::io(&self.path, e))
    }
}
