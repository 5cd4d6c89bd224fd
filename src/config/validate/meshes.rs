//! Body meshes and bars: generated rectangles (sized before they are built), Gmsh
//! files, bars along lines of nodes, and the memory check of the whole model
//! (the estimate itself is [`crate::memory`]'s).

use std::collections::BTreeMap;
use std::path::Path;

use super::checks::{finite, positive};
use crate::config::{LoadOptions, MeshSpec, MeshingSpec, Scenario};
use crate::error::{Error, Result};
use crate::material::Material;
use crate::memory::{factor_nnz_estimate, Estimate};
use crate::mesh::{gmsh, solid, structured, Block, ElementKind, Elements, Mesh, Part};
use crate::model::Body;

/// The nodes and elements of a rectangle of `nx x ny` cells, or `None` if the counts
/// overflow.
fn rectangle_size(nx: u64, ny: u64, element: ElementKind) -> Option<(u64, u64)> {
    let nodes = nx.checked_add(1)?.checked_mul(ny.checked_add(1)?)?;
    let cells = nx.checked_mul(ny)?;
    let elements = match element {
        ElementKind::Tri3 => cells.checked_mul(2)?,
        _ => cells,
    };
    Some((nodes, elements))
}

/// `[meshing] element_size` must reach a body: on a scenario whose bodies all give
/// `divisions`, their own `element_size` or a file, setting it (by `--set` or a mesh
/// study's `--sizes`) would change nothing, and a study over it would report the
/// convergence of one mesh.
pub fn meshing_size_is_taken(s: &Scenario) -> Result<()> {
    if s.meshing.element_size.is_none() {
        return Ok(());
    }
    let taken = s.bodies.iter().any(|b| {
        matches!(
            b.mesh,
            MeshSpec::Rectangle {
                divisions: None,
                element_size: None,
                ..
            } | MeshSpec::Box {
                divisions: None,
                element_size: None,
                ..
            }
        )
    });
    if taken {
        return Ok(());
    }
    let how: Vec<String> = s
        .bodies
        .iter()
        .map(|b| {
            let given = match &b.mesh {
                MeshSpec::Rectangle {
                    divisions: Some(_), ..
                } => "divisions",
                MeshSpec::Box {
                    divisions: Some(_), ..
                } => "divisions",
                MeshSpec::Rectangle { .. } | MeshSpec::Box { .. } => "its own element_size",
                MeshSpec::Gmsh { .. } => "a Gmsh file",
            };
            format!("`{}` gives {given}", b.name)
        })
        .collect();
    Err(Error::config(
        "meshing.element_size",
        format!(
            "no body takes it ({}): it would change no mesh; remove `divisions` from the \
             bodies it should size",
            how.join(", ")
        ),
    ))
}

/// How one rectangle (`N = 2`) or box (`N = 3`) is cut, resolved from its spec and
/// `[meshing]`.
enum Cuts<'a, const N: usize> {
    /// `divisions`: equal cells.
    Equal([usize; N]),
    /// `element_size` with optional grid lines.
    Sized { size: f64, lines: [&'a [f64]; N] },
}

impl<const N: usize> Cuts<'_, N> {
    /// The cell boundaries along each axis.
    fn lines(&self, size: [f64; N]) -> [Vec<f64>; N] {
        std::array::from_fn(|a| match self {
            Cuts::Equal(d) => (0..=d[a])
                .map(|i| size[a] * i as f64 / d[a] as f64)
                .collect(),
            Cuts::Sized { size: h, lines } => structured::graded_lines(size[a], *h, lines[a]),
        })
    }
}

