//! Nonlocal integral averaging of the damage drivers (Pijaudier-Cabot and Bažant).
//!
//! A nonlocal material's drivers ([`crate::material::Constitutive::drivers`]: Mazars'
//! equivalent strains)
//! are replaced, where they drive the damage, by their average over the Gauss points
//! of the same body within the interaction radius `R`:
//!
//! `ε̄_i = Σ_j α_ij ε_j`,  `α_ij = w(r_ij) V_j / Σ_k w(r_ik) V_k`,  `w(r) = (1 − r²/R²)²`
//!
//! (`V_j` the point's integration volume `w_q det J t`, `w_q det J` in a solid;
//! distances in the mesh's dimension, plane points at `z = 0`). The weights are normalised
//! per point, so a uniform field averages to itself, at a boundary too. The table of
//! neighbours and weights depends on the reference geometry only: it is built once
//! per mesh with an R-tree (`rstar`) and kept ([`NonlocalTable`]); each pass then
//! evaluates the drivers at every point of a nonlocal block ([`NonlocalTable`]'s
//! `local` input) and averages them, each point's row summed in one fixed order on
//! one thread, so the averages repeat to the last bit on any pool. Theory:
//! `theory/damage.md`, "Nonlocal averaging".

use rayon::prelude::*;
use rstar::primitives::GeomWithData;
use rstar::RTree;

use crate::fe::{
    kinematics, kinematics_from, rule_shapes, stiffness_rule, ElementKind, Kinematics,
};
use crate::material::store::StateStore;
use crate::material::{Material, MAX_DRIVERS};
use crate::mesh::Mesh;

/// Drivers per point in the buffers: every nonlocal model's
/// ([`crate::material::Constitutive::drivers`]; Mazars: `[ε_t, ε_c]` or `[ε̃, 0]`),
/// unused ones zero.
pub const DRIVERS: usize = MAX_DRIVERS;

/// An R-tree of member points (their member numbers as data).
type PointTree = RTree<GeomWithData<[f64; 3], u32>>;

/// Points per leaf of the parallel passes.
const POINT_LEAF: usize = 256;

/// The neighbour table of every nonlocal block: for each of their Gauss points (the
/// "members", numbered block after block), the members of the same body within the
/// material's radius and their normalised weights, in ascending member order.
#[derive(Clone, Debug, PartialEq)]
pub struct NonlocalTable {
    /// Per block: the number of its first member when its material is nonlocal.
    offsets: Vec<Option<usize>>,
    /// Per block: the radius the table was built with (to know it still fits).
    radii: Vec<Option<f64>>,
    /// Member coordinates (`z = 0` in the plane).
    points: Vec<[f64; 3]>,
    /// Row starts (members + 1).
    row_ptr: Vec<usize>,
    /// Neighbour members.
    cols: Vec<u32>,
    /// Normalised weights `α_ij`.
    weights: Vec<f64>,
    /// The bucket grid that bounds the averages: origin, cell size and cells along
    /// x, y and z (one layer in the plane).
    grid: ([f64; 3], f64, [usize; 3]),
    /// Per member: its bucket.
    bucket: Vec<u32>,
    /// Per member: how many buckets its radius reaches in each direction.
    reach: Vec<u8>,
    /// Per member: its block.
    block: Vec<u32>,
}

/// A Gauss point of a continuum element: its position and integration volume.
fn point_geometry(mesh: &Mesh, bi: usize, e: usize, q: usize) -> ([f64; 3], f64) {
    let block = &mesh.blocks[bi];
    let kind = block.elements.kind;
    let nodes = block.elements.element(e);
    let x = super::element_coords(mesh, nodes);
    let (xi, wq) = stiffness_rule(kind)[q];
    let k = kinematics(kind, &x[..nodes.len()], xi);
    let mut p = [0.0; 3];
    for a in 0..nodes.len() {
        for d in 0..3 {
            p[d] += k.n[a] * x[a][d];
        }
    }
    (p, wq * k.det_j * block.section)
}

/// The radius of block `bi`'s material when it is nonlocal (continuum blocks only).
fn block_radius(mesh: &Mesh, materials: &[Material], bi: usize) -> Option<f64> {
    let b = &mesh.blocks[bi];
    if b.elements.kind == ElementKind::Bar2 {
        return None;
    }
    materials[b.material].nonlocal_radius()
}

