//! `lambert._lambert`: the Rust half of the Python package (the Python half, `lambert/`, wraps
//! its results in numpy arrays, scipy matrices and dataclasses).
//!
//! - this file: the module, the scene handle [`PyScene`], and the handles of computed view
//!   factors ([`PyViewFactors`]) and solutions ([`PySolution`]) that save in the CLI's formats;
//! - [`arrays`]: scenes from numpy arrays, with the loaders' value checks;
//! - [`route`]: every computation on the library's plan (the CLI's method choice, stores and
//!   refusals);
//! - [`watch`]: progress callbacks polled while the GIL is released, and point factors.
//!
//! Every computation runs with the GIL released; library errors become the exceptions of
//! `lambert.errors` with the CLI's message.
use lambert::report;
use lambert::scene::{self, Scene};
use lambert::solve::Solution;
use lambert::viewfactor::{Level, MethodSet, ViewFactors};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod arrays;
mod route;
mod watch;

/// A library error as the `lambert.errors` exception of its kind, with the CLI's message.
fn to_py(e: lambert::Error) -> PyErr {
    let kind = match &e {
        lambert::Error::Input(_) => "InputError",
        lambert::Error::Usage(_) => "UsageError",
        lambert::Error::Unsupported(_) => "UnsupportedError",
        lambert::Error::Compute(_) => "ComputeError",
        lambert::Error::Io { .. } => "LambertIOError",
    };
    let message = e.to_string();
    Python::attach(|py| {
        match py
            .import("lambert.errors")
            .and_then(|m| m.getattr(kind))
            .and_then(|c| c.call1((message.clone(),)))
        {
            Ok(exc) => PyErr::from_value(exc),
            Err(err) => err,
        }
    })
}

/// Runs `f` on a pool of `threads` workers (the global pool when `None`), with the GIL released.
fn run<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    f: impl FnOnce() -> lambert::Result<T> + Send,
) -> PyResult<T> {
    py.detach(move || in_pool(threads, f)).map_err(to_py)
}

/// Runs `f` on a pool of `threads` workers (the global pool when `None`).
fn in_pool<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> lambert::Result<T> + Send,
) -> lambert::Result<T> {
    match threads {
        None => f(),
        Some(n) => {
            if !(1..=1024).contains(&n) {
                return Err(lambert::Error::Usage(format!("threads={n}: give 1 to 1024 worker threads")));
            }
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().map_err(|e| {
                lambert::Error::Usage(format!("threads={n}: the worker threads cannot be started ({e})"))
            })?;
            pool.install(f)
        }
    }
}

/// A scene: named surfaces, their patches, emissivities and boundary conditions.
/// Patch polygons for pyvista: points (k, 3), the VTK face array, the patch of each cell.
type PatchMesh<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<i64>>);

#[pyclass(name = "_Scene", module = "lambert._lambert", frozen)]
struct PyScene {
    scene: Arc<Scene>,
}