/// Resolves and checks a rectangle's or a box's cuts (before anything is allocated).
fn rectangle_cuts<'a, const N: usize>(
    field: &str,
    size: [f64; N],
    divisions: Option<[usize; N]>,
    element_size: Option<f64>,
    lines: [&'a [f64]; N],
    meshing: &MeshingSpec,
) -> Result<Cuts<'a, N>> {
    if let Some(d) = divisions {
        if element_size.is_some() {
            return Err(Error::config(
                format!("{field}.element_size"),
                "give `divisions` or `element_size`, not both",
            ));
        }
        if lines.iter().any(|l| !l.is_empty()) {
            return Err(Error::config(
                format!("{field}.x_lines"),
                "grid lines need `element_size` (here or in [meshing]), not `divisions`",
            ));
        }
        if d.contains(&0) {
            return Err(Error::config(
                format!("{field}.divisions"),
                format!("must be at least 1 each way, got {d:?}"),
            ));
        }
        return Ok(Cuts::Equal(d));
    }
    let (h, h_field) = match (element_size, meshing.element_size) {
        (Some(h), _) => (h, format!("{field}.element_size")),
        (None, Some(h)) => (h, "meshing.element_size".to_string()),
        (None, None) => {
            return Err(Error::config(
                format!("{field}.divisions"),
                "give `divisions`, or `element_size` here or in [meshing]",
            ))
        }
    };
    positive(&h_field, h)?;
    for (axis, name) in ["x_lines", "y_lines", "z_lines"]
        .into_iter()
        .enumerate()
        .take(N)
    {
        let f = format!("{field}.{name}");
        finite(&f, lines[axis])?;
        let mut prev = 0.0;
        for &c in lines[axis] {
            if c <= prev || c >= size[axis] {
                return Err(Error::config(
                    &f,
                    format!(
                        "grid lines must increase strictly inside (0, {}), got {:?}",
                        size[axis], lines[axis]
                    ),
                ));
            }
            prev = c;
        }
        // Count the cells before building anything: a tiny size is refused here.
        let cells = cells_along(size[axis], h, lines[axis]);
        if cells > 1e9 {
            return Err(Error::config(
                &h_field,
                format!("{h} m gives {cells:.3e} cells along {name}: far too many"),
            ));
        }
    }
    Ok(Cuts::Sized { size: h, lines })
}

/// The number of cells [`structured::graded_lines`] makes (as a float, so that a
/// tiny size cannot overflow).
fn cells_along(length: f64, size: f64, lines: &[f64]) -> f64 {
    let mut cuts = vec![0.0];
    cuts.extend_from_slice(lines);
    cuts.push(length);
    cuts.windows(2)
        .map(|w| structured::cells_in_band(w[1] - w[0], size))
        .sum()
}

impl<const N: usize> Cuts<'_, N> {
    /// Cells along each axis.
    fn counts(&self, size: [f64; N]) -> [u64; N] {
        std::array::from_fn(|a| match self {
            Cuts::Equal(d) => d[a] as u64,
            Cuts::Sized { size: h, lines } => cells_along(size[a], *h, lines[a]) as u64,
        })
    }
}

