//! VTK XML output for ParaView (`--vtk FILE.vtu` or `FILE.vtp`), written with `vtkio`: one
//! cell per patch polygon (triangle or polygon), cell data for every result column, and the
//! same columns averaged to the vertices as point data (`PatchMesh::to_points`).
//!
//! - [`VtkFields`]: named per-patch columns plus integer columns, and lookup lines
//!   (surface names, method codes) written as an XML comment ahead of the data;
//! - [`solution_fields`] / [`viewfactor_fields`]: the columns of a `solve` / `viewfactors` run;
//! - [`write_to`]: the file's bytes into a writer; [`fn@write`]: a file, through a temporary
//!   renamed on success.
//!
//! Memory is O(patches + vertices): the arrays, their base64 text, nothing of size N².
use super::mesh::PatchMesh;
use crate::scene::Scene;
use crate::solve::Solution;
use crate::viewfactor::{Level, ViewFactors};
use crate::{Error, Result};
use std::io::Write;
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, PolyDataPiece,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// Which XML data set the extension asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VtkKind {
    /// `.vtu`: unstructured grid.
    UnstructuredGrid,
    /// `.vtp`: poly data.
    PolyData,
}

/// The kind named by `path`'s extension, or a usage error (checked before any work starts).
pub fn kind_of(path: &Path) -> Result<VtkKind> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("vtu") => Ok(VtkKind::UnstructuredGrid),
        Some("vtp") => Ok(VtkKind::PolyData),
        _ => Err(Error::Usage(format!(
            "{} {}: unknown VTK file type; expected a .vtu or .vtp file",
            crate::error::opt("vtk"),
            path.display()
        ))),
    }
}

/// Per-patch columns for one VTK file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VtkFields {
    /// Float64 cell columns (one value per patch), also written as point averages.
    pub real: Vec<(String, Vec<f64>)>,
    /// Int32 cell columns (indices, codes): cell data only, never averaged.
    pub int: Vec<(String, Vec<i32>)>,
    /// Lookup lines written in a leading XML comment (e.g. `surface_index 0 = floor`).
    pub notes: Vec<String>,
}

/// Columns every file carries: surface_index, patch_index (within the surface), and the
/// surface names as lookup notes (patch_area is appended last by the callers).
fn base_fields(scene: &Scene) -> VtkFields {
    let mut f = VtkFields::default();
    let surface: Vec<i32> = scene.patches.iter().map(|p| p.surface as i32).collect();
    let local: Vec<i32> = scene
        .patches
        .iter()
        .enumerate()
        .map(|(k, p)| (k - scene.surfaces[p.surface].patches.start) as i32)
        .collect();
    f.int.push(("surface_index".into(), surface));
    f.int.push(("patch_index".into(), local));
    for (k, s) in scene.surfaces.iter().enumerate() {
        f.notes.push(format!("surface_index {k} = {}", s.name));
    }
    f
}

/// Row of the output matrix or table that patch `p` belongs to.
fn row_of(scene: &Scene, level: Level, p: usize) -> usize {
    match level {
        Level::Patch => p,
        Level::Surface => scene.patches[p].surface,
    }
}

/// The `solve` columns (emissivity, temperature, heat_flux, heat_rate, radiosity,
/// irradiation) per patch; a per-surface run gives each patch its surface's values.
pub fn solution_fields(scene: &Scene, sol: &Solution) -> VtkFields {
    let mut f = base_fields(scene);
    let rows: Vec<usize> = (0..scene.patches.len()).map(|p| row_of(scene, sol.level, p)).collect();
    let col = |g: &dyn Fn(usize) -> f64| rows.iter().map(|&r| g(r)).collect::<Vec<f64>>();
    let r = &sol.results;
    f.real.push(("emissivity".into(), col(&|k| sol.emissivity[k])));
    f.real.push(("temperature".into(), col(&|k| r[k].temperature)));
    f.real.push(("heat_flux".into(), col(&|k| r[k].heat_flux)));
    f.real.push(("heat_rate".into(), col(&|k| r[k].heat_rate)));
    f.real.push(("radiosity".into(), col(&|k| r[k].radiosity)));
    f.real.push(("irradiation".into(), col(&|k| r[k].irradiation)));
    f.real.push(("patch_area".into(), scene.patch_areas()));
    f.notes.push(format!("values per {}", level_name(sol.level)));
    f
}

/// The `viewfactors` row diagnostics per patch: row_sum Σ_j F_ij of its output row,
/// row_sum_error (closed scenes: Σ − 1) or to_ambient (open: 1 − Σ), std_error of the row
/// sum √Σ σ_ij², method_code (bit set, lookup in the notes), raw_row_sum = `raw_sums`, the
/// patch's own Σ_j F_ij before any enforcement (left out unless one per patch), and samples
/// when a Monte Carlo method counted them.
pub fn viewfactor_fields(scene: &Scene, vf: &ViewFactors, raw_sums: &[f64]) -> VtkFields {
    let mut f = base_fields(scene);
    let n = scene.patches.len();
    let rows: Vec<usize> = (0..n).map(|p| row_of(scene, vf.level, p)).collect();
    let sums = vf.row_sums();
    let se: Vec<f64> =
        vf.rows.iter().map(|r| r.iter().map(|e| e.std_error * e.std_error).sum::<f64>().sqrt()).collect();
    let code: Vec<i32> = vf
        .rows
        .iter()
        .map(|r| {
            r.iter().fold(crate::viewfactor::MethodSet::default(), |m, e| m.union(e.method)).bits() as i32
        })
        .collect();
    f.real.push(("row_sum".into(), rows.iter().map(|&r| sums[r]).collect()));
    if scene.is_closed() {
        f.real.push(("row_sum_error".into(), rows.iter().map(|&r| sums[r] - 1.0).collect()));
    } else {
        f.real.push(("to_ambient".into(), rows.iter().map(|&r| (1.0 - sums[r]).max(0.0)).collect()));
    }
    f.real.push(("std_error".into(), rows.iter().map(|&r| se[r]).collect()));
    f.int.push(("method_code".into(), rows.iter().map(|&r| code[r]).collect()));
    if raw_sums.len() == n {
        f.real.push(("raw_row_sum".into(), raw_sums.to_vec()));
    }
    if vf.patch_samples.len() == n && vf.patch_samples.iter().any(|&s| s > 0) {
        f.int.push((
            "samples".into(),
            vf.patch_samples.iter().map(|&s| s.min(i32::MAX as u32) as i32).collect(),
        ));
    }
    for (bit, name) in crate::viewfactor::MethodSet::NAMES.iter().enumerate() {
        f.notes.push(format!("method_code bit {} = {name}", 1 << bit));
    }
    f.real.push(("patch_area".into(), scene.patch_areas()));
    f.notes.push(format!("rows per {}", level_name(vf.level)));
    f
}