#[pymethods]
impl PyScene {
    /// Loads a scene file (.toml, .gltf, .glb, .stl, .obj, .vs3) as the CLI does.
    #[staticmethod]
    #[pyo3(signature = (path, unit=None, repair=false, allow_outside_paths=false))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        unit: Option<String>,
        repair: bool,
        allow_outside_paths: bool,
    ) -> PyResult<Self> {
        let scene = run(py, None, move || {
            let unit = match unit {
                Some(u) => route::keyword("unit", &u)?,
                None => scene::mesh_model::Unit::M,
            };
            let bare = scene::mesh_model::MeshOptions { unit, repair, ..Default::default() };
            scene::load_with(&path, &scene::LoadOptions { allow_outside_paths, bare })
        })?;
        Ok(Self { scene: Arc::new(scene) })
    }

    /// A scene from arrays: `faces` as a flat index array with `offsets` (face k is
    /// `faces[offsets[k]:offsets[k+1]]`), `surface` the surface index of each face.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (vertices, faces, offsets, surface, names, emissivity, temperature, heat_flux, ambient=None, title=None, source=None))]
    fn from_arrays(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f64>,
        faces: PyReadonlyArray1<'_, i64>,
        offsets: PyReadonlyArray1<'_, i64>,
        surface: PyReadonlyArray1<'_, i64>,
        names: Vec<String>,
        emissivity: Vec<f64>,
        temperature: Vec<Option<f64>>,
        heat_flux: Vec<Option<f64>>,
        ambient: Option<f64>,
        title: Option<String>,
        source: Option<String>,
    ) -> PyResult<Self> {
        let input = arrays::Input {
            vertices: vertices.as_array().to_owned(),
            faces: faces.as_array().to_vec(),
            offsets: offsets.as_array().to_vec(),
            surface: surface.as_array().to_vec(),
            names,
            emissivity,
            temperature,
            heat_flux,
            ambient,
            title,
            source: source.unwrap_or_else(|| "<arrays>".into()),
        };
        let scene = run(py, None, move || arrays::build(input))?;
        Ok(Self { scene: Arc::new(scene) })
    }

    /// Surface names.
    #[getter]
    fn surface_names(&self) -> Vec<String> {
        self.scene.surfaces.iter().map(|s| s.name.clone()).collect()
    }
    /// Patch names (`surface#k`, or the surface's name for a surface of one patch).
    #[getter]
    fn patch_names(&self) -> Vec<String> {
        (0..self.scene.patches.len()).map(|p| self.scene.patch_name(p)).collect()
    }
    /// Surface areas, m².
    #[getter]
    fn surface_areas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.scene.surfaces.iter().map(|s| s.area).collect())
    }
    /// Patch areas, m².
    #[getter]
    fn patch_areas<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.scene.patch_areas())
    }
    /// The surface index of each patch.
    #[getter]
    fn patch_surface<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(py, self.scene.patches.iter().map(|p| p.surface as i64).collect())
    }
    /// Surface emissivities.
    #[getter]
    fn emissivity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.scene.surfaces.iter().map(|s| s.emissivity).collect())
    }
    /// True for a closed enclosure (no ambient).
    #[getter]
    fn is_closed(&self) -> bool {
        self.scene.is_closed()
    }
    /// The ambient temperature of an open scene, K.
    #[getter]
    fn ambient(&self) -> Option<f64> {
        self.scene.ambient.map(|a| a.temperature)
    }
    /// The file the scene was read from (`<arrays>` for array scenes).
    #[getter]
    fn source(&self) -> String {
        self.scene.source.display().to_string()
    }
    /// The scene's title.
    #[getter]
    fn title(&self) -> Option<String> {
        self.scene.title.clone()
    }
    /// Warnings of the loader.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        spelled(&self.scene.warnings)
    }
    /// The geometry fingerprint that saved view factors carry.
    #[getter]
    fn fingerprint(&self) -> String {
        scene::fingerprint::geometry(&self.scene)
    }

    /// The patch polygons as (points (k, 3), VTK face array [n, i0, …], patch of each cell).
    fn mesh<'py>(&self, py: Python<'py>) -> PatchMesh<'py> {
        let (mut points, mut faces) = (Vec::new(), Vec::new());
        for p in &self.scene.patches {
            let v = p.polygon.vertices();
            faces.push(v.len() as i64);
            for x in v {
                faces.push((points.len() / 3) as i64);
                points.extend_from_slice(&[x.x, x.y, x.z]);
            }
        }
        let n = points.len() / 3;
        let pts =
            numpy::ndarray::Array2::from_shape_vec((n, 3), points).expect("three coordinates per point");
        let cells = (0..self.scene.patches.len() as i64).collect();
        (PyArray2::from_owned_array(py, pts), PyArray1::from_vec(py, faces), PyArray1::from_vec(py, cells))
    }

    /// View factors as `lambert viewfactors` computes them; a dict of arrays and diagnostics.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (method, tolerance, samples, resolution, seed, patches, enforce, threads, progress, watch=None))]
    fn view_factors<'py>(
        &self,
        py: Python<'py>,
        method: String,
        tolerance: Option<f64>,
        samples: Option<usize>,
        resolution: Option<usize>,
        seed: u64,
        patches: bool,
        enforce: Option<String>,
        threads: Option<usize>,
        progress: bool,
        watch: Option<Py<PyAny>>,
    ) -> PyResult<(Bound<'py, PyDict>, PyViewFactors)> {
        let scene = self.scene.clone();
        let out = watch::run_watched(py, threads, watch, move || {
            let mut opts =
                route::Options::new(&method, tolerance, samples, resolution, seed, patches, enforce)?;
            opts.set_progress(progress);
            route::view_factors(&scene, opts)
        })?;
        let d = vf_dict(py, &out.vf)?;
        d.set_item("raw_row_sums", PyArray1::from_vec(py, out.raw_row_sums))?;
        d.set_item("store", out.store)?;
        d.set_item("warnings", spelled(&out.said.warnings))?;
        d.set_item("notes", out.said.notes)?;
        Ok((d, PyViewFactors { scene: self.scene.clone(), vf: Arc::new(out.vf) }))
    }

    /// F(point → surface), or patch with `patches`, as a dense (points, columns) array, with
    /// the closure warning of a closed scene; `watch` hears the progress counts.
    #[pyo3(signature = (points, normals, patches, threads, watch=None))]
    fn point_view_factors<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f64>,
        normals: PyReadonlyArray2<'py, f64>,
        patches: bool,
        threads: Option<usize>,
        watch: Option<Py<PyAny>>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Vec<String>)> {
        watch::point_view_factors(py, self.scene.clone(), points, normals, patches, threads, watch)
    }

    /// Reads a `lambert viewfactors` CSV written for this scene.
    fn read_view_factors<'py>(
        &self,
        py: Python<'py>,
        path: PathBuf,
    ) -> PyResult<(Bound<'py, PyDict>, PyViewFactors, bool)> {
        let scene = self.scene.clone();
        let (vf, stamped) = run(py, None, move || route::read_viewfactors(&path, &scene))?;
        let d = vf_dict(py, &vf)?;
        d.set_item("warnings", Vec::<String>::new())?;
        d.set_item("notes", Vec::<String>::new())?;
        Ok((d, PyViewFactors { scene: self.scene.clone(), vf: Arc::new(vf) }, stamped))
    }

    /// The net-radiation solve as `lambert solve` runs it; per-patch arrays and diagnostics.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (method, tolerance, samples, resolution, seed, patches, enforce, threads, progress, solver, exchange, viewfactors=None, watch=None))]
    fn solve<'py>(
        &self,
        py: Python<'py>,
        method: String,
        tolerance: Option<f64>,
        samples: Option<usize>,
        resolution: Option<usize>,
        seed: u64,
        patches: bool,
        enforce: Option<String>,
        threads: Option<usize>,
        progress: bool,
        solver: String,
        exchange: String,
        viewfactors: Option<(PyRef<'py, PyViewFactors>, bool, Option<PathBuf>)>,
        watch: Option<Py<PyAny>>,
    ) -> PyResult<(Bound<'py, PyDict>, PySolution)> {
        let scene = self.scene.clone();
        let saved = viewfactors.map(|(v, stamped, file)| ((*v.vf).clone(), stamped, file));
        let out = watch::run_watched(py, threads, watch, move || {
            let mut opts =
                route::Options::new(&method, tolerance, samples, resolution, seed, patches, enforce)?;
            opts.set_progress(progress);
            let s = route::SolveOptions { solver, exchange };
            let saved = saved.as_ref().map(|(v, st, f)| (v.clone(), *st, f.as_deref()));
            route::solve(&scene, opts, &s, saved)
        })?;
        let d = PyDict::new(py);
        d.set_item("path", out.path)?;
        d.set_item("warnings", spelled(&out.said.warnings))?;
        d.set_item("notes", out.said.notes)?;
        let info = &out.solution.info;
        d.set_item("solver", info.solver.to_string())?;
        d.set_item("iterations", info.iterations)?;
        d.set_item("residual", info.residual)?;
        d.set_item("solve_seconds", info.wall.as_secs_f64())?;
        d.set_item("ambient", out.solution.ambient)?;
        let by_surface = out.solution.by_surface(&self.scene);
        if out.solution.level == Level::Patch {
            d.set_item("patch", solution_dict(py, &out.solution)?)?;
        }
        d.set_item("surface", solution_dict(py, &by_surface)?)?;
        Ok((d, PySolution { patch: Arc::new(out.solution), surface: Arc::new(by_surface) }))
    }
}