/// Estimates the generated meshes before building them, so that a mistyped
/// `divisions` is refused instead of allocating what the machine does not have.
pub(super) fn check_generated_size(
    s: &Scenario,
    materials: &[Material],
    mat_index: &BTreeMap<String, usize>,
    opts: &LoadOptions,
) -> Result<()> {
    let (mut nodes, mut elements, mut points, mut history) = (0u64, 0u64, 0u64, 0u64);
    let mut dim = 2;
    for (bi, b) in s.bodies.iter().enumerate() {
        let field = format!("bodies[{bi}].mesh");
        let counted = match &b.mesh {
            MeshSpec::Rectangle {
                size,
                divisions,
                element_size,
                x_lines,
                y_lines,
                element,
                ..
            } => {
                let cuts = rectangle_cuts(
                    &field,
                    *size,
                    *divisions,
                    *element_size,
                    [x_lines, y_lines],
                    &s.meshing,
                )?;
                let [nx, ny] = cuts.counts(*size);
                let (n, e) = rectangle_size(nx, ny, *element).ok_or_else(|| {
                    Error::config(
                        format!("{field}.divisions"),
                        format!("[{nx}, {ny}] cells: the node count overflows"),
                    )
                })?;
                let per = if *element == ElementKind::Tri3 { 1 } else { 4 };
                Some((n, e, e.saturating_mul(per)))
            }
            MeshSpec::Box {
                size,
                divisions,
                element_size,
                x_lines,
                y_lines,
                z_lines,
                element,
                ..
            } => {
                let cuts = rectangle_cuts(
                    &field,
                    *size,
                    *divisions,
                    *element_size,
                    [x_lines, y_lines, z_lines],
                    &s.meshing,
                )?;
                let [nx, ny, nz] = cuts.counts(*size);
                let n = (nx + 1)
                    .checked_mul(ny + 1)
                    .and_then(|v| v.checked_mul(nz + 1));
                let cells = nx.checked_mul(ny).and_then(|v| v.checked_mul(nz));
                let (Some(n), Some(cells)) = (n, cells) else {
                    return Err(Error::config(
                        format!("{field}.divisions"),
                        format!("[{nx}, {ny}, {nz}] cells: the node count overflows"),
                    ));
                };
                dim = 3;
                // A cell is one Hex8 (eight points) or six one-point Tet4.
                let (e, per) = if *element == ElementKind::Tet4 {
                    (cells.saturating_mul(6), 1)
                } else {
                    (cells, 8)
                };
                Some((n, e, e.saturating_mul(per)))
            }
            MeshSpec::Gmsh { .. } => None,
        };
        if let Some((n, e, p)) = counted {
            nodes = nodes.saturating_add(n);
            elements = elements.saturating_add(e);
            points = points.saturating_add(p);
            if let Some(&m) = mat_index.get(&b.material) {
                let voigt = if dim == 3 { 6 } else { 3 };
                history = history.max(materials[m].n_state(voigt) as u64);
            }
        }
    }
    if nodes == 0 {
        return Ok(());
    }
    let dofs = usize::try_from(nodes.saturating_mul(dim as u64)).unwrap_or(usize::MAX);
    let tangent = materials.iter().any(|m| !m.has_constant_tangent());
    let est = Estimate::of(
        dim,
        nodes,
        elements,
        points,
        history,
        if opts.distributed_factor {
            0
        } else {
            factor_nnz_estimate(dofs, dim)
        },
        tangent,
    );
    est.check(
        opts.memory_limit,
        &format!("the generated meshes ({nodes} nodes, {elements} elements)"),
    )
    .map_err(|e| Error::config("bodies[..].mesh.divisions", e.to_string()))
}

/// The memory estimate of the built mesh (the factor from its size: the exact
/// figure is checked again after the symbolic analysis, before the factorisation).
pub(super) fn check_memory(mesh: &Mesh, materials: &[Material], opts: &LoadOptions) -> Result<()> {
    let factor = opts.distributed_factor.then_some(0);
    let est = crate::memory::of_mesh(mesh, materials, factor);
    est.check(
        opts.memory_limit,
        &format!(
            "the model ({} nodes, {} elements)",
            mesh.n_nodes(),
            mesh.n_elements()
        ),
    )
}

/// A body's part from its mesh spec.
pub(super) fn body_part(
    field: &str,
    spec: &MeshSpec,
    meshing: &MeshingSpec,
    dir: &Path,
) -> Result<Part> {
    match spec {
        MeshSpec::Rectangle {
            origin,
            size,
            divisions,
            element_size,
            x_lines,
            y_lines,
            element,
        } => {
            finite(&format!("{field}.origin"), origin)?;
            positive(&format!("{field}.size[0]"), size[0])?;
            positive(&format!("{field}.size[1]"), size[1])?;
            if *element == ElementKind::Bar2 {
                return Err(Error::config(
                    format!("{field}.element"),
                    "a rectangle is meshed with quad4 or tri3",
                ));
            }
            let cuts = rectangle_cuts(
                field,
                *size,
                *divisions,
                *element_size,
                [x_lines, y_lines],
                meshing,
            )?;
            Ok(match cuts {
                Cuts::Equal(d) => structured::rectangle(*origin, *size, d[0], d[1], *element),
                Cuts::Sized { size: h, lines } => structured::grid(
                    *origin,
                    &structured::graded_lines(size[0], h, lines[0]),
                    &structured::graded_lines(size[1], h, lines[1]),
                    *element,
                ),
            })
        }
        MeshSpec::Box {
            origin,
            size,
            divisions,
            element_size,
            x_lines,
            y_lines,
            z_lines,
            element,
        } => {
            finite(&format!("{field}.origin"), origin)?;
            for (i, &l) in size.iter().enumerate() {
                positive(&format!("{field}.size[{i}]"), l)?;
            }
            if !matches!(element, ElementKind::Hex8 | ElementKind::Tet4) {
                return Err(Error::config(
                    format!("{field}.element"),
                    "a box is meshed with hex8 or tet4",
                ));
            }
            let cuts = rectangle_cuts(
                field,
                *size,
                *divisions,
                *element_size,
                [x_lines, y_lines, z_lines],
                meshing,
            )?;
            let [xs, ys, zs] = cuts.lines(*size);
            let cells = (xs.len() - 1) as f64 * (ys.len() - 1) as f64 * (zs.len() - 1) as f64;
            if cells > 2e8 {
                return Err(Error::config(
                    format!("{field}.divisions"),
                    format!("{cells:.3e} cells: far too many"),
                ));
            }
            Ok(solid::block(*origin, &xs, &ys, &zs, *element))
        }
        MeshSpec::Gmsh { file } => {
            if file.trim().is_empty() {
                return Err(Error::config(
                    format!("{field}.file"),
                    "the mesh file name is empty",
                ));
            }
            let path = dir.join(file);
            if !path.is_file() {
                return Err(Error::config(
                    format!("{field}.file"),
                    format!("mesh file {} does not exist", path.display()),
                ));
            }
            gmsh::read(&path).map_err(|e| Error::config(format!("{field}.file"), e.to_string()))
        }
    }
}

