//! Reading a run's `history.csv` back (the file `output::history` writes).

use std::path::Path;

use crate::error::{Error, Result};

/// The columns of a `history.csv`: a header of names and one row of numbers per
/// step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct History {
    /// Column names, as in the header (trimmed).
    pub columns: Vec<String>,
    /// The rows, each with one value per column (`NaN` and `inf` parse as such).
    pub rows: Vec<Vec<f64>>,
}

impl History {
    /// Reads the comma-separated file at `path`: one header line, then rows with
    /// as many fields as the header. Blank lines are skipped. A missing header, a
    /// row with the wrong number of fields or a field that is not a number is an
    /// error naming the file and the line.
    pub fn read(path: &Path) -> Result<History> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        History::parse(&text).map_err(|msg| {
            Error::io(
                path,
                std::io::Error::new(std::io::ErrorKind::InvalidData, msg),
            )
        })
    }

    /// Parses the text of a history file; the error says which line is wrong.
    fn parse(text: &str) -> std::result::Result<History, String> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| "line 1: empty file, expected a header line".to_string())?;
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        if let Some(i) = columns.iter().position(|c| c.is_empty()) {
            return Err(format!(
                "line 1: column {} of the header has no name",
                i + 1
            ));
        }
        let mut rows = Vec::new();
        for (n, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != columns.len() {
                return Err(format!(
                    "line {n}: {} fields, the header has {}",
                    fields.len(),
                    columns.len()
                ));
            }
            let row = fields
                .iter()
                .zip(&columns)
                .map(|(f, c)| {
                    f.parse::<f64>()
                        .map_err(|_| format!("line {n}: column {c}: '{f}' is not a number"))
                })
                .collect::<std::result::Result<Vec<f64>, String>>()?;
            rows.push(row);
        }
        Ok(History { columns, rows })
    }

    /// The values of column `name`, one per row (NaN where a row is too short);
    /// `None` when there is no such column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let j = self.columns.iter().position(|c| c == name)?;
        Some(
            self.rows
                .iter()
                .map(|r| r.get(j).copied().unwrap_or(f64::NAN))
                .collect(),
        )
    }

    /// Names `p` of the probes: those with both `p_ux` and `p_uy` columns, in order.
    pub fn probes(&self) -> Vec<String> {
        self.paired("_ux", "_uy")
    }

    /// Names `p` of the contact pairs: those with both `p_force` and `p_active`
    /// columns, in order.
    pub fn pairs(&self) -> Vec<String> {
        self.paired("_force", "_active")
    }

    /// Names `p` with columns `p<first>` and `p<second>`.
    fn paired(&self, first: &str, second: &str) -> Vec<String> {
        self.columns
            .iter()
            .filter_map(|c| c.strip_suffix(first))
            .filter(|p| !p.is_empty() && self.columns.iter().any(|c| *c == format!("{p}{second}")))
            .map(str::to_string)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "\
t,E_kin,E_int,W_ext,E_el,D_viscous,D_damage,D_plastic,D_contact,D_mass,D_num,residual,iterations,nl_residual,tip_ux,tip_uy,mid_ux,mid_uy,floor_force,floor_active
0.0e0,1.0e0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0
1.0e-4, 0.9 ,0.1,0,0.08,0.01,0,0,0,0,0.01,1e-16,3,1.0e-9,1e-6,-2e-5,0,-1e-5,150.5,2
2.0e-4,NaN,0.2,0,0.1,0.02,0,0,0,0,inf,-1e-16,2,1.0e-9,2e-6,-3e-5,0,-2e-5,0,0

";

    #[test]
    fn parses_columns_probes_and_pairs() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        std::fs::write(&path, CSV).unwrap();
        let h = History::read(&path).unwrap();
        assert_eq!(h.columns.len(), 20);
        assert_eq!(h.rows.len(), 3);
        assert_eq!(h.column("t").unwrap(), vec![0.0, 1e-4, 2e-4]);
        let ek = h.column("E_kin").unwrap();
        assert_eq!(ek[1], 0.9);
        assert!(ek[2].is_nan());
        assert_eq!(h.column("D_num").unwrap()[2], f64::INFINITY);
        assert_eq!(h.column("floor_force").unwrap()[1], 150.5);
        assert!(h.column("nope").is_none());
        assert_eq!(h.probes(), ["tip", "mid"]);
        assert_eq!(h.pairs(), ["floor"]);
    }

    #[test]
    fn ragged_row_is_an_error_with_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("history.csv");
        std::fs::write(&path, "t,E_kin\n0,1\n1,2\n2\n").unwrap();
        let msg = History::read(&path).unwrap_err().to_string();
        assert!(
            msg.contains("history.csv") && msg.contains("line 4"),
            "{msg}"
        );
        std::fs::write(&path, "t,E_kin\n0,1\n1,x\n").unwrap();
        let msg = History::read(&path).unwrap_err().to_string();
        assert!(msg.contains("line 3") && msg.contains("E_kin"), "{msg}");
        std::fs::write(&path, "").unwrap();
        assert!(History::read(&path).is_err());
        assert!(History::read(&dir.path().join("missing.csv")).is_err());
    }
}
