//! `fields.bin`: the displacement of every step, for studies that compare whole
//! fields between runs (the time study's `L∞(0,T; L2)` and `L2(0,T; H1)` errors).
//!
//! Little-endian binary: the 8 bytes `ROTHEFLD`, the dof count `n` as `u64`, then one
//! record per recorded state, `t` and the `n` displacements, all `f64`. Records are
//! appended and flushed as the run goes, so a stopped run leaves a valid prefix. The
//! reader streams records one at a time: a study never holds a whole run in memory.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

const MAGIC: &[u8; 8] = b"ROTHEFLD";

/// Appends states to `fields.bin`.
pub struct FieldWriter {
    path: PathBuf,
    out: BufWriter<File>,
    n: usize,
    buf: Vec<u8>,
}

impl FieldWriter {
    /// Creates the file for `n` dofs and writes its header.
    pub fn create(path: &Path, n: usize) -> Result<Self> {
        let file = File::create(path).map_err(|e| Error::io(path, e))?;
        let mut w = FieldWriter {
            path: path.into(),
            out: BufWriter::new(file),
            n,
            buf: Vec::with_capacity(8 * (n + 1)),
        };
        w.out
            .write_all(MAGIC)
            .and_then(|_| w.out.write_all(&(n as u64).to_le_bytes()))
            .map_err(|e| Error::io(path, e))?;
        Ok(w)
    }

    /// Appends one state and flushes it.
    pub fn append(&mut self, t: f64, u: &[f64]) -> Result<()> {
        debug_assert_eq!(u.len(), self.n);
        self.buf.clear();
        self.buf.extend_from_slice(&t.to_le_bytes());
        for x in u {
            self.buf.extend_from_slice(&x.to_le_bytes());
        }
        self.out
            .write_all(&self.buf)
            .and_then(|_| self.out.flush())
            .map_err(|e| Error::io(&self.path, e))
    }
}

/// Streams the states of a `fields.bin`.
pub struct FieldReader {
    path: PathBuf,
    input: BufReader<File>,
    n: usize,
    buf: Vec<u8>,
    len: u64,
}

impl FieldReader {
    /// Opens the file and reads its header.
    pub fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let mut input = BufReader::new(file);
        let mut head = [0u8; 16];
        input
            .read_exact(&mut head)
            .map_err(|e| Error::io(path, e))?;
        if &head[..8] != MAGIC {
            return Err(Error::io(
                path,
                std::io::Error::other("not a rothe fields file (bad magic)"),
            ));
        }
        let n = u64::from_le_bytes(head[8..16].try_into().expect("8 bytes")) as usize;
        Ok(FieldReader {
            path: path.into(),
            input,
            n,
            buf: vec![0u8; 8 * (n + 1)],
            len,
        })
    }

    /// The number of whole records, and whether the file ends exactly after the
    /// last of them (false: a record was cut, as when a run is killed mid-write).
    pub fn records(&self) -> (u64, bool) {
        let record = 8 * (self.n as u64 + 1);
        let body = self.len.saturating_sub(16);
        (body / record, body.is_multiple_of(record))
    }

    /// For the file of a run that completed: whole records only, as many as `states`,
    /// `n_dofs` unknowns each; otherwise an error naming what does not match
    /// (a truncated or foreign file must not pass for a shorter run).
    pub fn expect(&self, states: u64, n_dofs: usize) -> Result<()> {
        let (records, whole) = self.records();
        let problem = if self.n != n_dofs {
            Some(format!("{} dofs per state, the model has {n_dofs}", self.n))
        } else if !whole {
            Some("its last record is cut short (truncated)".to_string())
        } else if records != states {
            Some(format!(
                "{records} states, the completed run recorded {states} (truncated or from another run)"
            ))
        } else {
            None
        };
        match problem {
            Some(p) => Err(Error::io(&self.path, std::io::Error::other(p))),
            None => Ok(()),
        }
    }

    /// Dofs per state.
    pub fn dofs(&self) -> usize {
        self.n
    }

    /// The next state into `u` (resized to the dof count); its time, or `None` at
    /// the end of the file. A truncated last record (a run killed mid-write) ends
    /// the stream.
    pub fn next_into(&mut self, u: &mut Vec<f64>) -> Result<Option<f64>> {
        match self.input.read_exact(&mut self.buf) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
            Err(e) => return Err(Error::io(&self.path, e)),
        }
        let word = |k: usize| f64::from_le_bytes(self.buf[8 * k..8 * k + 8].try_into().expect("8"));
        u.clear();
        u.extend((1..=self.n).map(word));
        Ok(Some(word(0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_round_trip_and_a_truncated_record_ends_the_stream() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fields.bin");
        let mut w = FieldWriter::create(&path, 3).unwrap();
        w.append(0.0, &[1.0, 2.0, 3.0]).unwrap();
        w.append(0.5, &[-1.0, f64::NAN, 1e-300]).unwrap();
        drop(w);
        // A half-written third record.
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(&[0u8; 12]).unwrap();
        let mut r = FieldReader::open(&path).unwrap();
        assert_eq!(r.dofs(), 3);
        let mut u = Vec::new();
        assert_eq!(r.next_into(&mut u).unwrap(), Some(0.0));
        assert_eq!(u, [1.0, 2.0, 3.0]);
        assert_eq!(r.next_into(&mut u).unwrap(), Some(0.5));
        assert!(u[1].is_nan() && u[2] == 1e-300);
        assert_eq!(r.next_into(&mut u).unwrap(), None);
        // For a completed run the cut record, a missing state and another mesh are
        // errors.
        assert_eq!(r.records(), (2, false));
        let e = r.expect(2, 3).unwrap_err().to_string();
        assert!(e.contains("cut short"), "{e}");
        let mut w = FieldWriter::create(&path, 3).unwrap();
        w.append(0.0, &[1.0, 2.0, 3.0]).unwrap();
        drop(w);
        let r = FieldReader::open(&path).unwrap();
        assert!(r.expect(1, 3).is_ok());
        let e = r.expect(2, 3).unwrap_err().to_string();
        assert!(e.contains("1 states, the completed run recorded 2"), "{e}");
        let e = r.expect(1, 4).unwrap_err().to_string();
        assert!(e.contains("3 dofs per state, the model has 4"), "{e}");
        std::fs::write(&path, b"not a fields file").unwrap();
        assert!(FieldReader::open(&path).is_err());
    }
}
