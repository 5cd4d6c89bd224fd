//! Contact detection: geometry only, one loop over the pairs, their sides and their
//! slaves for every master ([`super::master`]) and both dimensions.
//!
//! [`detect`] gives, for every direction of every pair, the slave nodes near the
//! master surface, each with its row against its master in the current geometry
//! (the closest segment or face, the point on it, the gap along the master's outward
//! normal and that normal; a mortar side's weighted gaps, [`super::mortar`]).
//! [`crossed`] adds the slaves whose motion over a step carried them through a
//! master farther than that search reaches (theory/contact.md, "Nothing crosses
//! unseen"; theory/contact3d.md).

use super::master::face_tree::KeptFaces;
use super::master::faces::FaceSurface;
use super::master::{self, rigid::EdgeHistory, MasterSurface, Positions};
use super::rows::Candidate;
use super::state::Slave;
use crate::mesh::Face;
use crate::model::{ContactPair, Formulation, Master, SlaveSurface};

/// How far (in units of a pair's search radius) a face master's nodes may move
/// before the tree detection keeps of it is built again ([`KeptFaces`]): a tenth.
/// The boxes grow by as much, so a query meets a few more faces; in persistent
/// contact the tree then lasts the run.
pub const KEPT_MARGIN: f64 = 0.1;

/// What detection keeps from one evaluation to the next: the tree and topology of
/// every side with a face master ([`KeptFaces`]), by side in pair order.
#[derive(Default)]
pub struct Kept {
    sides: Vec<Option<KeptFaces>>,
}

impl Kept {
    /// The kept tree of side `index` (pair order) with the master `faces`, made at
    /// `x` (its margin a [`KEPT_MARGIN`] of `radius`) or refreshed for it.
    fn refreshed(&mut self, index: usize, faces: &[Face], x: Positions, radius: f64) -> &KeptFaces {
        if self.sides.len() <= index {
            self.sides.resize_with(index + 1, || None);
        }
        let slot = &mut self.sides[index];
        match slot {
            Some(t) => t.refresh(faces, x),
            None => *slot = Some(KeptFaces::new(faces, x, KEPT_MARGIN * radius)),
        }
        slot.as_ref().expect("set just above")
    }
}

/// Candidates of every pair at the geometry `x`, appended to `out` (cleared first),
/// ordered by pair, side and slave node (a slave in a notch or a valley gives one per
/// facet holding it, by facet). `rigid`: what the committed state knows of the rigid
/// lines' slaves; `kept`: what detection keeps across evaluations, if anything (the
/// same candidates either way).
pub fn detect(
    pairs: &[ContactPair],
    x: Positions,
    rigid: &EdgeHistory,
    mut kept: Option<&mut Kept>,
    out: &mut Vec<Candidate>,
) {
    out.clear();
    let mut side_index = 0;
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            side_index += 1;
            let kept_faces = match (kept.as_deref_mut(), &side.master) {
                (Some(k), Master::Faces { faces, .. }) => {
                    Some(k.refreshed(side_index - 1, faces, x, pair.radius))
                }
                _ => None,
            };
            if pair.formulation == Formulation::Mortar {
                // Rows are sized for the initial geometry (validation); a mesh sliding
                // far enough to bring more master nodes under one slave node keeps
                // the first `ROW_NODES`.
                match (&side.surface, &side.master) {
                    (SlaveSurface::Segments(slave_segments), Master::Segments(segments)) => {
                        super::mortar::segment_rows(
                            (pi, si),
                            &side.slaves,
                            slave_segments,
                            segments,
                            pair.radius,
                            pair.mortar_basis,
                            &|n| x.at::<2>(n),
                            out,
                        );
                        continue;
                    }
                    (SlaveSurface::Faces(slave_faces), Master::Faces { faces, .. }) => {
                        let fresh;
                        let tree = match kept_faces {
                            Some(t) => t,
                            None => {
                                fresh = KeptFaces::new(faces, x, KEPT_MARGIN * pair.radius);
                                &fresh
                            }
                        };
                        super::mortar::face_rows(
                            (pi, si),
                            &side.slaves,
                            slave_faces,
                            faces,
                            tree,
                            pair.radius,
                            pair.mortar_basis,
                            x,
                            out,
                        );
                        continue;
                    }
                    _ => {}
                }
            }
            let surface: Box<dyn MasterSurface + '_> = match (kept_faces, &side.master) {
                (Some(k), Master::Faces { faces, boundary }) => {
                    Box::new(FaceSurface::new(faces, boundary, x).kept(k))
                }
                _ => master::surface(side, x),
            };
            for &s in &side.slaves {
                surface.detect(Slave::new(pi, si, s), pair.radius, rigid, out);
            }
        }
    }
}

/// Whether slave `key` has a candidate among `found` (ordered by slave key: a binary
/// search, no set built on this per-iteration path).
fn known(found: &[Candidate], key: Slave) -> bool {
    found
        .binary_search_by_key(&key, Candidate::slave_key)
        .is_ok()
}

/// Slaves whose motion over the step, from the geometry `x0` to `x1`, crosses a
/// master the search at `x1` does not reach (the slave and the master moved farther
/// relative to each other than the pair's radius, as at very high speed), appended
/// to `out` as candidates at `x1` (their gap negative: behind the master), so that
/// nothing passes through a master unseen. A deformable master is swept with the
/// explicit path's collision times (the motion over the step taken as linear), and
/// only for the slaves that moved, relative to it, more than half the pair's radius:
/// those the radius search may have missed; a rigid one by the gap falling below
/// zero over the step (within a line's ends, not for a slave that started behind a
/// line). Slaves that already have a candidate in `out` are skipped. `out` stays
/// ordered by pair, side and slave.
pub fn crossed(
    pairs: &[ContactPair],
    x0: Positions,
    x1: Positions,
    rigid: &EdgeHistory,
    out: &mut Vec<Candidate>,
) {
    let before = out.len();
    let travel = |n: usize| x0.distance(&x1, n);
    for (pi, pair) in pairs.iter().enumerate() {
        for (si, side) in pair.sides.iter().enumerate() {
            let surface = master::surface(side, x1);
            let master_travel = surface
                .nodes()
                .map(|nodes| nodes.into_iter().map(travel).fold(0.0, f64::max));
            let movers: Vec<Slave> = side
                .slaves
                .iter()
                .map(|&s| Slave::new(pi, si, s))
                .filter(|&s| {
                    master_travel.is_none_or(|m| travel(s.node) + m > 0.5 * pair.radius)
                        && !known(&out[..before], s)
                })
                .collect();
            for s in movers {
                out.extend(surface.crossing(s, x0, rigid));
            }
        }
    }
    if out.len() > before {
        out.sort_by_key(Candidate::slave_key);
    }
}