/// Adds the bar blocks: 2-node bars through the body's nodes on each line. A bar's
/// name becomes a node set (`body.name`) and must not shadow an existing set.
pub(super) fn add_bars(
    s: &Scenario,
    mesh: &mut Mesh,
    bodies: &[Body],
    materials: &[Material],
    find_material: &dyn Fn(String, &str) -> Result<usize>,
) -> Result<()> {
    for (i, bar) in s.bars.iter().enumerate() {
        let field = format!("bars[{i}]");
        if bar.name.is_empty() || bar.name.contains('.') {
            return Err(Error::config(
                format!("{field}.name"),
                "must be non-empty and contain no `.`",
            ));
        }
        positive(&format!("{field}.area"), bar.area)?;
        let from = super::constraints::dimensioned(mesh.dim, &format!("{field}.from"), &bar.from)?;
        let to = super::constraints::dimensioned(mesh.dim, &format!("{field}.to"), &bar.to)?;
        // Points are printed with the model's dimension.
        let shown = |p: [f64; 3]| format!("{:?}", &p[..mesh.dim]);
        let mat = find_material(format!("{field}.material"), &bar.material)?;
        if !materials[mat].is_linear_elastic() {
            return Err(Error::config(
                format!("{field}.material"),
                "bars take an elastic material",
            ));
        }
        let body = bodies
            .iter()
            .position(|b| b.name == bar.body)
            .ok_or_else(|| {
                Error::config(
                    format!("{field}.body"),
                    format!("unknown body `{}`", bar.body),
                )
            })?;
        let set = format!("{}.{}", bar.body, bar.name);
        if mesh.node_sets.contains_key(&set) || mesh.edge_sets.contains_key(&set) {
            return Err(Error::config(
                format!("{field}.name"),
                format!("`{set}` is already a set of the mesh; give the bar another name"),
            ));
        }
        let len = crate::mesh::distance(from, to);
        if !(len > 0.0 && len.is_finite()) {
            return Err(Error::config(
                format!("{field}.to"),
                format!(
                    "the bar line from {} to {} has no length",
                    shown(from),
                    shown(to)
                ),
            ));
        }
        let nodes = mesh.nodes_on_segment(body, from, to, 1e-9 * len.max(1.0));
        if nodes.len() < 2 {
            return Err(Error::config(
                field,
                format!(
                    "the line from {} to {} passes through fewer than two nodes of `{}`",
                    shown(from),
                    shown(to),
                    bar.body
                ),
            ));
        }
        let conn = nodes.windows(2).flat_map(|w| [w[0], w[1]]).collect();
        mesh.blocks.push(Block {
            elements: Elements::new(ElementKind::Bar2, conn),
            body,
            material: mat,
            section: bar.area,
        });
        mesh.node_sets.insert(set, nodes);
    }
    Ok(())
}
