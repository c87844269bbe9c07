//! Reads a saved `viewfactors` CSV for `solve --viewfactors` and matches it to a scene:
//! surface level (names = surfaces) or patch level (`surface#k`), detected from the first row.
//! Extra columns are ignored, `to = ambient` rows are recomputed, a `std_error` column is kept.
//! A `geometry` fingerprint (report::csv) other than the scene's, or two different ones, is
//! a file written for another geometry; files without one (older files, hand-made exact
//! factors) load on the names alone. Unknown names, nodes without rows, duplicates and bad
//! numbers are input errors (exit 2).
use crate::error::InputError;
use crate::scene::Scene;
use crate::viewfactor::{Entry, Level, MethodSet, ViewFactors};
use crate::Result;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::time::Duration;

/// Names listed in a mismatch message.
const LIST: usize = 8;

/// Reads `path` and returns view factors in the scene's node order.
pub fn read_viewfactors(path: &Path, scene: &Scene) -> Result<ViewFactors> {
    read_stamped(path, scene).map(|(vf, _)| vf)
}

/// As [`read_viewfactors`], and whether the file carried the scene's geometry fingerprint
/// (false: an older or hand-made file, matched on its names only).
pub fn read_stamped(path: &Path, scene: &Scene) -> Result<(ViewFactors, bool)> {
    let bad = |problem: String| InputError::file(path, problem);
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| bad(format!("cannot read the view-factor file: {e}")))?;
    let headers = rdr.headers().map_err(|e| bad(format!("cannot read the header: {e}")))?.clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(cf), Some(ct), Some(cv)) = (col("from"), col("to"), col("factor")) else {
        return Err(bad("the header must contain from,to,factor (a `lambert viewfactors` CSV)".into()).into());
    };
    let cs = col("std_error");
    let cg = col(crate::report::csv::GEOMETRY);
    let mut stamp: Option<(String, usize)> = None;
    let surfaces: HashMap<String, usize> =
        scene.surfaces.iter().enumerate().map(|(i, s)| (s.name.clone(), i)).collect();
    let patches: HashMap<String, usize> =
        (0..scene.patches.len()).map(|p| (scene.patch_name(p), p)).collect();
    let mut level = None;
    let mut rows: Vec<BTreeMap<u32, (f64, f64)>> = Vec::new();
    let mut seen_from: Vec<bool> = Vec::new();
    let mut unknown: Vec<String> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| bad(format!("malformed CSV: {e}")))?;
        let line = rec.position().map_or(0, |p| p.line() as usize);
        let field = |c: usize| rec.get(c).unwrap_or("");
        let (from, to) = (field(cf), field(ct));
        if let Some(g) = cg.map(field).filter(|g| !g.is_empty()) {
            match &stamp {
                None => stamp = Some((g.to_string(), line)),
                Some((first, at)) if first != g => {
                    return Err(bad(format!(
                        "two geometry fingerprints ({first} on line {at}, {g} here): rows of files written \
                         for different geometries"
                    ))
                    .at_line(line)
                    .into())
                }
                Some(_) => {}
            }
        }
        let lvl = *level.get_or_insert_with(|| {
            let l = if surfaces.contains_key(from) || !patches.contains_key(from) {
                Level::Surface
            } else {
                Level::Patch
            };
            let n = if l == Level::Surface { scene.surfaces.len() } else { scene.patches.len() };
            rows = vec![BTreeMap::new(); n];
            seen_from = vec![false; n];
            l
        });
        let map = if lvl == Level::Surface { &surfaces } else { &patches };
        let Some(&i) = map.get(from) else {
            unknown.push(from.to_string());
            continue;
        };
        seen_from[i] = true;
        if to == crate::solve::AMBIENT {
            continue;
        }
        let Some(&j) = map.get(to) else {
            unknown.push(to.to_string());
            continue;
        };
        let num = |c: usize, what: &str| -> Result<f64> {
            let s = field(c);
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(bad(format!("{what} '{s}' is not a finite number")).at_line(line).into()),
            }
        };
        let f = num(cv, "factor")?;
        let se = match cs {
            Some(c) if !field(c).is_empty() => num(c, "std_error")?,
            _ => 0.0,
        };
        if rows[i].insert(j as u32, (f, se)).is_some() {
            return Err(bad(format!("duplicate row {from} -> {to}")).at_line(line).into());
        }
    }
    let Some(level) = level else {
        return Err(bad("the view-factor file has no rows".into()).into());
    };
    let ours = crate::scene::fingerprint::geometry(scene);
    if let Some((theirs, at)) = &stamp {
        if *theirs != ours {
            return Err(bad(format!(
                "the view factors were computed for another geometry (fingerprint {theirs}; this scene's \
                 is {ours}): a different scene, or these surfaces moved, reshaped or subdivided differently. \
                 Compute the view factors again for this scene, or, if the geometry is the same in every way the \
                 factors depend on, empty the geometry field to use the file anyway"
            ))
            .at_line(*at)
            .into());
        }
    }
    if !unknown.is_empty() {
        unknown.sort();
        unknown.dedup();
        let what = if level == Level::Surface { "surfaces" } else { "patches" };
        return Err(bad(format!(
            "{} name(s) not among the scene's {what}: {}",
            unknown.len(),
            unknown.iter().take(LIST).cloned().collect::<Vec<_>>().join(", ")
        ))
        .into());
    }
    let names: Vec<String> = match level {
        Level::Surface => scene.surfaces.iter().map(|s| s.name.clone()).collect(),
        Level::Patch => (0..scene.patches.len()).map(|p| scene.patch_name(p)).collect(),
    };
    let missing: Vec<&str> =
        names.iter().zip(&seen_from).filter(|(_, s)| !**s).map(|(n, _)| n.as_str()).collect();
    if !missing.is_empty() {
        return Err(bad(format!(
            "the scene's {} missing from the file ({} without any row): {}",
            if level == Level::Surface { "surfaces are" } else { "patches are" },
            missing.len(),
            missing.iter().take(LIST).copied().collect::<Vec<_>>().join(", ")
        ))
        .into());
    }
    let areas: Vec<f64> = match level {
        Level::Surface => scene.surfaces.iter().map(|s| s.area).collect(),
        Level::Patch => scene.patch_areas(),
    };
    let rows: Vec<Vec<Entry>> = rows
        .into_iter()
        .map(|r| {
            r.into_iter()
                .map(|(to, (factor, std_error))| Entry {
                    to,
                    factor,
                    std_error,
                    method: MethodSet::default(),
                })
                .collect()
        })
        .collect();
    let sums: Vec<f64> = rows.iter().map(|r| r.iter().map(|e| e.factor).sum()).collect();
    // Patch row sums: exact at patch level, the surface's sum for each of its patches otherwise.
    let patch_row_sums = match level {
        Level::Patch => sums,
        Level::Surface => scene.patches.iter().map(|p| sums[p.surface]).collect(),
    };
    let vf = ViewFactors {
        level,
        names,
        areas,
        rows,
        patch_row_sums,
        patch_samples: vec![0; scene.patches.len()],
        pairs: 0,
        wall: Duration::ZERO,
        flags: Vec::new(),
        warnings: Vec::new(),
    };
    Ok((vf, stamp.is_some()))
}
