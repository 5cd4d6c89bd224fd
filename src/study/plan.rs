//! What a sweep runs: a [`Plan`] of independent runs, each a scenario with its
//! overrides and its own output directory, kept as `plan.json` in the study's
//! directory. The in-process sweep runs it ([`super::sweep()`]); `--emit` writes it out
//! as shell commands and a Slurm job-array script instead, and `rothe study collect`
//! reads the same `plan.json` back, so both ways give the same tables.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::config::Overrides;
use crate::error::{Error, Result};

/// What the sweep studies (how `collect` tabulates it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StudyKind {
    /// The same scenario for a sequence of time steps.
    Time,
    /// The same scenario for a sequence of mesh sizes.
    Mesh,
    /// The same scenario through the implicit and the explicit path.
    Compare,
    /// The paper's benchmarks: every model and mesh.
    Report,
    /// An error-controlled scenario at a sequence of tolerances, beside fixed steps.
    Tolerance,
}

/// One run of a sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannedRun {
    /// Directory name under `runs/`, unique in the plan.
    pub id: String,
    /// Scenario file (absolute).
    pub scenario: PathBuf,
    /// Its overrides.
    pub overrides: Overrides,
    /// The studied parameter: the step `h` (time), the mesh size (mesh), 0 or 1
    /// (compare: implicit, explicit).
    pub param: f64,
    /// A label for tables and legends (`h = 2.5e-6 s`, `mazars, 0.1 m`).
    pub label: String,
    /// Also write `fields.bin` (the time study's norms need it).
    pub record_fields: bool,
}

/// Checks a list of mesh sizes given for `flag`: finite and positive, at most
/// [`MAX_SIZES`] of them, and not empty when `needed`.
pub fn check_sizes(flag: &str, sizes: &[f64], needed: bool) -> Result<()> {
    if needed && sizes.is_empty() {
        return Err(Error::config(flag, "give at least one size (m)"));
    }
    if sizes.len() > MAX_SIZES {
        return Err(Error::config(
            flag,
            format!("{} sizes: at most {MAX_SIZES}", sizes.len()),
        ));
    }
    if let Some(s) = sizes.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::config(
            flag,
            format!("sizes must be positive lengths (m), got {s} in {sizes:?}"),
        ));
    }
    Ok(())
}

/// Most sizes a mesh list of a study may hold.
pub const MAX_SIZES: usize = 32;

/// Most runs a plan may hold.
pub const MAX_RUNS: usize = 1000;

/// A sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Kind.
    pub kind: StudyKind,
    /// The runs.
    pub runs: Vec<PlannedRun>,
}

impl Plan {
    /// Reads `dir/plan.json`.
    pub fn read(dir: &Path) -> Result<Plan> {
        let path = dir.join("plan.json");
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        serde_json::from_str(&text).map_err(|e| {
            Error::io(
                &path,
                std::io::Error::other(format!("not a study plan: {e}")),
            )
        })
    }

