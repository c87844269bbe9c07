//! Radiative conductances RADK_ij = A_i ε_i B_ij (Gebhart, B = (I − Fρ)⁻¹ F diag(ε)), the
//! thermal-network convention (docs/literature.md §5): Q_i = σ Σ_j RADK_ij (T_i⁴ − T_j⁴).
//!
//! Column j is one solve of the all-temperature system with unit emissive power on node j
//! and zero elsewhere: RADK_ij = A_i ε_i H_i (what i absorbs of j's emission). All columns
//! share one factorisation of K. The ambient (open scenes) is a black node: its column is the
//! solve with E_b∞ = 1, its row RADK_∞j = Σ_i S_i∞ J_i^(j) (everything reaching it is
//! absorbed). Symmetry and row sums Σ_j RADK_ij = A_i ε_i are properties to test, not imposed.
//! [`check_deck`] refuses, before any work, a deck whose nodes could not reproduce the solve.
use super::direct;
use super::system::{self, RowKind};
use super::Params;
use crate::error::opt;
use crate::error::InputError;
use crate::exchange::Exchange;
use crate::scene::{BoundaryCondition, Scene};
use crate::viewfactor::Level;
use crate::{Error, Result};
use faer::Mat;

/// Largest node count for the dense conductance matrix (N² doubles: 200 MB at 5,000).
pub const MAX_NODES: usize = 5000;

/// A dense conductance matrix; the ambient, when present, is the last node.
#[derive(Debug, Clone, PartialEq)]
pub struct Conductances {
    /// Node names (ambient last for open scenes).
    pub names: Vec<String>,
    /// A_i ε_i per node (ambient: NaN, it has no area).
    pub emitting_area: Vec<f64>,
    /// RADK_ij, m².
    pub radk: Vec<Vec<f64>>,
}

impl Conductances {
    /// Sums nodes into groups (patches → surfaces): conductances add.
    pub fn aggregate(&self, group: &[usize], names: Vec<String>) -> Conductances {
        let m = names.len();
        let mut radk = vec![vec![0.0; m]; m];
        let mut ea = vec![0.0; m];
        for (i, row) in self.radk.iter().enumerate() {
            ea[group[i]] += self.emitting_area[i];
            for (j, v) in row.iter().enumerate() {
                radk[group[i]][group[j]] += v;
            }
        }
        Conductances { names, emitting_area: ea, radk }
    }
}

/// Refuses RADK over more than [`MAX_NODES`] nodes (patches): one dense solve per node.
pub fn check_nodes(n: usize) -> Result<()> {
    if n > MAX_NODES {
        return Err(Error::Unsupported(format!(
            "{} for {n} patches: RADK needs a dense solve over the patches, limited to \
             {MAX_NODES}; use a coarser `subdivide` (surface conductances are summed from the patches)",
            opt("conductances")
        )));
    }
    Ok(())
}

