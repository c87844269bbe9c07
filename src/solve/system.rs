//! The linear system of the net-radiation method (docs/literature.md §5), SPD form:
//! - T row (0 < ε < 1): (A_i/ρ_i) J_i − Σ_j S_ij J_j = (A_i ε_i/ρ_i) E_bi + S_i∞ E_b∞;
//! - q row: A_i J_i − Σ_j S_ij J_j = A_i q_i + S_i∞ E_b∞;
//! - black T row (ε = 1): J_i = E_bi is known and moves to the right-hand side.
//!
//! K = D − S is symmetric when S is, and SPD iff every connected group of unknowns has a
//! strictly dominant row ([`check_anchored`]).
use crate::error::InputError;
use crate::exchange::operator::Operator;
use crate::exchange::ranks::Groups;
use crate::exchange::Exchange;
use crate::scene::{BoundaryCondition, Scene};
use crate::viewfactor::Level;
use crate::{Error, Result, SIGMA};
use rayon::prelude::*;
use sprs::CsMat;

/// A group of unknowns is anchored when it holds a given temperature, or when some heat-flux
/// row's diagonal dominance margin Σ_j K_ij exceeds this fraction of K_ii; closure leaves
/// ~1e-12, so 1e-9 separates a true anchor from round-off.
pub const ANCHOR_TOL: f64 = 1e-9;

/// One radiosity node with its surface's properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Owning surface.
    pub surface: usize,
    /// Area, m².
    pub area: f64,
    /// Gray emissivity.
    pub emissivity: f64,
    /// Boundary condition.
    pub condition: BoundaryCondition,
}

impl Node {
    /// The row this node contributes for gray radiation.
    pub fn row_kind(&self) -> RowKind {
        match self.condition {
            BoundaryCondition::Temperature(t) => RowKind::Temperature(SIGMA * t.powi(4)),
            BoundaryCondition::HeatFlux(q) => RowKind::Flux(q),
        }
    }
}

/// The equation of one node: known emissive power or known net flux (W/m²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RowKind {
    /// E_b known.
    Temperature(f64),
    /// q known.
    Flux(f64),
}

/// The boundary condition of surface `s`, or the error that names a surface without one.
pub fn condition(scene: &Scene, s: usize) -> Result<crate::scene::BoundaryCondition> {
    let surf = &scene.surfaces[s];
    surf.condition.ok_or_else(|| {
        Error::from(InputError::surface(
            &scene.source,
            surf.name.clone(),
            "no boundary condition: `solve` needs `temperature` or `heat_flux`",
        ))
    })
}

/// Nodes of `ex` with the properties of their surfaces; every surface needs a condition.
pub fn nodes(scene: &Scene, ex: &Exchange) -> Result<Vec<Node>> {
    let expected = match ex.level {
        Level::Surface => scene.surfaces.len(),
        Level::Patch => scene.patches.len(),
    };
    if ex.len() != expected {
        return Err(InputError::file(
            &scene.source,
            format!("the exchange matrix has {} nodes but the scene has {expected}", ex.len()),
        )
        .into());
    }
    (0..ex.len())
        .map(|i| {
            let s = match ex.level {
                Level::Surface => i,
                Level::Patch => scene.patches[i].surface,
            };
            let surf = &scene.surfaces[s];
            Ok(Node {
                surface: s,
                area: ex.areas[i],
                emissivity: surf.emissivity,
                condition: condition(scene, s)?,
            })
        })
        .collect()
}

/// y = K x over the rows of `k`, each row summed in storage order (the same on any thread
/// count).
pub fn matvec(k: &CsMat<f64>, x: &[f64]) -> Vec<f64> {
    let (ip, idx, d) = (k.indptr(), k.indices(), k.data());
    let ip = ip.raw_storage();
    (0..k.rows()).into_par_iter().map(|i| (ip[i]..ip[i + 1]).map(|p| d[p] * x[idx[p]]).sum()).collect()
}

/// ‖b − Kx‖ / ‖b‖ (or ‖b − Kx‖ when b = 0).
pub fn residual(k: &CsMat<f64>, x: &[f64], b: &[f64]) -> f64 {
    let kx = matvec(k, x);
    let r: Vec<f64> = b.iter().zip(&kx).map(|(b, k)| b - k).collect();
    let bn = crate::exchange::linalg::norm(b);
    let rn = crate::exchange::linalg::norm(&r);
    if bn > 0.0 {
        rn / bn
    } else {
        rn
    }
}

/// Diagonal entries K_ii (0 where not stored).
pub fn diagonal(k: &CsMat<f64>) -> Vec<f64> {
    (0..k.rows()).map(|i| k.get(i, i).copied().unwrap_or(0.0)).collect()
}