    /// Writes `dir/plan.json` (creating `dir`).
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let path = dir.join("plan.json");
        let text = serde_json::to_string_pretty(self).expect("a plan serialises");
        std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
        Ok(path)
    }

    /// Checks the plan before anything runs: it has runs, at most [`MAX_RUNS`]; every
    /// run's scenario loads with its overrides (an error names the run); and the
    /// plan's total steps and output stay within the limits `check` warns at
    /// ([`crate::config::HUGE_STEPS`], [`crate::check::HUGE_OUTPUT`]), so a study
    /// with a mistyped size or halving count is refused instead of started.
    /// Returns the total `(steps, output bytes)`.
    pub fn preflight(&self) -> Result<(usize, u64)> {
        if self.runs.is_empty() {
            return Err(Error::config("plan", "has no runs"));
        }
        if self.runs.len() > MAX_RUNS {
            return Err(Error::config(
                "plan",
                format!(
                    "{} runs: more than {MAX_RUNS}; is a count or a list of sizes mistyped?",
                    self.runs.len()
                ),
            ));
        }
        let (mut steps, mut bytes) = (0usize, 0u64);
        for r in &self.runs {
            let model = crate::config::load_with_overrides(
                &r.scenario,
                &crate::config::LoadOptions::default(),
                &r.overrides,
            )
            .map_err(|e| Error::config(format!("run {} ({})", r.id, r.label), e.to_string()))?;
            let v = crate::check::volume(&model);
            let fields = if r.record_fields {
                (model.analysis.n_steps() as u64 + 1) * (model.mesh.n_dofs() as u64 + 1) * 8
            } else {
                0
            };
            steps = steps.saturating_add(model.analysis.n_steps());
            bytes = bytes.saturating_add(v.history.1 + v.vtk.1 + fields);
        }
        if steps >= crate::config::HUGE_STEPS {
            return Err(Error::config(
                "plan",
                format!(
                    "{} runs take {steps} steps in all, past the {} a check calls runaway; \
                     fewer halvings or coarser steps?",
                    self.runs.len(),
                    crate::config::HUGE_STEPS
                ),
            ));
        }
        if bytes >= crate::check::HUGE_OUTPUT {
            return Err(Error::config(
                "plan",
                format!(
                    "{} runs would write about {:.1} GB in all (history, VTK, fields): raise \
                     vtk_every or plan fewer runs",
                    self.runs.len(),
                    bytes as f64 / 1e9
                ),
            ));
        }
        Ok((steps, bytes))
    }

    /// The output directory of a run.
    pub fn run_dir(dir: &Path, run: &PlannedRun) -> PathBuf {
        dir.join("runs").join(&run.id)
    }

    /// The `rothe run` command line of each run (arguments quoted for a POSIX
    /// shell), the binary called `rothe`.
    pub fn commands(&self, dir: &Path) -> Vec<String> {
        self.runs
            .iter()
            .map(|r| {
                let mut args = vec![
                    "rothe".to_string(),
                    "run".into(),
                    r.scenario.display().to_string(),
                ];
                args.extend(r.overrides.to_args());
                args.push("--out".into());
                args.push(Self::run_dir(dir, r).display().to_string());
                args.push("--quiet".into());
                args.push("--overwrite".into());
                if r.record_fields {
                    args.push("--record-fields".into());
                }
                args.iter().map(|a| quote(a)).collect::<Vec<_>>().join(" ")
            })
            .collect()
    }

    /// Writes `plan.json`, `runs.txt` (one command per line) and `slurm.sh` (a job
    /// array, one task per line of `runs.txt`) into `dir`; returns the files.
    pub fn emit(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let dir = absolute(dir)?;
        let plan = self.write(&dir)?;
        let runs = dir.join("runs.txt");
        let mut text = self.commands(&dir).join("\n");
        text.push('\n');
        std::fs::write(&runs, text).map_err(|e| Error::io(&runs, e))?;
        let slurm = dir.join("slurm.sh");
        let script = format!(
            "#!/bin/bash\n\
             # A Slurm job array running the {n} runs of this study, one per task.\n\
             # Submit:  sbatch slurm.sh    (then: rothe study collect {d})\n\
             # Set ROTHE to the rothe binary if it is not on PATH.\n\
             #SBATCH --job-name=rothe-study\n\
             #SBATCH --array=1-{n}\n\
             #SBATCH --cpus-per-task=1\n\
             #SBATCH --output={d}/slurm-%A_%a.out\n\
             set -euo pipefail\n\
             ROTHE=\"${{ROTHE:-rothe}}\"\n\
             line=$(sed -n \"${{SLURM_ARRAY_TASK_ID}}p\" '{r}')\n\
             eval \"\\\"$ROTHE\\\"${{line#rothe}}\"\n",
            n = self.runs.len(),
            d = dir.display(),
            r = runs.display(),
        );
        std::fs::write(&slurm, script).map_err(|e| Error::io(&slurm, e))?;
        Ok(vec![plan, runs, slurm])
    }
}

/// `path` made absolute against the current directory (the emitted commands run
/// from anywhere).
pub fn absolute(path: &Path) -> Result<PathBuf> {
    if path.is_absolute() {
        return Ok(path.to_path_buf());
    }
    let cwd = std::env::current_dir().map_err(|e| Error::io(path, e))?;
    Ok(cwd.join(path))
}

/// Quotes one argument for a POSIX shell when it needs it.
fn quote(arg: &str) -> String {
    let plain = arg
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain && !arg.is_empty() {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_quote_what_the_shell_would_split() {
        let plan = Plan {
            kind: StudyKind::Time,
            runs: vec![PlannedRun {
                id: "h0".into(),
                scenario: "/s/a b.toml".into(),
                overrides: Overrides::none()
                    .set("bodies.steel.velocity=[0.0, -1.0]")
                    .unwrap(),
                param: 1e-6,
                label: "h".into(),
                record_fields: true,
            }],
        };
        let c = &plan.commands(Path::new("/d"))[0];
        assert_eq!(
            c,
            "rothe run '/s/a b.toml' --set 'bodies.steel.velocity=[0.0, -1.0]' --out /d/runs/h0 --quiet --overwrite --record-fields"
        );
        let dir = tempfile::tempdir().unwrap();
        plan.emit(dir.path()).unwrap();
        assert_eq!(Plan::read(dir.path()).unwrap(), plan);
        let slurm = std::fs::read_to_string(dir.path().join("slurm.sh")).unwrap();
        assert!(slurm.contains("#SBATCH --array=1-1"));
    }
}
