//! The contact state a step leaves, shared by both paths: the multipliers by key
//! (the implicit path's first guess of the next step), the per-pair record that
//! `history.csv` and `summary.json` read, and the nodal fields of the VTK output
//! (gap, pressure, friction traction, slip path).

use crate::model::Model;

/// A slave node of one side of a pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Slave {
    /// Pair index.
    pub pair: usize,
    /// Direction within the pair.
    pub side: usize,
    /// The slave node.
    pub node: usize,
}

impl Slave {
    /// The slave `node` of side `side` of pair `pair`.
    pub fn new(pair: usize, side: usize, node: usize) -> Slave {
        Slave { pair, side, node }
    }
}

/// What a constraint's slave node meets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Target {
    /// Facet `k` (segment or face) of the side's deformable master.
    Facet(usize),
    /// The master surface as mortar sees it: the node's weighted gap.
    Mortar,
    /// The side's rigid line or plane.
    Rigid,
}

/// Key of a constraint across re-linearisations: its slave and what it meets
/// (`rows::Candidate::key`), ordered by pair, side, slave node, then target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Key {
    /// The slave node.
    pub slave: Slave,
    /// What it meets.
    pub target: Target,
}

/// One pair's contact at the end of a step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PairRecord {
    /// Total normal force `Σ λ` (N).
    pub force: f64,
    /// Active constraints (nodes pressed against the master).
    pub active: usize,
    /// Largest penetration (m), zero when none.
    pub penetration: f64,
    /// Total tangential (friction) force `Σ λ_T` on the slaves, along each row's
    /// tangent (N).
    pub tangential_force: f64,
    /// Total magnitude of the tangential forces `Σ |λ_T|` (N): the net force above
    /// cancels where a symmetric body slides outwards on both sides.
    pub tangential_magnitude: f64,
    /// Pressed nodes of a frictional pair that stick (`|λ_T| < μ λ_N`).
    pub sticking: usize,
    /// Pressed nodes of a frictional pair that slip (on the cone).
    pub slipping: usize,
    /// The longest slip path of a pressed node of the pair so far (m).
    pub max_slip: f64,
}

/// The contact state a step leaves: kept in `time::State`, so a cut-back restores
/// it with the rest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ContactState {
    /// The positive multipliers (N), by key (the active constraints are those above
    /// a millionth of the largest).
    pub active: Vec<(Key, f64)>,
    /// Per pair.
    pub pairs: Vec<PairRecord>,
    /// Gap at each node (m); NaN where the node is no candidate.
    pub gap: Vec<f64>,
    /// Contact pressure at each node (Pa): its force over its tributary area.
    pub pressure: Vec<f64>,
    /// The tangential multipliers (N) of the frictional rows, by key: along the
    /// row's tangent in the plane (the second zero), along its two tangents in a
    /// solid.
    pub tangential: Vec<(Key, [f64; 2])>,
    /// Tangential traction at each node (Pa), along its row's tangent.
    pub traction: Vec<f64>,
    /// Slip path of each node (m): the sum of the magnitudes of its relative
    /// tangential displacement over the steps it was pressed in.
    pub slip: Vec<f64>,
}

impl ContactState {
    /// The state at the start of a run: no forces, the gaps of the initial geometry
    /// (displacements `u`).
    pub fn initial(model: &Model, u: &[f64]) -> ContactState {
        let mut out = ContactState {
            pairs: vec![PairRecord::default(); model.contacts.len()],
            ..Default::default()
        };
        if model.contacts.is_empty() {
            return out;
        }
        let mut cands = Vec::new();
        super::candidates(model, u, &mut cands);
        out.gap = vec![f64::NAN; model.mesh.n_nodes()];
        out.pressure = vec![0.0; model.mesh.n_nodes()];
        for c in &cands {
            let g = &mut out.gap[c.slave];
            *g = if g.is_nan() { c.gap } else { g.min(c.gap) };
            let rec = &mut out.pairs[c.pair];
            rec.penetration = rec.penetration.max(-c.gap);
        }
        out
    }
}