/// Refuses a deck that could not reproduce the solve it comes with, before any work:
/// - semi-gray bands whose emissivities differ from a surface's gray one: RADK is a gray
///   quantity, and band-wise exchange makes it depend on the temperatures;
/// - per-surface nodes (`patches` false) over a patch-level exchange (`exchange`) when a
///   surface with a heat-flux condition has several patches: the solve gives each patch its
///   own temperature, which one network node cannot carry, so the summed conductances would
///   give other heat rates than the solve (the cube furnace's floor: 5 % off). A surface
///   with a temperature condition is isothermal, and its summed conductances are exact.
pub fn check_deck(scene: &Scene, exchange: Level, patches: bool) -> Result<()> {
    if let Some(sp) = &scene.spectral {
        let gray = |s: usize| sp.emissivity[s].iter().all(|&e| e == scene.surfaces[s].emissivity);
        if let Some(s) = (0..scene.surfaces.len()).find(|&s| !gray(s)) {
            let bands: Vec<String> = sp.emissivity[s].iter().map(|e| e.to_string()).collect();
            return Err(Error::Unsupported(format!(
                "{}: {} writes gray conductances, but surface '{}' has band emissivities {} \
                 ([[band]] table): with semi-gray bands the exchange depends on the temperatures, so no \
                 gray deck reproduces the solve",
                scene.source.display(),
                opt("conductances"),
                scene.surfaces[s].name,
                bands.join(", ")
            )));
        }
    }
    if patches || exchange == Level::Surface {
        return Ok(());
    }
    let lumped: Vec<&crate::scene::Surface> = scene
        .surfaces
        .iter()
        .filter(|s| s.patches.len() > 1 && matches!(s.condition, Some(BoundaryCondition::HeatFlux(_))))
        .collect();
    let Some(first) = lumped.first() else { return Ok(()) };
    let more = match lumped.len() {
        1 => String::new(),
        n => format!(" ({} more such surfaces)", n - 1),
    };
    Err(InputError::surface(
        &scene.source,
        &first.name,
        format!(
            "{} per surface: this surface has a heat_flux condition over {} patches{more}, and \
             the solve gives each patch its own temperature; one network node per surface cannot carry \
             them, so the summed conductances would not reproduce the solve's heat rates. Add {} \
             for a deck over the patches (nodes {}#0, ...), or give the surface one patch",
            opt("conductances"),
            first.patches.len(),
            opt("patches"),
            first.name
        ),
    )
    .into())
}

/// Computes RADK for the nodes of `ex` (plus the ambient for open scenes).
pub fn radk(scene: &Scene, ex: &Exchange, params: &Params) -> Result<Conductances> {
    let nodes = system::nodes(scene, ex)?;
    let n = nodes.len();
    check_nodes(n)?;
    let open = ex.ambient.is_some();
    let eps: Vec<f64> = nodes.iter().map(|n| n.emissivity).collect();
    let rows = vec![RowKind::Temperature(0.0); n];
    let sys = system::assemble(ex, &eps, &rows, 0.0);
    let f = direct::factor(&sys.k, sys.symmetric, params.dense_max, params.dense_full_max, &mut None)?;
    let cols = n + usize::from(open);
    let m = sys.node.len();
    let ip = ex.indptr();
    let (idx, s) = (ex.s.indices(), ex.s.data());
    // Right-hand sides: unit emissive power on one node (or the ambient) per column.
    let mut b = Mat::<f64>::zeros(m, cols);
    for (u, &i) in sys.node.iter().enumerate() {
        let (a, e) = (ex.areas[i], eps[i]);
        b[(u, i)] += a * e / (1.0 - e);
        for k in ip[i]..ip[i + 1] {
            if sys.unknown[idx[k]].is_none() {
                b[(u, idx[k])] += s[k];
            }
        }
        if let Some(amb) = &ex.ambient {
            b[(u, n)] += amb[i];
        }
    }
    let x = f.solve_many(b);
    let mut radk = vec![vec![0.0; cols]; cols];
    for c in 0..cols {
        // Radiosities of every node for source c.
        let j: Vec<f64> =
            (0..n).map(|i| sys.unknown[i].map_or(if i == c { 1.0 } else { 0.0 }, |u| x[(u, c)])).collect();
        for i in 0..n {
            let mut inc: f64 = (ip[i]..ip[i + 1]).map(|k| s[k] * j[idx[k]]).sum();
            if c == n {
                inc += ex.ambient.as_ref().map_or(0.0, |a| a[i]);
            }
            radk[i][c] = eps[i] * inc;
        }
        if open && c < n {
            radk[n][c] = ex.ambient.as_ref().map_or(0.0, |a| a.iter().zip(&j).map(|(a, j)| a * j).sum());
        }
    }
    let mut names = ex.names.clone();
    let mut emitting_area: Vec<f64> = (0..n).map(|i| ex.areas[i] * eps[i]).collect();
    if open {
        names.push(super::AMBIENT.to_string());
        emitting_area.push(f64::NAN);
    }
    Ok(Conductances { names, emitting_area, radk })
}