/// K J = b over the unknown radiosities.
#[derive(Debug, Clone, PartialEq)]
pub struct System {
    /// Node → unknown index (None: eliminated black node).
    pub unknown: Vec<Option<usize>>,
    /// Unknown → node.
    pub node: Vec<usize>,
    /// J of eliminated nodes (E_b), 0 elsewhere.
    pub known: Vec<f64>,
    /// K = D − S on the unknowns, CSR (sprs) with sorted columns.
    pub k: CsMat<f64>,
    /// True when K is exactly symmetric (S is).
    pub symmetric: bool,
    /// Right-hand side.
    pub b: Vec<f64>,
}

impl System {
    /// Radiosities of every node from the unknowns' solution.
    pub fn radiosities(&self, x: &[f64]) -> Vec<f64> {
        self.unknown.iter().zip(&self.known).map(|(u, k)| u.map_or(*k, |u| x[u])).collect()
    }
}

/// True when S_ij = S_ji exactly for every stored entry.
pub fn is_symmetric(ex: &Exchange) -> bool {
    ex.fold_mirrored(true, |same, s, sji| same && s == sji)
}

/// Assembles K J = b for per-node emissivities, row kinds and ambient emissive power.
pub fn assemble(ex: &Exchange, eps: &[f64], rows: &[RowKind], e_amb: f64) -> System {
    let n = ex.len();
    let mut unknown = vec![None; n];
    let mut node = Vec::new();
    let mut known = vec![0.0; n];
    for i in 0..n {
        match rows[i] {
            RowKind::Temperature(eb) if eps[i] >= 1.0 => known[i] = eb,
            _ => {
                unknown[i] = Some(node.len());
                node.push(i);
            }
        }
    }
    let ip = ex.indptr();
    let (idx, s) = (ex.s.indices(), ex.s.data());
    let amb = ex.ambient.as_deref();
    let built: Vec<(Vec<usize>, Vec<f64>, f64)> = node
        .par_iter()
        .map(|&i| {
            let a = ex.areas[i];
            let rho = 1.0 - eps[i];
            let (d, mut b) = match rows[i] {
                RowKind::Temperature(eb) => (a / rho, a * eps[i] / rho * eb),
                RowKind::Flux(q) => (a, a * q),
            };
            b += amb.map_or(0.0, |am| am[i]) * e_amb;
            let (mut cols, mut vals) = (Vec::new(), Vec::new());
            let ui = unknown[i].unwrap_or(0);
            let mut diag_done = false;
            for k in ip[i]..ip[i + 1] {
                let j = idx[k];
                match unknown[j] {
                    None => b += s[k] * known[j],
                    Some(uj) => {
                        if uj > ui && !diag_done {
                            cols.push(ui);
                            vals.push(d);
                            diag_done = true;
                        }
                        if uj == ui {
                            cols.push(ui);
                            vals.push(d - s[k]);
                            diag_done = true;
                        } else {
                            cols.push(uj);
                            vals.push(-s[k]);
                        }
                    }
                }
            }
            if !diag_done {
                cols.push(ui);
                vals.push(d);
            }
            (cols, vals, b)
        })
        .collect();
    let mut indptr = vec![0usize];
    let (mut indices, mut data, mut b) = (Vec::new(), Vec::new(), Vec::with_capacity(node.len()));
    for (c, v, bi) in built {
        indices.extend(c);
        data.extend(v);
        b.push(bi);
        indptr.push(indices.len());
    }
    let m = b.len();
    let k = CsMat::new((m, m), indptr, indices, data);
    System { unknown, node, known, k, b, symmetric: is_symmetric(ex) }
}

/// Refuses a system with a group of unknowns that has no temperature anchor (all-flux closed
/// enclosure): K = D − S is singular there. Exit 2: a missing temperature is bad input. One
/// check for every exchange store, on the operator's couplings and the rows' kinds: the
/// unknowns are all nodes but the black temperature ones (J = E_b is known); a given
/// temperature anchors its group whatever its emissivity; a heat-flux row anchors only through
/// a dominance margin A_i − Σ_{j unknown} s_ij (what it loses to the ambient or to black
/// temperature nodes). `surface[i]` is node i's surface, for the message.
pub fn check_anchored(
    scene: &Scene,
    op: &dyn Operator,
    surface: &[usize],
    eps: &[f64],
    rows: &[RowKind],
) -> Result<()> {
    let n = op.len();
    let areas = op.areas();
    let unknown: Vec<bool> =
        (0..n).map(|i| !matches!(rows[i], RowKind::Temperature(_) if eps[i] >= 1.0)).collect();
    if rows.iter().all(|r| matches!(r, RowKind::Temperature(_))) {
        return Ok(());
    }
    let mask: Vec<f64> = unknown.iter().map(|&u| if u { 1.0 } else { 0.0 }).collect();
    let su = op.matvec_scaled(None, &mask);
    let anchored: Vec<bool> = (0..n)
        .map(|i| match rows[i] {
            RowKind::Temperature(_) => true,
            // K_ii = A_i − s_ii; the margin is the row's sum over the unknowns.
            RowKind::Flux(_) => areas[i] - su[i] > ANCHOR_TOL * (areas[i] - op.self_term(i)).abs(),
        })
        .collect();
    let bad = unanchored(&anchored, |join| {
        op.couplings(&mut |i, j| {
            if unknown[i] && unknown[j] {
                join(i, j);
            }
        })
    });
    let Some(&first) = bad.first() else { return Ok(()) };
    let surfaces: Vec<usize> = bad.iter().map(|&i| surface[i]).collect();
    Err(no_anchor(scene, op.names()[first].clone(), surfaces))
}