/// The table's entries before it is built (for the memory estimate): its points
/// and the neighbours each point's radius reaches, counted with the same R-trees
/// the build queries, so a mesh refined where it matters (a notch) is counted as it
/// is, not at its mean density. Counting stops past `COUNT_CAP` entries (a table
/// beyond any machine), and a mean-density estimate beyond it is not counted at all.
pub fn estimated_entries(mesh: &Mesh, materials: &[Material]) -> (u64, u64) {
    let Some(m) = Members::of(mesh, materials) else {
        return (0, 0);
    };
    let n = m.points.len() as u64;
    let mean = mean_density_entries(mesh, materials);
    if mean > COUNT_CAP {
        return (n, mean);
    }
    let trees = m.trees();
    let counted = std::sync::atomic::AtomicU64::new(0);
    (0..m.points.len()).into_par_iter().for_each(|i| {
        if counted.load(std::sync::atomic::Ordering::Relaxed) > COUNT_CAP {
            return;
        }
        let (body, r) = m.owner[i];
        let tree = &trees.iter().find(|t| t.0 == body).expect("body tree").1;
        let k = tree.locate_within_distance(m.points[i], r * r).count() as u64;
        counted.fetch_add(k, std::sync::atomic::Ordering::Relaxed);
    });
    (n, counted.into_inner())
}

/// Entries past which [`estimated_entries`] stops counting: 2³³ (over 100 GB of
/// table), far beyond what any machine holds, so the memory check refuses anyway.
const COUNT_CAP: u64 = 1 << 33;

/// Per nonlocal block, its points times those a disc (a ball in a solid) of the
/// radius holds at the block's mean point density: the cheap bound that decides
/// whether counting is worth it.
fn mean_density_entries(mesh: &Mesh, materials: &[Material]) -> u64 {
    let mut entries = 0u64;
    for (bi, b) in mesh.blocks.iter().enumerate() {
        let Some(r) = block_radius(mesh, materials, bi) else {
            continue;
        };
        let n = (b.elements.len() * stiffness_rule(b.elements.kind).len()) as u64;
        let measure: f64 = (0..b.elements.len())
            .map(|e| mesh.element_area(bi, e))
            .sum();
        let reach = if b.elements.kind.dim() == 3 {
            4.0 / 3.0 * std::f64::consts::PI * r * r * r
        } else {
            std::f64::consts::PI * r * r
        };
        let per_point = (reach * n as f64 / measure.max(f64::MIN_POSITIVE)).clamp(1.0, n as f64);
        entries = entries.saturating_add((n as f64 * per_point) as u64);
    }
    entries
}

/// The members of every nonlocal block (their Gauss points, block after block).
struct Members {
    /// Per block: the radius of its material when nonlocal.
    radii: Vec<Option<f64>>,
    /// Per block: its first member.
    offsets: Vec<Option<usize>>,
    points: Vec<[f64; 3]>,
    volumes: Vec<f64>,
    /// Per member: its body and radius.
    owner: Vec<(usize, f64)>,
    /// Per member: its block.
    block: Vec<u32>,
}

impl Members {
    /// The members of `mesh`, or `None` when no material is nonlocal.
    fn of(mesh: &Mesh, materials: &[Material]) -> Option<Members> {
        let radii: Vec<Option<f64>> = (0..mesh.blocks.len())
            .map(|bi| block_radius(mesh, materials, bi))
            .collect();
        if radii.iter().all(Option::is_none) {
            return None;
        }
        let mut m = Members {
            offsets: vec![None; mesh.blocks.len()],
            radii,
            points: Vec::new(),
            volumes: Vec::new(),
            owner: Vec::new(),
            block: Vec::new(),
        };
        for (bi, b) in mesh.blocks.iter().enumerate() {
            let Some(r) = m.radii[bi] else { continue };
            m.offsets[bi] = Some(m.points.len());
            let ng = stiffness_rule(b.elements.kind).len();
            for e in 0..b.elements.len() {
                for q in 0..ng {
                    let (p, v) = point_geometry(mesh, bi, e, q);
                    m.points.push(p);
                    m.volumes.push(v);
                    m.owner.push((b.body, r));
                    m.block.push(bi as u32);
                }
            }
        }
        Some(m)
    }