/// The sparse rows of `vf` as CSR arrays, with names, areas and diagnostics.
fn vf_dict<'py>(py: Python<'py>, vf: &ViewFactors) -> PyResult<Bound<'py, PyDict>> {
    let nnz: usize = vf.rows.iter().map(Vec::len).sum();
    let mut indptr = Vec::with_capacity(vf.rows.len() + 1);
    let (mut indices, mut data, mut se, mut method) =
        (Vec::with_capacity(nnz), Vec::with_capacity(nnz), Vec::with_capacity(nnz), Vec::with_capacity(nnz));
    indptr.push(0i64);
    for row in &vf.rows {
        for e in row {
            indices.push(e.to as i64);
            data.push(e.factor);
            se.push(e.std_error);
            method.push(e.method.bits());
        }
        indptr.push(indices.len() as i64);
    }
    let d = PyDict::new(py);
    d.set_item("level", if vf.level == Level::Patch { "patch" } else { "surface" })?;
    d.set_item("names", vf.names.clone())?;
    d.set_item("areas", PyArray1::from_vec(py, vf.areas.clone()))?;
    d.set_item("indptr", PyArray1::from_vec(py, indptr))?;
    d.set_item("indices", PyArray1::from_vec(py, indices))?;
    d.set_item("data", PyArray1::from_vec(py, data))?;
    d.set_item("std_error", PyArray1::from_vec(py, se))?;
    d.set_item("method", PyArray1::from_vec(py, method))?;
    d.set_item("method_names", MethodSet::NAMES.to_vec())?;
    d.set_item("row_sums", PyArray1::from_vec(py, vf.row_sums()))?;
    d.set_item("patch_row_sums", PyArray1::from_vec(py, vf.patch_row_sums.clone()))?;
    d.set_item("pairs", vf.pairs)?;
    d.set_item("seconds", vf.wall.as_secs_f64())?;
    Ok(d)
}

