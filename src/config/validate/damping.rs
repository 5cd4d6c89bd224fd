//! `analysis.damping`: Rayleigh's pair from a damping ratio at two frequencies,
//! given or computed as modes (`theory/modal.md`).

use crate::config::AnalysisSpec;
use crate::error::{Error, Result};
use crate::model::{Damping, Model};

/// Rayleigh's pair: `analysis.rayleigh` as given, or from `analysis.damping`'s
/// ratio at two frequencies (given; by modes, set once the model is built,
/// [`modal_targets`]).
pub(super) fn targets(
    a: &AnalysisSpec,
) -> Result<([f64; 2], Option<crate::model::RayleighTargets>)> {
    let Some(d) = &a.damping else {
        return Ok((a.rayleigh, None));
    };
    if a.rayleigh != [0.0, 0.0] {
        return Err(Error::config(
            "analysis.damping",
            "give Rayleigh's pair either as `rayleigh = [a_m, a_k]` or from targets as \
             `damping = { ratio, frequencies }`, not both",
        ));
    }
    if !(d.ratio.is_finite() && d.ratio >= 0.0 && d.ratio < 1.0) {
        return Err(Error::config(
            "analysis.damping.ratio",
            format!(
                "{}: a damping ratio lies in [0, 1) (0.02 is two percent)",
                d.ratio
            ),
        ));
    }
    match (d.frequencies, d.modes) {
        (Some(f), None) => {
            for (k, &fk) in f.iter().enumerate() {
                if !(fk.is_finite() && fk > 0.0) {
                    return Err(Error::config(
                        format!("analysis.damping.frequencies[{k}]"),
                        format!("{fk}: a frequency (Hz) must be positive"),
                    ));
                }
            }
            let w = f.map(|x| 2.0 * std::f64::consts::PI * x);
            Ok((Damping::rayleigh_for(d.ratio, w), Some((d.ratio, w))))
        }
        (None, Some(m)) => {
            if m.contains(&0) {
                return Err(Error::config(
                    "analysis.damping.modes",
                    "modes are numbered from 1 (the lowest)",
                ));
            }
            Ok(([0.0, 0.0], None))
        }
        _ => Err(Error::config(
            "analysis.damping",
            "give exactly one of `frequencies = [f1, f2]` (Hz) and `modes = [i, j]`",
        )),
    }
}

/// Sets Rayleigh's pair from the ratio `xi` at modes `modes` (numbers from 1),
/// computed by [`crate::modal::modes`] on the built model.
pub(super) fn modal_targets(model: &mut Model, xi: f64, modes: [usize; 2]) -> Result<()> {
    let count = modes[0].max(modes[1]);
    let found = crate::modal::modes(
        model,
        &crate::modal::ModalOptions {
            count,
            backend: crate::linsolve::Backend::Faer,
            ..Default::default()
        },
    )
    .map_err(|e| Error::config("analysis.damping.modes", e.to_string()))?;
    let mut w = [0.0; 2];
    for (k, &i) in modes.iter().enumerate() {
        let m = &found.modes[i - 1];
        if m.rigid {
            return Err(Error::config(
                format!("analysis.damping.modes[{k}]"),
                format!("mode {i} is a rigid-body mode: it has no frequency to damp at"),
            ));
        }
        w[k] = m.omega();
    }
    model.analysis.damping.rayleigh = Damping::rayleigh_for(xi, w);
    model.analysis.damping.targets = Some((xi, w));
    Ok(())
}