    /// One R-tree per body over its members.
    fn trees(&self) -> Vec<(usize, PointTree)> {
        let mut bodies: Vec<usize> = self.owner.iter().map(|o| o.0).collect();
        bodies.sort_unstable();
        bodies.dedup();
        bodies
            .iter()
            .map(|&body| {
                let items = (0..self.points.len())
                    .filter(|&m| self.owner[m].0 == body)
                    .map(|m| GeomWithData::new(self.points[m], m as u32))
                    .collect();
                (body, RTree::bulk_load(items))
            })
            .collect()
    }
}

impl NonlocalTable {
    /// The table of `mesh` for `materials`, or `None` when no material is nonlocal.
    pub fn build(mesh: &Mesh, materials: &[Material]) -> Option<NonlocalTable> {
        let members = Members::of(mesh, materials)?;
        let trees = members.trees();
        let Members {
            radii,
            offsets,
            points,
            volumes,
            owner,
            block,
        } = members;
        let rows: Vec<(Vec<u32>, Vec<f64>)> = (0..points.len())
            .into_par_iter()
            .map(|i| {
                let (body, r) = owner[i];
                let tree = &trees.iter().find(|t| t.0 == body).expect("body tree").1;
                let r2 = r * r;
                let mut nb: Vec<(u32, f64)> = tree
                    .locate_within_distance(points[i], r2)
                    .filter_map(|g| {
                        let j = g.data as usize;
                        let (dx, dy, dz) = (
                            points[j][0] - points[i][0],
                            points[j][1] - points[i][1],
                            points[j][2] - points[i][2],
                        );
                        let s = 1.0 - (dx * dx + dy * dy + dz * dz) / r2;
                        (s > 0.0).then_some((g.data, s * s * volumes[j]))
                    })
                    .collect();
                nb.sort_unstable_by_key(|p| p.0);
                let total: f64 = nb.iter().map(|p| p.1).sum();
                nb.into_iter().map(|(j, w)| (j, w / total)).unzip()
            })
            .collect();
        // Buckets of half the largest radius: a point's neighbours lie in the buckets
        // within `ceil(R / cell)` of its own.
        let r_max = owner.iter().map(|o| o.1).fold(0.0, f64::max);
        let cell = 0.5 * r_max;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &points {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        // At most 4096 cells a side in the plane, 128 in a solid (two million
        // buckets); points past the last cell fall into it, which keeps the bounds
        // conservative.
        let limit = if mesh.dim == 3 { 1 << 7 } else { 1 << 12 };
        // Clamped as floats: a radius far below the body's size (1e-20 m) gives a
        // ratio past `usize`, whose saturated cast would wrap on the `+ 1`.
        let n = std::array::from_fn(|d| {
            ((hi[d] - lo[d]) / cell)
                .floor()
                .clamp(0.0, (limit - 1) as f64) as usize
                + 1
        });
        let bucket = points
            .iter()
            .map(|p| {
                let i: [usize; 3] =
                    std::array::from_fn(|d| (((p[d] - lo[d]) / cell) as usize).min(n[d] - 1));
                ((i[2] * n[1] + i[1]) * n[0] + i[0]) as u32
            })
            .collect();
        let reach = owner
            .iter()
            .map(|o| (o.1 / cell).ceil().min(255.0) as u8)
            .collect();
        let mut row_ptr = Vec::with_capacity(points.len() + 1);
        row_ptr.push(0);
        let nnz: usize = rows.iter().map(|r| r.0.len()).sum();
        let (mut cols, mut weights) = (Vec::with_capacity(nnz), Vec::with_capacity(nnz));
        for (c, w) in rows {
            cols.extend_from_slice(&c);
            weights.extend_from_slice(&w);
            row_ptr.push(cols.len());
        }
        Some(NonlocalTable {
            offsets,
            radii,
            points,
            row_ptr,
            cols,
            weights,
            grid: (lo, cell, n),
            bucket,
            reach,
            block,
        })
    }

    /// Whether the table was built for these blocks and radii.
    pub fn fits(&self, mesh: &Mesh, materials: &[Material]) -> bool {
        self.radii.len() == mesh.blocks.len()
            && (0..mesh.blocks.len()).all(|bi| block_radius(mesh, materials, bi) == self.radii[bi])
    }

    /// Number of members (Gauss points of nonlocal blocks).
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Number of (point, neighbour) entries.
    pub fn n_entries(&self) -> usize {
        self.cols.len()
    }

    /// Bytes the table holds (indices, weights, rows, coordinates).
    pub fn bytes(&self) -> u64 {
        (self.cols.len() * 12 + self.row_ptr.len() * 8 + self.points.len() * 24) as u64
    }

    /// The smallest and largest neighbour count of a point (itself included).
    pub fn neighbour_range(&self) -> (usize, usize) {
        self.row_ptr
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold((usize::MAX, 0), |(lo, hi), n| (lo.min(n), hi.max(n)))
    }

    /// The first member of block `bi`, when its material is nonlocal.
    pub fn offset(&self, bi: usize) -> Option<usize> {
        self.offsets.get(bi).copied().flatten()
    }

    /// Coordinates of member `i` (`z = 0` in the plane).
    pub fn point(&self, i: usize) -> [f64; 3] {
        self.points[i]
    }

    /// The neighbours of member `i` and their normalised weights.
    pub fn neighbours(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.row_ptr[i]..self.row_ptr[i + 1];
        (&self.cols[r.clone()], &self.weights[r])
    }

    /// `out_i = Σ_j α_ij local_j` for each of the [`DRIVERS`] values per member, on
    /// the thread pool (each row summed in its stored order: the same bits on any
    /// pool).
    pub fn average(&self, local: &[f64], out: &mut [f64]) {
        let mut bounds = vec![[0.0; DRIVERS]; self.n_buckets()];
        self.average_where(local, &mut bounds, |_, _| true, out);
    }

    /// Number of buckets of the bounding grid.
    pub fn n_buckets(&self) -> usize {
        self.grid.2.iter().product()
    }

    /// [`NonlocalTable::average`] for the members where `needed(i, bound)` holds,
    /// `bound` being an upper bound of their averages (the largest driver in the
    /// buckets their radius reaches); the others get `-∞`.
    fn average_where<F>(
        &self,
        local: &[f64],
        bounds: &mut [[f64; DRIVERS]],
        needed: F,
        out: &mut [f64],
    ) where
        F: Fn(usize, [f64; DRIVERS]) -> bool + Sync,
    {
        self.bucket_maxima(local, bounds);
        let bounds = &*bounds;
        let (_, _, [nx, ny, nz]) = self.grid;
        out.par_chunks_mut(DRIVERS * POINT_LEAF)
            .enumerate()
            .for_each(|(c, chunk)| {
                let first = c * POINT_LEAF;
                for (k, o) in chunk.chunks_exact_mut(DRIVERS).enumerate() {
                    let i = first + k;
                    let b = self.bucket[i] as usize;
                    let (bx, by, bz) = (b % nx, (b / nx) % ny, b / (nx * ny));
                    let r = self.reach[i] as usize;
                    let mut bound = [f64::NEG_INFINITY; DRIVERS];
                    for z in bz.saturating_sub(r)..(bz + r + 1).min(nz) {
                        for y in by.saturating_sub(r)..(by + r + 1).min(ny) {
                            for x in bx.saturating_sub(r)..(bx + r + 1).min(nx) {
                                let m = bounds[(z * ny + y) * nx + x];
                                bound = std::array::from_fn(|d| bound[d].max(m[d]));
                            }
                        }
                    }
                    if !needed(i, bound) {
                        o.fill(f64::NEG_INFINITY);
                        continue;
                    }
                    let (cols, w) = self.neighbours(i);
                    let mut sum = [0.0; DRIVERS];
                    for (&j, &wj) in cols.iter().zip(w) {
                        let lj = &local[DRIVERS * j as usize..][..DRIVERS];
                        for d in 0..DRIVERS {
                            sum[d] += wj * lj[d];
                        }
                    }
                    o.copy_from_slice(&sum);
                }
            });
    }

    /// The largest of each driver per bucket, into `m`.
    fn bucket_maxima(&self, local: &[f64], m: &mut [[f64; DRIVERS]]) {
        m.fill([f64::NEG_INFINITY; DRIVERS]);
        for (i, &b) in self.bucket.iter().enumerate() {
            let e = &mut m[b as usize];
            for d in 0..DRIVERS {
                e[d] = e[d].max(local[DRIVERS * i + d]);
            }
        }
    }

    /// The drivers of every member at displacements `u` (their own, not averaged),
    /// in the idealisation `K`, on the thread pool.
    pub fn local_drivers<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &self,
        mesh: &Mesh,
        materials: &[Material],
        u: &[f64],
        local: &mut [f64],
    ) {
        for (bi, b) in mesh.blocks.iter().enumerate() {
            let Some(off) = self.offset(bi) else { continue };
            let mat = &materials[b.material];
            let kind = b.elements.kind;
            let ng = stiffness_rule(kind).len();
            let span = &mut local[DRIVERS * off..DRIVERS * (off + ng * b.elements.len())];
            span.par_chunks_mut(DRIVERS * ng * (POINT_LEAF / ng).max(1))
                .enumerate()
                .for_each(|(c, chunk)| {
                    let per = (POINT_LEAF / ng).max(1);
                    for (k, el) in chunk.chunks_exact_mut(DRIVERS * ng).enumerate() {
                        let e = c * per + k;
                        let (x, ue, nn) = super::gather::<D>(mesh, b.elements.element(e), u);
                        for (q, shape) in rule_shapes(kind).iter().enumerate() {
                            let kin = kinematics_from(kind, &x[..nn], shape);
                            let eps = K::strain(&kin, nn, &ue);
                            let d = mat.drivers::<V, K>(&eps);
                            el[DRIVERS * q..][..DRIVERS].copy_from_slice(&d);
                        }
                    }
                });
        }
    }
}