/// The rows (in order) of the groups that `couplings` joins (it calls its argument on coupled
/// pairs) and that hold no `anchored` row.
fn unanchored(anchored: &[bool], couplings: impl FnOnce(&mut dyn FnMut(usize, usize))) -> Vec<usize> {
    let m = anchored.len();
    if anchored.iter().all(|&a| a) {
        return Vec::new();
    }
    let mut groups = Groups::new(m);
    couplings(&mut |u, v| groups.join(u, v));
    let mut root_ok = vec![false; m];
    for (u, &a) in anchored.iter().enumerate() {
        root_ok[groups.root(u)] |= a;
    }
    (0..m).filter(|&u| !root_ok[groups.root(u)]).collect()
}

/// The refusal of an enclosure with only heat-flux conditions and no ambient: `first` names
/// the row, `surfaces` (in node order) the surfaces of that enclosure.
fn no_anchor(scene: &Scene, first: String, mut surfaces: Vec<usize>) -> Error {
    surfaces.dedup();
    let names: Vec<&str> = surfaces.iter().take(8).map(|&s| scene.surfaces[s].name.as_str()).collect();
    InputError::surface(
        &scene.source,
        first,
        format!(
            "no temperature anchor: the enclosure formed by {} has only heat-flux conditions and \
             sees no ambient, so its temperatures are undetermined (singular system); give at least \
             one of these surfaces a temperature",
            names.join(", ")
        ),
    )
    .into()
}

/// H, q, Q and T of every node from the radiosities J.
pub fn recover(
    ex: &Exchange,
    nodes: &[Node],
    rows: &[RowKind],
    j: &[f64],
    e_amb: f64,
) -> Result<Vec<super::NodeResult>> {
    let ip = ex.indptr();
    let (idx, s) = (ex.s.indices(), ex.s.data());
    (0..ex.len())
        .map(|i| {
            let a = ex.areas[i];
            let inc: f64 = (ip[i]..ip[i + 1]).map(|k| s[k] * j[idx[k]]).sum::<f64>()
                + ex.ambient.as_ref().map_or(0.0, |am| am[i] * e_amb);
            let h = inc / a;
            let q = j[i] - h;
            let eps = nodes[i].emissivity;
            let temperature = match (rows[i], nodes[i].condition) {
                // The given temperature as given (σT⁴ and back would add round-off).
                (RowKind::Temperature(_), BoundaryCondition::Temperature(t)) => t,
                (RowKind::Temperature(eb), _) => (eb / SIGMA).powf(0.25),
                (RowKind::Flux(qp), _) => {
                    let eb = j[i] + (1.0 - eps) / eps * qp;
                    if eb < 0.0 {
                        return Err(Error::Compute(format!(
                            "{}: the prescribed heat flux {qp} W/m² would need a negative emissive power",
                            ex.names[i]
                        )));
                    }
                    (eb / SIGMA).powf(0.25)
                }
            };
            // A given flux is written back as given; the heat rate stays the solved one, so a
            // solve residual shows in the energy balance instead of being hidden.
            let heat_flux = match rows[i] {
                RowKind::Flux(qp) => qp,
                RowKind::Temperature(_) => q,
            };
            Ok(super::NodeResult {
                temperature,
                heat_flux,
                heat_rate: a * q,
                radiosity: j[i],
                irradiation: h,
            })
        })
        .collect()
}

/// Net heat the ambient gives the scene: Σ_i S_i∞ (E_b∞ − J_i).
pub fn ambient_heat(ex: &Exchange, j: &[f64], e_amb: f64) -> f64 {
    ex.ambient.as_ref().map_or(0.0, |am| am.iter().zip(j).map(|(a, j)| a * (e_amb - j)).sum())
}
