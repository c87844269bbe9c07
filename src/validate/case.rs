//! A validation case: a folder with a scene (`scene.toml`, `scene.gltf` or `scene.glb`) and a
//! `reference.toml` holding the citation, the reference quantities with their provenance, and
//! optional per-method tolerance overrides (each with its reason).
use crate::error::InputError;
use crate::viewfactor::Method;
use crate::Result;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The reference file's name inside a case folder.
pub const REFERENCE_FILE: &str = "reference.toml";
/// Scene file names tried in order when `scene` is not given.
const SCENE_FILES: [&str; 3] = ["scene.toml", "scene.gltf", "scene.glb"];

/// `reference.toml` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// One-line description.
    pub title: String,
    /// Where the case comes from: catalogue number, textbook example, docs/literature.md ID.
    pub citation: String,
    /// Scene file relative to the case folder (default: the first of `SCENE_FILES` present).
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// Methods deliberately not run on this case, with the reason (shown in the report).
    #[serde(default)]
    pub skip: BTreeMap<String, String>,
    /// Methods with a known, reported defect on this case, with the reason: their failures are
    /// listed as `known` (not counted), and a pass says the marker can go.
    #[serde(default)]
    pub known_issue: BTreeMap<String, String>,
    /// False for cases too heavy for `--quick` (listed as skipped there).
    #[serde(default = "yes")]
    pub quick: bool,
    /// A looser accuracy goal for `auto` on this case, when the suite's own goal would take
    /// minutes (a meshed body behind which auto integrates at 1e-6); the checks follow it.
    #[serde(default)]
    pub auto_goal: Option<f64>,
    /// Per-method tolerance overrides.
    #[serde(default)]
    pub tolerance: BTreeMap<String, Override>,
    /// Reference view factors.
    #[serde(default, rename = "viewfactor")]
    pub viewfactors: Vec<VfRef>,
    /// Reference heat rates and temperatures of enclosure problems.
    #[serde(default)]
    pub heat: Vec<HeatRef>,
    /// An exact view-factor CSV (SPEC `viewfactors` format) for `solve --viewfactors`: used for
    /// 2-D or curved enclosures whose exact factors planar patches cannot express.
    #[serde(default)]
    pub viewfactors_file: Option<PathBuf>,
}

fn yes() -> bool {
    true
}

/// A tolerance override for one method on one case.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Override {
    /// Absolute tolerance replacing the model's.
    pub abs: f64,
    /// Why the model does not apply.
    pub why: String,
}

/// One reference view factor F(from → to) between named surfaces.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VfRef {
    /// Emitting surface.
    pub from: String,
    /// Receiving surface.
    pub to: String,
    /// Reference value.
    pub value: f64,
    /// How the value was obtained.
    pub source: String,
    /// Absolute error bound of the reference itself (0 for closed forms).
    #[serde(default)]
    pub uncertainty: f64,
    /// Point-sampling bias: max over the patch-centre and 2×2-Gauss-point estimates of
    /// |Σ_i (A_i/A_I) F(dA_i → J) − F_IJ| (the hemicube's infinite-resolution error).
    #[serde(default)]
    pub point_bias: f64,
}

/// One reference heat quantity of an enclosure problem.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeatRef {
    /// Surface name, or `ambient`.
    pub surface: String,
    /// Net outgoing heat rate, W.
    #[serde(default)]
    pub heat_rate: Option<f64>,
    /// Temperature, K (for flux-given surfaces).
    #[serde(default)]
    pub temperature: Option<f64>,
    /// How the value was obtained.
    pub source: String,
    /// Relative error bound of the reference itself.
    #[serde(default)]
    pub uncertainty: f64,
    /// d(quantity)/dF_IJ per surface pair (F_JI moved reciprocally): propagates an approximate
    /// method's view-factor tolerances into a heat tolerance.
    #[serde(default)]
    pub sensitivity: Vec<Sensitivity>,
}

/// One entry of a heat quantity's sensitivity to a surface-pair view factor.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sensitivity {
    /// Emitting surface.
    pub from: String,
    /// Receiving surface.
    pub to: String,
    /// d(quantity)/dF(from → to), W or K.
    pub d: f64,
}

/// A case ready to run.
#[derive(Debug, Clone)]
pub struct Case {
    /// Folder name, used as the case name.
    pub name: String,
    /// The case folder.
    pub dir: PathBuf,
    /// The scene file.
    pub scene: PathBuf,
    /// Parsed reference.
    pub reference: Reference,
}

