//! Gauss-point storage: committed and trial history, committed strain.

/// Per-Gauss-point history, committed and trial, for one element block.
#[derive(Clone, Debug, Default)]
pub struct StateStore {
    /// History values per point.
    pub n_state: usize,
    /// Committed history (`n_points * n_state`).
    pub committed: Vec<f64>,
    /// Trial history of the step being solved.
    pub trial: Vec<f64>,
    /// Committed strain per point (`n_points * 3`).
    pub eps: Vec<f64>,
    /// Trial strain per point.
    pub eps_trial: Vec<f64>,
    /// Committed stress per point (`n_points * 3`).
    pub sigma: Vec<f64>,
    /// Trial stress per point.
    pub sigma_trial: Vec<f64>,
    /// Committed cumulative dissipation density (viscous + damage + plastic) per point.
    pub dissipated: Vec<f64>,
    /// Trial cumulative dissipation density.
    pub dissipated_trial: Vec<f64>,
}

impl StateStore {
    /// Storage for `n_points` points with `n_state` values each, all zero.
    pub fn new(n_points: usize, n_state: usize) -> Self {
        StateStore {
            n_state,
            committed: vec![0.0; n_points * n_state],
            trial: vec![0.0; n_points * n_state],
            eps: vec![0.0; n_points * 3],
            eps_trial: vec![0.0; n_points * 3],
            sigma: vec![0.0; n_points * 3],
            sigma_trial: vec![0.0; n_points * 3],
            dissipated: vec![0.0; n_points],
            dissipated_trial: vec![0.0; n_points],
        }
    }

    /// Accepts the step: trial becomes committed. The buffers are swapped, not
    /// copied: every evaluation rewrites all trial entries before they are read.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.trial);
        std::mem::swap(&mut self.eps, &mut self.eps_trial);
        std::mem::swap(&mut self.sigma, &mut self.sigma_trial);
        std::mem::swap(&mut self.dissipated, &mut self.dissipated_trial);
    }

    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.eps.len() / 3
    }
}
