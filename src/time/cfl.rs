//! The explicit (central difference) critical step, for `rothe check` and the explicit
//! path: `Δt = ω min_e L_e / c_e` with the dilatational wave speed
//! `c = sqrt(E(1−ν) / (ρ(1+ν)(1−2ν)))` of the paper's formula (ω = 1 here), and
//! `c = sqrt(E/ρ)` for bars.

use crate::mesh::ElementKind;
use crate::model::Model;

/// Critical step and the block/element that sets it.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CriticalStep {
    /// `min L_e / c_e`.
    pub dt: f64,
    /// Block index of the limiting element.
    pub block: usize,
    /// Element index within the block.
    pub element: usize,
}

/// Critical explicit step of the model's mesh.
pub fn critical_step(model: &Model) -> Option<CriticalStep> {
    let mut best: Option<CriticalStep> = None;
    for (bi, b) in model.mesh.blocks.iter().enumerate() {
        let m = &model.materials[b.material];
        let c = match b.elements.kind {
            ElementKind::Bar2 => (m.e / m.rho).sqrt(),
            _ => (m.e * (1.0 - m.nu) / (m.rho * (1.0 + m.nu) * (1.0 - 2.0 * m.nu))).sqrt(),
        };
        for e in 0..b.elements.len() {
            let dt = model.mesh.element_length(bi, e) / c;
            if best.is_none_or(|s| dt < s.dt) {
                best = Some(CriticalStep {
                    dt,
                    block: bi,
                    element: e,
                });
            }
        }
    }
    best
}
