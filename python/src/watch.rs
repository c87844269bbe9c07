//! Progress for Python callers, and the point factors that report it.
//!
//! [`run_watched`]: the computation runs on a worker thread under a
//! [`Watch`](lambert::viewfactor::progress::Watch); the calling thread waits with the GIL
//! released and, every [`POLL`], takes the GIL back to hand the counts to the Python callback
//! (stages started, units done, units in the stage, what the units are, and the library's
//! phases entered since the last call: "bvh", "view factors", "solve"...). Python code thus
//! never runs on a thread the library computes on, the GIL is free while it computes, and the
//! callback cannot change a number. An exception in the callback stops further calls and is
//! raised when the computation has finished.
use lambert::viewfactor::points::{self, ViewPoint};
use lambert::viewfactor::progress::{watching, Reading, Watch};
use lambert::viewfactor::Level;
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

/// How often the waiting thread reads the counts: often enough for a smooth bar, rare enough
/// to cost nothing.
pub const POLL: Duration = Duration::from_millis(100);

/// Runs `f` on `threads` workers (as [`crate::run`]) while `callback`, if any, hears the counts
/// of every progress stage it starts; without a callback this is [`crate::run`].
pub fn run_watched<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    callback: Option<Py<PyAny>>,
    f: impl FnOnce() -> lambert::Result<T> + Send,
) -> PyResult<T> {
    let Some(callback) = callback else { return crate::run(py, threads, f) };
    let watch = Arc::new(Watch::default());
    let (tx, mut rx) = channel();
    let (out, failed) = std::thread::scope(|s| {
        let w = Arc::clone(&watch);
        s.spawn(move || {
            let _ = tx.send(crate::in_pool(threads, move || watching(&w, f)));
        });
        let mut last: Option<Reading> = None;
        let mut failed: Option<PyErr> = None;
        loop {
            let (back, got) = py.detach(move || {
                let got = rx.recv_timeout(POLL);
                (rx, got)
            });
            rx = back;
            let done = match got {
                Ok(out) => Some(out),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => {
                    Some(Err(lambert::Error::Compute("the computation stopped without a result".into())))
                }
            };
            let r = watch.read();
            let seen = last.map_or(0, |l| l.phases);
            if failed.is_none() && (r.stages > 0 || r.phases > seen) && last != Some(r) {
                let phases: Vec<&str> = watch.phases(seen).into_iter().map(|p| p.name()).collect();
                if let Err(e) = callback.call1(py, (r.stages, r.done, r.total, r.what, phases)) {
                    failed = Some(e);
                }
                last = Some(r);
            }
            if let Some(out) = done {
                return (out, failed);
            }
        }
    });
    if let Some(e) = failed {
        return Err(e);
    }
    out.map_err(crate::to_py)
}

/// The (n, 3) points and normals as checked [`ViewPoint`]s; errors name the row.
fn view_points(
    points: &PyReadonlyArray2<'_, f64>,
    normals: &PyReadonlyArray2<'_, f64>,
) -> lambert::Result<Vec<ViewPoint>> {
    let (p, n) = (points.as_array(), normals.as_array());
    let bad = |problem: String| lambert::Error::Input(lambert::error::InputError::file("<arrays>", problem));
    if p.ncols() != 3 || n.shape() != p.shape() {
        return Err(bad(format!(
            "points has shape {:?} and normals {:?}; expected two arrays of shape (n, 3)",
            p.shape(),
            n.shape()
        )));
    }
    (0..p.nrows())
        .map(|k| {
            ViewPoint::new([p[[k, 0]], p[[k, 1]], p[[k, 2]]], [n[[k, 0]], n[[k, 1]], n[[k, 2]]])
                .map_err(|e| bad(format!("point {k}: {e}")))
        })
        .collect()
}

/// F(point → surface or patch) as a dense (points, columns) array, with the closure warning of
/// a closed scene (`Scene.point_view_factors`).
pub fn point_view_factors<'py>(
    py: Python<'py>,
    scene: Arc<lambert::scene::Scene>,
    points: PyReadonlyArray2<'py, f64>,
    normals: PyReadonlyArray2<'py, f64>,
    patches: bool,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Vec<String>)> {
    let pts = view_points(&points, &normals).map_err(crate::to_py)?;
    let level = if patches { Level::Patch } else { Level::Surface };
    let (dense, n, m, warnings) = run_watched(py, threads, progress, move || {
        let pf = points::compute(&scene, &pts, level, false);
        let mut warnings = Vec::new();
        if scene.is_closed() && !scene.patches.is_empty() {
            let names: Vec<String> = (0..pts.len()).map(|k| format!("point {k}")).collect();
            warnings.extend(pf.closure().warning(&names, !scene.obstructions.is_empty()));
        }
        Ok((pf.dense(), pf.rows.len(), pf.names.len(), warnings))
    })?;
    let arr = numpy::ndarray::Array2::from_shape_vec((n, m), dense).expect("points × columns");
    Ok((PyArray2::from_owned_array(py, arr), warnings))
}
