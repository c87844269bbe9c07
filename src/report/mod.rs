//! Reports: the one place that turns results into bytes (CSV, charts) and reads saved results
//! back.
//! - [`csv`]: the `viewfactors` matrix;
//! - [`solve_csv`]: the `solve` table and radiative conductances;
//! - [`read_vf`]: a saved `viewfactors` CSV, matched to a scene (`solve --viewfactors`);
//! - [`charts`]: log–log charts of the validation studies (SVG, PNG);
//! - [`mesh`]: patch polygons as a welded mesh, cell values averaged to vertices;
//! - [`vtk`]: VTK XML (.vtu/.vtp) for ParaView (`--vtk`);
//! - [`render`]: false-colour pictures of a result on the geometry (`lambert render`).
pub mod charts;
pub mod csv;
pub mod mesh;
pub mod read_vf;
pub mod render;
pub mod solve_csv;
pub mod vtk;

/// Runs `write` on the temporary `tmp` beside `path`, then renames it over `path`; on failure
/// the temporary is removed and an earlier `path` is left as it was.
pub fn replace_on_success(
    path: &std::path::Path,
    tmp: &std::path::Path,
    write: impl FnOnce(&std::path::Path) -> crate::Result<()>,
) -> crate::Result<()> {
    match write(tmp) {
        Ok(()) => {
            std::fs::rename(tmp, path).map_err(|e| crate::Error::Io { path: path.to_path_buf(), source: e })
        }
        Err(e) => {
            let _ = std::fs::remove_file(tmp);
            Err(e)
        }
    }
}

/// Characters the exponent form must save before it replaces the plain form (keeps "1000").
const EXPONENT_MIN_SAVING: usize = 3;

/// Full-precision text for an f64 (SPEC.md): the shortest round-trip digits, in plain form unless
/// the exponent form is clearly shorter (tiny or huge magnitudes); both forms round-trip exactly.
pub fn fmt_f64(x: f64) -> String {
    let plain = x.to_string();
    let sci = format!("{x:e}");
    if sci.len() + EXPONENT_MIN_SAVING <= plain.len() {
        sci
    } else {
        plain
    }
}

#[cfg(test)]
mod tests {
    use super::fmt_f64;

    #[test]
    fn shortest_round_trip() {
        for x in [0.0, 1.0, -0.5, 7.275957614183426e-12, 1e300, 0.19982489569838732, 21386.617834354303] {
            let s = fmt_f64(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
            assert!(s.len() <= x.to_string().len(), "{s}");
        }
        assert_eq!(fmt_f64(7.275957614183426e-12), "7.275957614183426e-12");
        assert_eq!(fmt_f64(1000.0), "1000");
        assert_eq!(fmt_f64(1e300), "1e300");
    }
}
