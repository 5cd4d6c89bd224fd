//! VTK XML output: one `.vtu` per saved step under `vtk/`, and `result.pvd` listing
//! them with their times (rewritten after every file, so it is always valid).

use std::path::{Path, PathBuf};

use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use crate::error::{Error, Result};
use crate::mesh::{ElementKind, Mesh};

/// Writes the VTK series of a run.
pub struct VtkSeries {
    dir: PathBuf,
    /// The collection's name (`result` for a run: `result.pvd`) and its files'
    /// prefix (`step`: `vtk/step_0000010.vtu`).
    collection: &'static str,
    prefix: &'static str,
    /// Dofs per node of the mesh.
    dim: usize,
    entries: Vec<(f64, String)>,
    connectivity: Vec<u64>,
    offsets: Vec<u64>,
    types: Vec<CellType>,
    points: Vec<f64>,
}

impl VtkSeries {
    /// Prepares `dir/vtk/` and the cell tables of `mesh`.
    pub fn new(dir: &Path, mesh: &Mesh) -> Result<Self> {
        Self::named(dir, mesh, "result", "step")
    }

    /// The same, the collection `dir/<collection>.pvd` listing `vtk/<prefix>_*.vtu`.
    pub fn named(
        dir: &Path,
        mesh: &Mesh,
        collection: &'static str,
        prefix: &'static str,
    ) -> Result<Self> {
        let sub = dir.join("vtk");
        std::fs::create_dir_all(&sub).map_err(|e| Error::io(&sub, e))?;
        let mut connectivity = Vec::new();
        let mut offsets = Vec::new();
        let mut types = Vec::new();
        for b in &mesh.blocks {
            let t = match b.elements.kind {
                ElementKind::Quad4 => CellType::Quad,
                ElementKind::Tri3 => CellType::Triangle,
                ElementKind::Bar2 => CellType::Line,
                ElementKind::Hex8 => CellType::Hexahedron,
                ElementKind::Tet4 => CellType::Tetra,
            };
            for e in 0..b.elements.len() {
                connectivity.extend(b.elements.element(e).iter().map(|&n| n as u64));
                offsets.push(connectivity.len() as u64);
                types.push(t);
            }
        }
        let points = mesh.coords.iter().flatten().copied().collect();
        Ok(VtkSeries {
            dim: mesh.dim,
            dir: dir.into(),
            collection,
            prefix,
            entries: Vec::new(),
            connectivity,
            offsets,
            types,
            points,
        })
    }

    /// Writes step `step` at time `t` with nodal `u`, `v`, further scalar point fields
    /// `point_extra`, cell `stress` and further scalar cell fields `extra`.
    #[allow(clippy::too_many_arguments)]
    pub fn write(
        &mut self,
        step: usize,
        t: f64,
        u: &[f64],
        v: &[f64],
        point_extra: &[(&str, &[f64])],
        stress: &[[f64; 6]],
        extra: &[(&str, Vec<f64>)],
    ) -> Result<()> {
        let dim = self.dim;
        let vec3 = |x: &[f64]| -> IOBuffer {
            x.chunks_exact(dim)
                .flat_map(|p| [p[0], p[1], if dim == 3 { p[2] } else { 0.0 }])
                .collect::<Vec<f64>>()
                .into()
        };
        // The plane's three components as they are; a solid's six in VTK's
        // symmetric-tensor order `xx, yy, zz, xy, yz, xz`.
        let stress: Vec<f64> = if dim == 3 {
            stress
                .iter()
                .flat_map(|s| [s[0], s[1], s[3], s[2], s[4], s[5]])
                .collect()
        } else {
            stress.iter().flat_map(|s| [s[0], s[1], s[2]]).collect()
        };
        let piece = UnstructuredGridPiece {
            points: self.points.clone().into(),
            cells: Cells {
                cell_verts: VertexNumbers::XML {
                    connectivity: self.connectivity.clone(),
                    offsets: self.offsets.clone(),
                },
                types: self.types.clone(),
            },
            data: Attributes {
                point: [
                    Attribute::DataArray(DataArray {
                        name: "displacement".into(),
                        elem: ElementType::Vectors,
                        data: vec3(u),
                    }),
                    Attribute::DataArray(DataArray {
                        name: "velocity".into(),
                        elem: ElementType::Vectors,
                        data: vec3(v),
                    }),
                ]
                .into_iter()
                .chain(point_extra.iter().map(|(name, values)| {
                    Attribute::DataArray(DataArray {
                        name: (*name).into(),
                        elem: ElementType::Scalars {
                            num_comp: 1,
                            lookup_table: None,
                        },
                        data: values.to_vec().into(),
                    })
                }))
                .collect(),
                cell: std::iter::once(Attribute::DataArray(DataArray {
                    name: "stress".into(),
                    elem: ElementType::Generic(if dim == 3 { 6 } else { 3 }),
                    data: stress.into(),
                }))
                .chain(extra.iter().map(|(name, values)| {
                    Attribute::DataArray(DataArray {
                        name: (*name).into(),
                        elem: ElementType::Scalars {
                            num_comp: 1,
                            lookup_table: None,
                        },
                        data: values.clone().into(),
                    })
                }))
                .collect(),
            },
        };
        let name = format!("{}_{step:07}.vtu", self.prefix);
        let path = self.dir.join("vtk").join(&name);
        let vtk = Vtk {
            version: Version::new_xml(1, 0),
            title: format!("rothe t = {t:e}"),
            byte_order: ByteOrder::LittleEndian,
            data: DataSet::inline(piece),
            file_path: None,
        };
        vtk.export(&path)
            .map_err(|e| Error::io(&path, std::io::Error::other(format!("{e:?}"))))?;
        self.entries.push((t, format!("vtk/{name}")));
        self.write_pvd()
    }

    fn write_pvd(&self) -> Result<()> {
        let mut s = String::from("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n");
        for (t, f) in &self.entries {
            s.push_str(&format!(
                "    <DataSet timestep=\"{t:.9e}\" group=\"\" part=\"0\" file=\"{f}\"/>\n"
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        let path = self.dir.join(format!("{}.pvd", self.collection));
        let tmp = self.dir.join(format!("{}.pvd.tmp", self.collection));
        std::fs::write(&tmp, s).map_err(|e| Error::io(&tmp, e))?;
        std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e))
    }
}
