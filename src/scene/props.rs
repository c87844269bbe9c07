//! Surface properties in layers and their resolution.
//!
//! Priority, highest first: the `[[surface]]` entry (shape or override) → glTF node `extras` →
//! the `[[model]]` entry → `[defaults]` → built-in defaults (emissivity 1, no boundary
//! condition, role "surface"). Each property is taken from the highest layer that sets it. The
//! boundary condition is one property: the highest layer that sets `temperature` or
//! `heat_flux` decides, so a surface's `heat_flux` replaces a default `temperature`. A layer
//! that sets both is a conflict, reported by `Scene::check_boundary_conditions` (`solve`) and
//! ignored by `viewfactors`.
//!
//! Obstructions: a layer that says `role = "obstruction"` and also sets emissivity, a boundary
//! condition or a patch size is an error (an obstruction only blocks rays); properties
//! inherited from lower layers are ignored for obstructions.
use super::validate::DEFAULT_EMISSIVITY;
use super::BoundaryCondition;
use crate::error::InputError;
use std::path::PathBuf;

/// Whether a surface exchanges radiation or only blocks it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Role {
    /// Exchanges radiation (the default).
    #[default]
    Surface,
    /// Blocks rays; no part in the exchange, no output row.
    Obstruction,
}

impl Role {
    /// Parses `"surface"` or `"obstruction"`.
    pub fn parse(s: &str) -> Result<Role, String> {
        match s {
            "surface" => Ok(Role::Surface),
            "obstruction" => Ok(Role::Obstruction),
            _ => Err(format!("unknown role '{s}'; expected \"surface\" or \"obstruction\"")),
        }
    }
}

/// One layer of properties, validated, with where it came from.
#[derive(Debug, Clone, Default)]
pub struct Layer {
    /// Where it was set, for messages (e.g. "\[defaults\]", "node extras").
    pub origin: String,
    /// File that holds it.
    pub file: PathBuf,
    /// 1-based line, when known.
    pub line: Option<usize>,
    /// Gray emissivity.
    pub emissivity: Option<f64>,
    /// Temperature, K.
    pub temperature: Option<f64>,
    /// Net outgoing flux, W/m².
    pub heat_flux: Option<f64>,
    /// Role.
    pub role: Option<Role>,
    /// Largest patch width, m.
    pub max_patch_size: Option<f64>,
}

impl Layer {
    /// An empty layer from `origin` in `file` at `line`.
    pub fn new(origin: impl Into<String>, file: impl Into<PathBuf>, line: Option<usize>) -> Self {
        Self { origin: origin.into(), file: file.into(), line, ..Self::default() }
    }

    /// Refuses an obstruction that also carries exchange properties (see the module docs).
    pub fn check_role(&self) -> Result<(), String> {
        if self.role != Some(Role::Obstruction) {
            return Ok(());
        }
        let set: Vec<&str> = [
            ("emissivity", self.emissivity.is_some()),
            ("temperature", self.temperature.is_some()),
            ("heat_flux", self.heat_flux.is_some()),
            ("max_patch_size", self.max_patch_size.is_some()),
        ]
        .iter()
        .filter(|(_, on)| *on)
        .map(|(k, _)| *k)
        .collect();
        if set.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "an obstruction only blocks rays and takes no part in the exchange; remove {} or the role",
                set.join(", ")
            ))
        }
    }
}

/// The properties of one surface after resolution.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolved {
    /// Emissivity (built-in default 1).
    pub emissivity: f64,
    /// Boundary condition, if one layer gives exactly one.
    pub condition: Option<BoundaryCondition>,
    /// Set when the deciding layer gives both temperature and heat_flux.
    pub conflict: Option<InputError>,
    /// Role.
    pub role: Role,
    /// Largest patch width, m.
    pub max_patch_size: Option<f64>,
}

/// Resolves the properties of surface `name` from `layers`, highest priority first.
pub fn resolve(name: &str, layers: &[&Layer]) -> Resolved {
    let first = |f: &dyn Fn(&Layer) -> Option<f64>| layers.iter().find_map(|l| f(l));
    let mut out = Resolved {
        emissivity: first(&|l| l.emissivity).unwrap_or(DEFAULT_EMISSIVITY),
        condition: None,
        conflict: None,
        role: layers.iter().find_map(|l| l.role).unwrap_or_default(),
        max_patch_size: first(&|l| l.max_patch_size),
    };
    if let Some(l) = layers.iter().find(|l| l.temperature.is_some() || l.heat_flux.is_some()) {
        match (l.temperature, l.heat_flux) {
            (Some(t), None) => out.condition = Some(BoundaryCondition::Temperature(t)),
            (None, Some(q)) => out.condition = Some(BoundaryCondition::HeatFlux(q)),
            _ => {
                let mut e = InputError::surface(
                    &l.file,
                    name,
                    format!(
                        "both temperature and heat_flux are given in {}; give exactly one \
                         (temperature in K, or heat_flux in W/m², 0 = adiabatic)",
                        l.origin
                    ),
                );
                e.line = l.line;
                out.conflict = Some(e);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn higher_layers_win_and_conditions_resolve_as_one() {
        let mut defaults = Layer::new("[defaults]", "s.toml", Some(3));
        defaults.emissivity = Some(0.5);
        defaults.temperature = Some(300.0);
        let mut own = Layer::new("this [[surface]]", "s.toml", Some(9));
        own.heat_flux = Some(0.0);
        let r = resolve("wall", &[&own, &defaults]);
        assert_eq!(r.emissivity, 0.5);
        assert_eq!(r.condition, Some(BoundaryCondition::HeatFlux(0.0)));
        assert!(r.conflict.is_none());
        own.temperature = Some(400.0);
        let r = resolve("wall", &[&own, &defaults]);
        let e = r.conflict.unwrap();
        assert_eq!((e.surface.as_deref(), e.line), (Some("wall"), Some(9)));
        assert!(e.problem.contains("both temperature and heat_flux"));
        assert_eq!(resolve("x", &[]).emissivity, DEFAULT_EMISSIVITY);
    }

    #[test]
    fn obstruction_layer_with_condition_is_refused() {
        let mut l = Layer::new("x", "s.toml", None);
        l.role = Some(Role::Obstruction);
        assert!(l.check_role().is_ok());
        l.temperature = Some(300.0);
        assert!(l.check_role().unwrap_err().contains("temperature"));
        assert!(Role::parse("blocker").unwrap_err().contains("unknown role 'blocker'"));
    }
}