impl Case {
    /// Loads `dir/reference.toml` and locates the scene.
    pub fn load(dir: &Path) -> Result<Case> {
        let path = dir.join(REFERENCE_FILE);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| InputError::file(&path, format!("cannot read: {e}")))?;
        let reference: Reference = toml::from_str(&text).map_err(|e| {
            let err = InputError::file(&path, e.message().to_string());
            match e.span() {
                Some(span) => err.at_line(text[..span.start].matches('\n').count() + 1),
                None => err,
            }
        })?;
        reference.check(&path)?;
        let scene =
            match &reference.scene {
                Some(s) => dir.join(s),
                None => SCENE_FILES.iter().map(|f| dir.join(f)).find(|p| p.exists()).ok_or_else(|| {
                    InputError::file(&path, "no scene.toml, scene.gltf or scene.glb beside it")
                })?,
            };
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        Ok(Case { name, dir: dir.to_path_buf(), scene, reference })
    }

    /// True when `method` runs on this case (not listed under `skip`).
    pub fn runs(&self, method: Method) -> bool {
        !self.reference.skip.contains_key(&method.to_string())
    }
}

impl Reference {
    /// Rejects unknown method names, non-finite numbers and empty references.
    fn check(&self, path: &Path) -> Result<()> {
        let bad = |problem: String| Err(InputError::file(path, problem).into());
        for name in self.skip.keys().chain(self.tolerance.keys()).chain(self.known_issue.keys()) {
            if name.parse::<Method>().is_err() {
                return bad(format!("unknown method '{name}' in [skip], [tolerance] or [known_issue]"));
            }
        }
        if self.auto_goal.is_some_and(|g| !(g.is_finite() && g > 0.0)) {
            return bad("auto_goal must be a positive number".into());
        }
        for (m, o) in &self.tolerance {
            if !(o.abs.is_finite() && o.abs > 0.0) {
                return bad(format!("tolerance for '{m}' must be a positive number"));
            }
        }
        for v in &self.viewfactors {
            let nums = [v.value, v.uncertainty, v.point_bias];
            if nums.iter().any(|x| !x.is_finite() || *x < 0.0) || v.value > 1.0 + 1e-12 {
                return bad(format!(
                    "F({} → {}): value, uncertainty and point_bias must be finite and ≥ 0",
                    v.from, v.to
                ));
            }
        }
        for h in &self.heat {
            let nums = [h.heat_rate.unwrap_or(0.0), h.temperature.unwrap_or(1.0), h.uncertainty];
            if nums.iter().any(|x| !x.is_finite()) || h.heat_rate.is_none() && h.temperature.is_none() {
                return bad(format!(
                    "heat reference for '{}' needs a finite heat_rate or temperature",
                    h.surface
                ));
            }
        }
        if self.viewfactors.is_empty() && self.heat.is_empty() {
            return bad("no [[viewfactor]] or [[heat]] reference quantities".into());
        }
        Ok(())
    }
}

/// The case folders under `root` that hold a `reference.toml`, sorted by name; folders without
/// one are returned separately so the report can list them. Folders named `_*` or `.*` are
/// skipped.
pub fn discover(root: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    let entries = std::fs::read_dir(root)
        .map_err(|e| InputError::file(root, format!("cannot read the cases folder: {e}")))?;
    // Folders starting with '_' or '.' are tooling (cases/_generator), not cases.
    let tooling =
        |p: &PathBuf| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with(['_', '.']));
    let mut dirs: Vec<PathBuf> =
        entries.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.is_dir() && !tooling(p)).collect();
    dirs.sort();
    Ok(dirs.into_iter().partition(|d| d.join(REFERENCE_FILE).exists()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_case(text: &str) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), "").unwrap();
        std::fs::write(dir.path().join(REFERENCE_FILE), text).unwrap();
        dir
    }

    const GOOD: &str = "title = \"t\"\ncitation = \"c\"\n[skip]\n\"mc-area\" = \"too slow\"\n\n[[viewfactor]]\nfrom = \"a\"\nto = \"b\"\nvalue = 0.2\nsource = \"C-11\"\n";

    #[test]
    fn loads_a_reference_and_finds_the_scene() {
        let dir = write_case(GOOD);
        let case = Case::load(dir.path()).unwrap();
        assert_eq!(case.scene, dir.path().join("scene.toml"));
        assert!(!case.runs(Method::McArea) && case.runs(Method::Analytic));
        assert_eq!(case.reference.viewfactors[0].point_bias, 0.0);
        assert_eq!(case.reference.auto_goal, None);
        let dir = write_case(&GOOD.replace("citation = \"c\"\n", "citation = \"c\"\nauto_goal = 1e-4\n"));
        assert_eq!(Case::load(dir.path()).unwrap().reference.auto_goal, Some(1e-4));
    }

    #[test]
    fn bad_references_name_the_file_line_and_problem() {
        let dir = write_case(&format!("{GOOD}colour = 3\n"));
        let e = Case::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("reference.toml:11") && e.contains("colour"), "{e}");
        let dir = write_case(&GOOD.replace("mc-area", "mc-fast"));
        let e = Case::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("unknown method 'mc-fast'"), "{e}");
        let dir = write_case(&GOOD.replace("citation = \"c\"\n", "citation = \"c\"\nauto_goal = -1.0\n"));
        let e = Case::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("auto_goal must be a positive number"), "{e}");
        let dir = write_case(&GOOD.replace("0.2", "nan"));
        let e = Case::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("F(a → b)"), "{e}");
    }
}
