//! Gauss-point storage of one element block: committed and trial states.
//!
//! Each state is one buffer laid out as `[ε (v per point) | σ (v per point) |
//! cumulative dissipation density (1 per point) | history (n_state per point)]`,
//! `v` the Voigt size (3 in the plane, 6 in a solid). The
//! Gauss-point loop writes a whole trial state through one base pointer (see
//! `assembly::internal`); accepting a step swaps the two buffers, so a commit copies
//! nothing and no pass allocates. Every evaluation rewrites all trial entries before
//! they are read.

/// Per-Gauss-point state, committed and trial, for one element block.
#[derive(Clone, Debug, Default)]
pub struct StateStore {
    n_points: usize,
    n_state: usize,
    voigt: usize,
    committed: Vec<f64>,
    trial: Vec<f64>,
}

/// Offsets of the parts of a state buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Points in the block.
    pub n_points: usize,
    /// History values per point.
    pub n_state: usize,
    /// Strain and stress components per point.
    pub voigt: usize,
}

impl Layout {
    /// Start of the strains.
    pub fn eps(&self) -> usize {
        0
    }
    /// Start of the stresses.
    pub fn sigma(&self) -> usize {
        self.voigt * self.n_points
    }
    /// Start of the cumulative dissipation densities.
    pub fn dissipated(&self) -> usize {
        2 * self.voigt * self.n_points
    }
    /// Start of the history values.
    pub fn history(&self) -> usize {
        (2 * self.voigt + 1) * self.n_points
    }
    /// Length of a state buffer.
    pub fn len(&self) -> usize {
        (2 * self.voigt + 1 + self.n_state) * self.n_points
    }
    /// True for a block without points.
    pub fn is_empty(&self) -> bool {
        self.n_points == 0
    }
}

impl StateStore {
    /// Storage for `n_points` points of `voigt` strain components with `n_state`
    /// history values each, all zero.
    pub fn new(n_points: usize, n_state: usize, voigt: usize) -> Self {
        let len = Layout {
            n_points,
            n_state,
            voigt,
        }
        .len();
        StateStore {
            n_points,
            n_state,
            voigt,
            committed: crate::buffers::zeroed(len),
            trial: crate::buffers::zeroed(len),
        }
    }

    /// The buffer layout.
    pub fn layout(&self) -> Layout {
        Layout {
            n_points: self.n_points,
            n_state: self.n_state,
            voigt: self.voigt,
        }
    }

    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.n_points
    }

    /// History values per point.
    pub fn n_state(&self) -> usize {
        self.n_state
    }

    /// The committed state.
    pub fn committed(&self) -> Committed<'_> {
        Committed {
            layout: self.layout(),
            data: &self.committed,
        }
    }

    /// The committed state of the last evaluation's trial buffer (for inspecting a
    /// step before it is accepted).
    pub fn trial(&self) -> Committed<'_> {
        Committed {
            layout: self.layout(),
            data: &self.trial,
        }
    }

    /// Committed history of point `g`, for setting an initial state.
    pub fn history_mut(&mut self, g: usize) -> &mut [f64] {
        let o = self.layout().history() + g * self.n_state;
        &mut self.committed[o..o + self.n_state]
    }

    /// The committed state for reading and the trial buffer for writing, at once
    /// (the Gauss-point loop reads one and writes the other).
    pub fn split(&mut self) -> (Committed<'_>, &mut [f64]) {
        (
            Committed {
                layout: self.layout(),
                data: &self.committed,
            },
            &mut self.trial,
        )
    }

    /// Makes the trial state the committed one.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.trial);
    }

    /// Sets the committed strain, stress, cumulative dissipation density and history
    /// of point `g` (a state built from other fields, as for output).
    pub fn set_committed(
        &mut self,
        g: usize,
        eps: &[f64],
        sigma: &[f64],
        dissipated: f64,
        history: &[f64],
    ) {
        let l = self.layout();
        let v = l.voigt;
        self.committed[l.eps() + v * g..l.eps() + v * g + v].copy_from_slice(&eps[..v]);
        self.committed[l.sigma() + v * g..l.sigma() + v * g + v].copy_from_slice(&sigma[..v]);
        self.committed[l.dissipated() + g] = dissipated;
        let o = l.history() + g * self.n_state;
        self.committed[o..o + history.len()].copy_from_slice(history);
    }

    /// Copies the committed state into the trial buffer (after setting an initial
    /// state by hand).
    pub fn reset_trial(&mut self) {
        self.trial.copy_from_slice(&self.committed);
    }
}

/// Read access to one state buffer of a [`StateStore`].
#[derive(Clone, Copy, Debug)]
pub struct Committed<'a> {
    layout: Layout,
    data: &'a [f64],
}

impl Committed<'_> {
    /// Strain of point `g` (`V` the store's Voigt size).
    #[inline]
    pub fn eps<const V: usize>(&self, g: usize) -> [f64; V] {
        let o = V * g;
        std::array::from_fn(|i| self.data[o + i])
    }

    /// Stress of point `g` (`V` the store's Voigt size).
    #[inline]
    pub fn sigma<const V: usize>(&self, g: usize) -> [f64; V] {
        let o = self.layout.sigma() + V * g;
        std::array::from_fn(|i| self.data[o + i])
    }

    /// Stress of point `g` in the Voigt order of `fe`, padded to six components.
    pub fn sigma6(&self, g: usize) -> [f64; 6] {
        let v = self.layout.voigt;
        let o = self.layout.sigma() + v * g;
        std::array::from_fn(|i| if i < v { self.data[o + i] } else { 0.0 })
    }

    /// Cumulative dissipation density (viscous + damage + plastic, J/m³) of point `g`.
    #[inline]
    pub fn dissipated(&self, g: usize) -> f64 {
        self.data[self.layout.dissipated() + g]
    }

    /// History of point `g`.
    #[inline]
    pub fn history(&self, g: usize) -> &[f64] {
        let o = self.layout.history() + g * self.layout.n_state;
        &self.data[o..o + self.layout.n_state]
    }

    /// Number of points.
    pub fn n_points(&self) -> usize {
        self.layout.n_points
    }

    /// The buffer layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }
}
