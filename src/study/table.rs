//! A table written both as CSV (for pandas or a spreadsheet) and as Markdown (for
//! the study's summary and the report).

use std::path::Path;

use crate::error::{Error, Result};

/// Rows of text cells under a header.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Column names.
    pub header: Vec<String>,
    /// Rows, each as long as the header.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new<S: AsRef<str>>(header: &[S]) -> Self {
        Table {
            header: header.iter().map(|s| s.as_ref().to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row.
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }

    /// CSV text (cells with commas or quotes quoted).
    pub fn csv(&self) -> String {
        let cell = |c: &String| {
            if c.contains([',', '"', '\n']) {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.clone()
            }
        };
        let mut s = String::new();
        for r in std::iter::once(&self.header).chain(&self.rows) {
            s.push_str(&r.iter().map(cell).collect::<Vec<_>>().join(","));
            s.push('\n');
        }
        s
    }

    /// Markdown text.
    pub fn markdown(&self) -> String {
        let line = |r: &[String]| format!("| {} |\n", r.join(" | "));
        let mut s = line(&self.header);
        s.push_str(&line(&vec!["---".to_string(); self.header.len()]));
        for r in &self.rows {
            s.push_str(&line(r));
        }
        s
    }

    /// Writes the CSV to `path`.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.csv()).map_err(|e| Error::io(path, e))
    }
}

/// A number in a table: an integral value as an integer, others to 4 significant
/// digits; `-` for a missing value, `NaN` kept.
pub fn num(v: Option<f64>) -> String {
    match v {
        None => "-".into(),
        Some(x) if x.is_nan() => "NaN".into(),
        Some(0.0) => "0".into(),
        // Counts (dofs, steps, iterations) print as integers.
        Some(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{x:.0}"),
        Some(x) if (1e-3..1e5).contains(&x.abs()) => {
            let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
            format!("{x:.digits$}")
        }
        Some(x) => format!("{x:.3e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_and_markdown() {
        let mut t = Table::new(&["a", "b"]);
        t.push(vec!["1".into(), "x,y".into()]);
        assert_eq!(t.csv(), "a,b\n1,\"x,y\"\n");
        assert_eq!(t.markdown(), "| a | b |\n| --- | --- |\n| 1 | x,y |\n");
        assert_eq!(num(Some(1.23456)), "1.235");
        assert_eq!(num(Some(1234.5)), "1234");
        assert_eq!(num(Some(2.5e-6)), "2.500e-6");
        assert_eq!(num(Some(96.0)), "96");
        assert_eq!(num(Some(-6000.0)), "-6000");
        assert_eq!(num(None), "-");
        assert_eq!(num(Some(f64::NAN)), "NaN");
    }
}