/// The per-node arrays of a solution.
fn solution_dict<'py>(py: Python<'py>, s: &Solution) -> PyResult<Bound<'py, PyDict>> {
    let col =
        |f: fn(&lambert::solve::NodeResult) -> f64| PyArray1::from_vec(py, s.results.iter().map(f).collect());
    let d = PyDict::new(py);
    d.set_item("names", s.names.clone())?;
    d.set_item("area", PyArray1::from_vec(py, s.areas.clone()))?;
    d.set_item("emissivity", PyArray1::from_vec(py, s.emissivity.clone()))?;
    d.set_item("surface", PyArray1::from_vec(py, s.surface.iter().map(|&x| x as i64).collect()))?;
    d.set_item("temperature", col(|r| r.temperature))?;
    d.set_item("heat_flux", col(|r| r.heat_flux))?;
    d.set_item("heat_rate", col(|r| r.heat_rate))?;
    d.set_item("radiosity", col(|r| r.radiosity))?;
    d.set_item("irradiation", col(|r| r.irradiation))?;
    let err = s.heat_rate_error.clone().unwrap_or_else(|| vec![0.0; s.results.len()]);
    d.set_item("heat_rate_error", PyArray1::from_vec(py, err))?;
    Ok(d)
}

/// Computed or read view factors, kept for saving in the CLI's format and for `solve`.
#[pyclass(name = "_ViewFactors", module = "lambert._lambert", frozen)]
struct PyViewFactors {
    scene: Arc<Scene>,
    vf: Arc<ViewFactors>,
}

#[pymethods]
impl PyViewFactors {
    /// Writes the `lambert viewfactors` CSV (with the scene's geometry fingerprint).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let (scene, vf) = (self.scene.clone(), self.vf.clone());
        run(py, None, move || {
            let geometry = scene::fingerprint::geometry(&scene);
            let open = !scene.is_closed();
            report::outputs::write_file("output", "path", "view-factor CSV", &path, |w, p| {
                report::csv::write_viewfactors(w, &vf, open, &geometry, p)
            })
        })
    }
}

/// A solution, kept for saving in the CLI's results CSV.
#[pyclass(name = "_Solution", module = "lambert._lambert", frozen)]
struct PySolution {
    patch: Arc<Solution>,
    surface: Arc<Solution>,
}

#[pymethods]
impl PySolution {
    /// Writes the `lambert solve` results CSV, per surface or (`patches`) per node solved.
    fn save(&self, py: Python<'_>, path: PathBuf, patches: bool) -> PyResult<()> {
        let sol = if patches { self.patch.clone() } else { self.surface.clone() };
        run(py, None, move || write_solution(&sol, &path))
    }
}

/// The results CSV of `sol` at `path`.
fn write_solution(sol: &Solution, path: &Path) -> lambert::Result<()> {
    report::outputs::write_file("output", "path", "results CSV", path, |w, p| {
        report::solve_csv::write_solution(w, sol, p)
    })
}

/// The extension module.
#[pymodule]
fn _lambert(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_class::<PyViewFactors>()?;
    m.add_class::<PySolution>()?;
    m.add("SIGMA", lambert::SIGMA)?;
    Ok(())
}

/// Library messages with their option marks spelled as the keyword arguments of this package.
fn spelled(lines: &[String]) -> Vec<String> {
    lines.iter().map(|w| lambert::error::spell_options(w, &lambert::error::keyword)).collect()
}
