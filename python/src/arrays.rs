//! Scenes from numpy arrays (`Scene.from_arrays`): every face a patch, faces grouped into
//! surfaces by index, with the value checks of the scene loaders and messages that name the
//! array, the face or the surface.
use lambert::error::InputError;
use lambert::geometry::{DVec3, Polygon};
use lambert::scene::{validate, BoundaryCondition, Scene, SceneBuilder, Shape};
use lambert::Result;
use numpy::ndarray::Array2;

/// The arrays of `from_arrays`, shapes already checked by the Python half.
pub struct Input {
    /// Vertex coordinates (n, 3), m.
    pub vertices: Array2<f64>,
    /// Vertex indices of every face, concatenated.
    pub faces: Vec<i64>,
    /// Face k is `faces[offsets[k]..offsets[k + 1]]`.
    pub offsets: Vec<i64>,
    /// The surface index of every face.
    pub surface: Vec<i64>,
    /// Surface names.
    pub names: Vec<String>,
    /// Per surface.
    pub emissivity: Vec<f64>,
    /// Per surface, `None` where not prescribed, K.
    pub temperature: Vec<Option<f64>>,
    /// Per surface, `None` where not prescribed, W/m².
    pub heat_flux: Vec<Option<f64>>,
    /// Ambient temperature of an open scene, K.
    pub ambient: Option<f64>,
    /// Title.
    pub title: Option<String>,
    /// What messages call the scene.
    pub source: String,
}

/// Builds and checks the scene.
pub fn build(a: Input) -> Result<Scene> {
    let src = a.source.as_str();
    let file = |problem: String| InputError::file(src, problem);
    let m = a.names.len();
    let n = a.vertices.nrows();
    if let Some((k, _)) =
        a.vertices.rows().into_iter().enumerate().find(|(_, r)| !r.iter().all(|x| x.is_finite()))
    {
        return Err(file(format!("vertices[{k}] has a NaN or infinite coordinate")).into());
    }
    let nf = a.offsets.len().saturating_sub(1);
    let mut polys: Vec<Vec<Polygon>> = vec![Vec::new(); m];
    for k in 0..nf {
        let (lo, hi) = (a.offsets[k] as usize, a.offsets[k + 1] as usize);
        let s = a.surface[k];
        if s < 0 || s as usize >= m {
            return Err(file(format!("surface_ids: face {k} has surface index {s} outside 0..{m}")).into());
        }
        let mut ring = Vec::with_capacity(hi - lo);
        for &v in &a.faces[lo..hi] {
            if v < 0 || v as usize >= n {
                return Err(
                    file(format!("faces[{k}] refers to vertex {v}, but there are {n} vertices")).into()
                );
            }
            let r = a.vertices.row(v as usize);
            ring.push(DVec3::new(r[0], r[1], r[2]));
        }
        let name = &a.names[s as usize];
        let poly = Polygon::new(ring).map_err(|e| {
            InputError::surface(src, name.as_str(), format!("face {k}: {}", validate::polygon_problem(&e)))
        })?;
        polys[s as usize].push(poly);
    }
    let mut b = SceneBuilder::default().source(src);
    if let Some(t) = &a.title {
        b = b.title(t);
    }
    if let Some(t) = a.ambient {
        b = b.ambient(validate::ambient_temperature(t).map_err(file)?);
    }
    for (s, patches) in polys.into_iter().enumerate() {
        let name = a.names[s].as_str();
        let bad = |problem: String| InputError::surface(src, name, problem);
        if patches.is_empty() {
            return Err(bad("no face has this surface's id".into()).into());
        }
        let eps = validate::emissivity(a.emissivity[s]).map_err(bad)?;
        let condition = match (a.temperature[s], a.heat_flux[s]) {
            (Some(_), Some(_)) => return Err(bad("give temperature or heat_flux, not both".into()).into()),
            (Some(t), None) => {
                Some(BoundaryCondition::Temperature(validate::temperature(t, "temperature").map_err(bad)?))
            }
            (None, Some(q)) => Some(BoundaryCondition::HeatFlux(validate::heat_flux(q).map_err(bad)?)),
            (None, None) => None,
        };
        b.push_surface(name, Shape::Polygon, patches, eps, condition);
    }
    let mut scene = b.build();
    scene.warnings.extend(validate::celsius_suspects(&scene));
    Ok(scene)
}