fn level_name(level: Level) -> &'static str {
    match level {
        Level::Patch => "patch",
        Level::Surface => "surface (every patch shows its surface's value)",
    }
}

/// Builds the vtkio model of `mesh` with `fields` as cell data and their vertex averages as
/// point data.
pub fn model(mesh: &PatchMesh, fields: &VtkFields, kind: VtkKind, title: &str) -> Vtk {
    let points: Vec<f64> = mesh.points.iter().flat_map(|p| p.to_array()).collect();
    let mut data = Attributes::new();
    for (name, values) in &fields.real {
        data.cell.push(Attribute::DataArray(DataArray::scalars(name.as_str(), 1).with_data(values.clone())));
        data.point.push(Attribute::DataArray(
            DataArray::scalars(name.as_str(), 1).with_data(mesh.to_points(values)),
        ));
    }
    for (name, values) in &fields.int {
        data.cell.push(Attribute::DataArray(DataArray::scalars(name.as_str(), 1).with_data(values.clone())));
    }
    let verts = VertexNumbers::XML {
        connectivity: mesh.connectivity.iter().map(|&k| k as u64).collect(),
        offsets: mesh.offsets.iter().map(|&k| k as u64).collect(),
    };
    let data = match kind {
        VtkKind::UnstructuredGrid => {
            let types = (0..mesh.cells())
                .map(|c| match (mesh.cell(c).len(), mesh.convex[c]) {
                    (3, _) => CellType::Triangle,
                    (4, true) => CellType::Quad,
                    _ => CellType::Polygon,
                })
                .collect();
            DataSet::inline(UnstructuredGridPiece {
                points: points.into(),
                cells: Cells { cell_verts: verts, types },
                data,
            })
        }
        VtkKind::PolyData => DataSet::inline(PolyDataPiece {
            points: points.into(),
            polys: Some(verts),
            data,
            ..Default::default()
        }),
    };
    Vtk {
        version: Version::new_xml(1, 0),
        title: title.into(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data,
    }
}

/// Writes `fields` on the patches of `scene` to `path` (.vtu or .vtp), through a temporary
/// beside it that replaces `path` only on success.
pub fn write(path: &Path, scene: &Scene, fields: &VtkFields) -> Result<()> {
    let kind = kind_of(path)?;
    super::outputs::write_file("vtk", &crate::error::opt("vtk"), "VTK results", path, |w, p| {
        write_to(w, p, kind, scene, fields)
    })
}

/// Writes `fields` on the patches of `scene` as VTK XML of `kind` into `out`; `path` names
/// the file in errors.
pub fn write_to(
    out: &mut dyn Write,
    path: &Path,
    kind: VtkKind,
    scene: &Scene,
    fields: &VtkFields,
) -> Result<()> {
    let mesh = PatchMesh::build(scene);
    let title = scene.title.clone().unwrap_or_else(|| "lambert".into());
    let vtk = model(&mesh, fields, kind, &title);
    drop(mesh);
    let io = |e: std::io::Error| Error::Io { path: path.to_path_buf(), source: e };
    // A comment before the root element: readers skip it, people read it.
    writeln!(out, "<!-- lambert results on the patches of '{}'", comment_safe(&title)).map_err(io)?;
    for note in &fields.notes {
        writeln!(out, "     {}", comment_safe(note)).map_err(io)?;
    }
    writeln!(out, "-->").map_err(io)?;
    vtk.write_xml(&mut *out).map_err(|e| io(vtk_io_error(e)))?;
    out.flush().map_err(io)
}

/// vtkio's error as an I/O error: its own I/O errors unwrapped, anything else in words.
fn vtk_io_error(e: vtkio::Error) -> std::io::Error {
    match e {
        vtkio::Error::IO(e) => e,
        other => std::io::Error::other(other.to_string()),
    }
}

/// `--` may not appear inside an XML comment.
fn comment_safe(s: &str) -> String {
    s.replace("--", "- -")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A library call names the file by its keyword (`vtk`); the command line spells it `--vtk`.
    #[test]
    fn a_missing_folder_names_the_vtk_option() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nodir/x.vtu");
        let e = write(&path, &Scene::builder().build(), &VtkFields::default()).unwrap_err();
        let head = format!("vtk {}: the folder ", path.display());
        assert!(e.to_string().starts_with(&head) && e.to_string().contains("does not exist"), "{e}");
        let flag = |k: &str| format!("--{k}");
        assert!(e.spelled(&flag).starts_with(&format!("--{head}")), "{e}");
    }
}
