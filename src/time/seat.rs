//! The static seat: what lets statics solve for a body that only contact holds.
//! Such a body's rigid motions make `K` singular until the contact constraints are
//! found; statics adds a tiny multiple of `M` to the matrix it solves with
//! ([`STATIC_SEAT`], `theory/contact.md`), and a failed static step names the bodies
//! in this position ([`bodies_held_by_contact_only`]).

use crate::model::Model;

/// The multiple of `M`, relative to `trace K / trace M`, that statics adds to the
/// matrix it solves with when a body in contact is held by contact alone (a block
/// pressed onto a support, a punch on a beam): its rigid motions make `K` singular,
/// and the contact constraints only hold them once found. The residual is the static
/// one, so the iterations converge to static equilibrium; the term only makes the
/// matrix positive definite and contracts the error of each elastic mode by about
/// `1e-8 ω²_max/ω²` per iteration (`theory/contact.md`).
pub const STATIC_SEAT: f64 = 1e-8;

/// Whether some body with a contact side has a rigid motion (translation or
/// rotation) that its supports and prescribed displacements do not hold.
fn held_by_contact_only(model: &Model) -> bool {
    !bodies_held_by_contact_only(model).is_empty()
}

/// The bodies with a contact side that have a rigid motion (translation or rotation)
/// their supports and prescribed displacements do not hold.
pub(crate) fn bodies_held_by_contact_only(model: &Model) -> Vec<usize> {
    let mesh = &model.mesh;
    let dim = mesh.dim;
    let mut in_contact = vec![false; model.bodies.len()];
    for p in &model.contacts {
        for side in &p.sides {
            for &n in &side.slaves {
                in_contact[mesh.node_body[n]] = true;
            }
            for n in side.master_nodes() {
                in_contact[mesh.node_body[n]] = true;
            }
        }
    }
    // Rigid modes: the translations, then the rotations (one in the plane, about z;
    // three in a solid).
    let modes = if dim == 3 { 6 } else { 3 };
    (0..model.bodies.len())
        .filter(|&b| in_contact[b])
        .filter(|&b| {
            // Gram matrix of the rigid modes about the body's centroid on the body's
            // constrained dofs: singular when a mode is free.
            let nodes: Vec<usize> = (0..mesh.n_nodes())
                .filter(|&n| mesh.node_body[n] == b)
                .collect();
            let mut c = [0.0; 3];
            for &n in &nodes {
                for i in 0..dim {
                    c[i] += mesh.coords[n][i] / nodes.len() as f64;
                }
            }
            let mut g = [[0.0f64; 6]; 6];
            let mut size: f64 = 0.0;
            for con in &model.constraints {
                let (n, comp) = (con.dof / dim, con.dof % dim);
                if mesh.node_body[n] != b {
                    continue;
                }
                let mut r = [0.0; 3];
                for i in 0..dim {
                    r[i] = mesh.coords[n][i] - c[i];
                    size = size.max(r[i].abs());
                }
                // The dof's component of each mode: e_comp for the translations,
                // (e_a × r)_comp for the rotations about axis a.
                let mut row = [0.0; 6];
                row[comp] = 1.0;
                let rot = |a: usize| match (a, comp) {
                    (0, 1) => -r[2],
                    (0, 2) => r[1],
                    (1, 0) => r[2],
                    (1, 2) => -r[0],
                    (2, 0) => -r[1],
                    (2, 1) => r[0],
                    _ => 0.0,
                };
                if dim == 3 {
                    for a in 0..3 {
                        row[3 + a] = rot(a);
                    }
                } else {
                    row[2] = rot(2);
                }
                for i in 0..modes {
                    for j in 0..modes {
                        g[i][j] += row[i] * row[j];
                    }
                }
            }
            if size == 0.0 {
                return true;
            }
            // Rotations in units of the body's size, then a Cholesky factorisation:
            // a pivot below 1e-10 of the largest diagonal is a free mode.
            for (i, row) in g.iter_mut().enumerate().take(modes) {
                for (j, v) in row.iter_mut().enumerate().take(modes) {
                    let f = |k: usize| if k >= dim { size } else { 1.0 };
                    *v /= f(i) * f(j);
                }
            }
            let scale = (0..modes).fold(0.0f64, |a, i| a.max(g[i][i]));
            for k in 0..modes {
                let p = g[k][k];
                if p <= 1e-10 * scale {
                    return true;
                }
                for i in k + 1..modes {
                    let f = g[i][k] / p;
                    for j in k..modes {
                        g[i][j] -= f * g[k][j];
                    }
                }
            }
            false
        })
        .collect()
}

/// The multiple of `M` statics add to the matrix: [`STATIC_SEAT`] times
/// `trace K / trace M` when a body in contact is held by contact alone, else 0.
pub(crate) fn seat(
    model: &Model,
    pattern: &crate::assembly::pattern::Pattern,
    k: &[f64],
    mass: &crate::assembly::Mass,
) -> f64 {
    if !held_by_contact_only(model) {
        return 0.0;
    }
    let (mut tk, mut tm) = (0.0, 0.0);
    let dim = model.mesh.dim;
    for n in 0..model.mesh.n_nodes() {
        for c in 0..dim {
            tk += k[pattern.position(n, c, n, c)];
            tm += match mass {
                crate::assembly::Mass::Consistent(m) => m[pattern.position(n, c, n, c)],
                crate::assembly::Mass::Lumped(m) => m[dim * n + c],
            };
        }
    }
    if tk > 0.0 && tm > 0.0 {
        STATIC_SEAT * tk / tm
    } else {
        0.0
    }
}