/// The table with the buffers of one pass: the members' own drivers and their
/// averages. Kept by the [`super::Assembler`] between passes (built at the first
/// pass that needs it).
#[derive(Debug)]
pub struct Nonlocal {
    /// The neighbour table.
    pub table: NonlocalTable,
    /// The members' own drivers of the last pass.
    pub local: Vec<f64>,
    /// Their averages (`-∞` where the bound shows that no history maximum can grow).
    pub averaged: Vec<f64>,
    /// The largest drivers per bucket of the last pass.
    bounds: Vec<[f64; DRIVERS]>,
}

impl Nonlocal {
    /// The table of `mesh` and zeroed buffers, or `None` without nonlocal materials.
    pub fn build(mesh: &Mesh, materials: &[Material]) -> Option<Nonlocal> {
        NonlocalTable::build(mesh, materials).map(|table| {
            let n = DRIVERS * table.n_points();
            Nonlocal {
                bounds: vec![[0.0; DRIVERS]; table.n_buckets()],
                table,
                local: crate::buffers::zeroed(n),
                averaged: crate::buffers::zeroed(n),
            }
        })
    }

    /// Evaluates the drivers at `u` and averages them into `averaged` where an
    /// average can raise a history maximum of the committed states `stores`: a
    /// point whose bound (the largest driver within its reach) stays at or below its
    /// history maxima (and thresholds) would take the same damage from any average
    /// below the bound, so it gets `-∞` instead, which the update reads the same way.
    pub fn evaluate<const D: usize, const V: usize, K: Kinematics<D, V>>(
        &mut self,
        mesh: &Mesh,
        materials: &[Material],
        u: &[f64],
        stores: &[StateStore],
    ) {
        let t = &self.table;
        t.local_drivers::<D, V, K>(mesh, materials, u, &mut self.local);
        let needed = |i: usize, bound: [f64; DRIVERS]| {
            let bi = t.block[i] as usize;
            let Some(store) = stores.get(bi) else {
                return true;
            };
            let g = i - t.offsets[bi].unwrap_or(0);
            materials[mesh.blocks[bi].material]
                .drivers_can_grow(bound, store.committed().history(g))
        };
        t.average_where(&self.local, &mut self.bounds, needed, &mut self.averaged);
    }

    /// The averaged drivers of block `bi`'s points (`DRIVERS` per point), when its
    /// material is nonlocal.
    pub fn block(&self, mesh: &Mesh, bi: usize) -> Option<&[f64]> {
        let off = self.table.offset(bi)?;
        let b = &mesh.blocks[bi];
        let n = b.elements.len() * stiffness_rule(b.elements.kind).len();
        Some(&self.averaged[DRIVERS * off..DRIVERS * (off + n)])
    }
}
