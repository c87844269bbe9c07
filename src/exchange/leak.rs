//! Why a closed scene leaks: the hint printed with a leak warning or refusal, checked against
//! the geometry facts ([`SceneFacts`]) before it is said.
//!
//! In order, each cause is named only when the facts show it:
//! 1. mesh surfaces wound against themselves (repair flips them);
//! 2. closed meshes facing inward inside the scene (flipped bodies);
//! 3. an opening: the surfaces' area vectors do not cancel (|Σ A n| bounds the opening's
//!    projected area from below), with the open meshes and their boundary-edge counts;
//! 4. no enclosure: everything faces outward. A body is never told to flip; only a closed
//!    mesh that surrounds the whole scene is offered the flip, beside `[ambient]`;
//! 5. sampling: the geometry shows none of the above and every leaking row carries sampled
//!    entries (std_error > 0). Then sampling, not geometry, is named, with the rows, the
//!    worst sampled entry and the rows that are slivers.
//!
//! [`rows_from_viewfactors`], [`rows_from_exchange`] and [`rows_from_triangle`] read the
//! leaking rows' sampled entries from each store.
use super::Exchange;
use crate::error::opt;
use crate::scene::orientation::SceneFacts;
use crate::viewfactor::ViewFactors;

/// Leaking rows named in a hint.
const NAMED_ROWS: usize = 5;

/// A sampled entry of a leaking row.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledEntry {
    /// Column name.
    pub to: String,
    /// F(row → to).
    pub factor: f64,
    /// Its standard error.
    pub std_error: f64,
}

/// One leaking row and its sampled entries.
#[derive(Debug, Clone, PartialEq)]
pub struct LeakRow {
    /// Row name (`surface` or `surface#k`).
    pub name: String,
    /// Σ_j F_ij.
    pub row_sum: f64,
    /// Entries with a standard error.
    pub sampled: usize,
    /// Entries of any kind (0: the row found nothing at all).
    pub entries: usize,
    /// The one with the largest standard error.
    pub worst: Option<SampledEntry>,
}

impl LeakRow {
    /// A row named `name` with row sum `row_sum` and no entries yet.
    pub fn new(name: &str, row_sum: f64) -> Self {
        Self { name: name.to_string(), row_sum, sampled: 0, entries: 0, worst: None }
    }
    /// The same row with nothing counted yet (the start of a merge across MPI ranks).
    pub(crate) fn emptied(&self) -> Self {
        Self::new(&self.name, self.row_sum)
    }

    /// The counts and worst entry, as bytes for [`LeakRow::merge_bytes`].
    pub(crate) fn partial_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&(self.entries as u64).to_le_bytes());
        b.extend_from_slice(&(self.sampled as u64).to_le_bytes());
        if let Some(w) = &self.worst {
            b.push(1);
            b.extend_from_slice(&(w.to.len() as u64).to_le_bytes());
            b.extend_from_slice(w.to.as_bytes());
            b.extend_from_slice(&w.factor.to_bits().to_le_bytes());
            b.extend_from_slice(&w.std_error.to_bits().to_le_bytes());
        } else {
            b.push(0);
        }
        b
    }

    /// Adds the counts of [`LeakRow::partial_bytes`] at the start of `b` and takes its worst
    /// entry when larger (as [`LeakRow::add`] would, entry by entry); returns the rest of `b`.
    pub(crate) fn merge_bytes<'a>(&mut self, b: &'a [u8]) -> Option<&'a [u8]> {
        let word = |b: &[u8], o: usize| Some(u64::from_le_bytes(b.get(o..o + 8)?.try_into().ok()?));
        self.entries += usize::try_from(word(b, 0)?).ok()?;
        self.sampled += usize::try_from(word(b, 8)?).ok()?;
        if *b.get(16)? == 0 {
            return Some(&b[17..]);
        }
        let len = usize::try_from(word(b, 17)?).ok()?;
        let to = String::from_utf8_lossy(b.get(25..25 + len)?).into_owned();
        let (factor, std_error) = (f64::from_bits(word(b, 25 + len)?), f64::from_bits(word(b, 33 + len)?));
        if self.worst.as_ref().is_none_or(|w| std_error > w.std_error) {
            self.worst = Some(SampledEntry { to, factor, std_error });
        }
        Some(&b[41 + len..])
    }

    pub(super) fn add(&mut self, to: &str, factor: f64, std_error: f64) {
        self.entries += usize::from(factor != 0.0);
        if std_error > 0.0 {
            self.sampled += 1;
            if self.worst.as_ref().is_none_or(|w| std_error > w.std_error) {
                self.worst = Some(SampledEntry { to: to.to_string(), factor, std_error });
            }
        }
    }
}

/// The leaking rows `(row, row sum)` of a view-factor matrix.
pub fn rows_from_viewfactors(vf: &ViewFactors, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
    leaks
        .iter()
        .map(|&(i, sum)| {
            let mut r = LeakRow::new(&vf.names[i], sum);
            for e in &vf.rows[i] {
                r.add(&vf.names[e.to as usize], e.factor, e.std_error);
            }
            r
        })
        .collect()
}

/// The leaking rows `(row, row sum)` of a sparse exchange matrix.
pub fn rows_from_exchange(ex: &Exchange, leaks: &[(usize, f64)]) -> Vec<LeakRow> {
    let (ip, cols, s) = (ex.indptr(), ex.s.indices(), ex.s.data());
    leaks
        .iter()
        .map(|&(i, sum)| {
            let mut r = LeakRow::new(&ex.names[i], sum);
            for k in ip[i]..ip[i + 1] {
                let a = ex.areas[i];
                r.add(&ex.names[cols[k]], s[k] / a, ex.var[k].sqrt() / a);
            }
            r
        })
        .collect()
}

/// The hint for `rows` (worst first), or an empty string when the facts name no cause.
pub fn hint(facts: &SceneFacts, rows: &[LeakRow]) -> String {
    let mut says: Vec<String> = Vec::new();
    let leaking: Vec<usize> = rows.iter().filter_map(|r| facts.surface_of(&r.name)).collect();
    let on_leaking = |name: &str| leaking.iter().any(|&s| facts.names[s] == name);

    // 1. Winding.
    for d in facts.defects.iter().filter(|d| d.against > 0) {
        says.push(format!(
            "surface '{}' has {} triangles wound against their neighbours, so part of it faces the wrong way; \
             repair = true (or {}) flips them",
            d.surface,
            d.against,
            opt("repair")
        ));
    }
    // 2. Inward bodies inside the scene.
    for b in facts.bodies.iter().filter(|b| b.volume < 0.0 && !b.encloses_scene) {
        says.push(format!(
            "a closed mesh of surface '{}' ({:.3e} m³) faces inward inside the scene: it is seen from inside \
             and shows its back to the rest; if it is a body, reverse its winding (repair = true turns it \
             outward)",
            b.surfaces.join("', '"),
            -b.volume
        ));
    }
    // 3. An opening.
    let open: Vec<String> = facts
        .defects
        .iter()
        .filter(|d| d.boundary_edges > 0 && (on_leaking(&d.surface) || facts.all_checked_meshes))
        .map(|d| format!("'{}' is an open mesh, {} boundary edges", d.surface, d.boundary_edges))
        .collect();
    if !facts.closes() {
        let mut s = format!(
            "the exchanging surfaces do not close: their area vectors sum to {:.3e} m² ({:.1e} of their area) \
             where a closed set sums to 0, so an opening at least that large, or surfaces facing the wrong way",
            facts.area_vector,
            facts.area_vector / facts.area
        );
        if !open.is_empty() {
            s.push_str(&format!(" ({})", open.join("; ")));
        }
        s.push_str(&format!("; close it, or {}", ambient_advice(facts)));
        says.push(s);
    } else if !open.is_empty() {
        // Open meshes among the leaking rows' surfaces (or anywhere, when the mesh checks see
        // the whole scene): small openings leave the area vectors cancelling, but sight lines
        // through them still leave, or reach back faces, which take no exchange.
        says.push(format!(
            "{}; radiation leaves through the openings (or reaches back faces, which take none), whatever \
             the method's accuracy",
            open.join("; ")
        ));
    }
    // 4. No enclosure: everything faces outward.
    let outward: Vec<&crate::scene::orientation::Body> =
        facts.bodies.iter().filter(|b| b.volume > 0.0).collect();
    if facts.closes() && facts.volume >= 0.0 && !outward.is_empty() {
        let around: Vec<_> = outward.iter().filter(|b| b.encloses_scene).collect();
        if let [b] = around.as_slice() {
            says.push(format!(
                "surface '{}' is a closed mesh whose normals all face outward around the rest of the scene, so \
                 it sees nothing from inside; if it is the enclosure, reverse its triangles' winding (flip its \
                 normals); if the scene is open, {}",
                b.surfaces.join("', '"),
                ambient_advice(facts)
            ));
        } else {
            let mut names: Vec<String> = Vec::new();
            for b in &outward {
                let n = b.surfaces.join("', '");
                if !names.contains(&n) {
                    names.push(n);
                }
            }
            says.push(format!(
                "nothing encloses the scene: its {} closed meshes (of surface '{}') face outward, bodies seen \
                 from outside, and no surface surrounds them, so the scene is open: {}",
                outward.len(),
                names.join("', '"),
                ambient_advice(facts)
            ));
        }
    }
    if !says.is_empty() {
        return sentences(&says);
    }
    // 5. Sampling.
    let sound = format!(
        "the geometry shows no cause (the surfaces' area vectors cancel, {}no mesh is wound against itself)",
        if facts.all_checked_meshes { "every mesh is closed, " } else { "" }
    );
    if rows.is_empty() {
        return String::new();
    }
    if rows.iter().any(|r| r.sampled == 0) {
        let (sampled, empty) =
            (rows.iter().filter(|r| r.sampled > 0).count(), rows.iter().filter(|r| r.entries == 0).count());
        if sampled == 0 && empty == 0 {
            return String::new();
        }
        return sentences(&[format!(
            "{sound}; of the {} leaking rows, {sampled} carry sampled entries and {empty} have no entry at all \
             (a sampling method that found nothing from them): more samples, a tighter {} or \
             {} analytic will tell sampling from geometry",
            rows.len(),
            opt("tolerance"),
            opt("method")
        )]);
    }
    let named: Vec<String> = rows
        .iter()
        .take(NAMED_ROWS)
        .map(|r| format!("{} (row sum {:.6}, {} sampled entries)", r.name, r.row_sum, r.sampled))
        .collect();
    let worst = rows
        .iter()
        .filter_map(|r| r.worst.as_ref().map(|w| (r, w)))
        .max_by(|a, b| a.1.std_error.total_cmp(&b.1.std_error));
    let mut s = format!(
        "{sound} and every leaking row carries sampled entries: sampling, not geometry, is the cause. Rows: {}",
        named.join(", ")
    );
    if let Some((r, w)) = worst {
        s.push_str(&format!(
            "; worst sampled entry {} → {}: F = {:.6e} ± {:.1e}",
            r.name, w.to, w.factor, w.std_error
        ));
    }
    let slivers = rows
        .iter()
        .filter(|r| facts.patch_of(&r.name).is_some_and(|p| facts.sliver_patches.contains(&p)))
        .count();
    if slivers > 0 {
        s.push_str(&format!("; {slivers} of these rows are sliver triangles (repair = true drops slivers)"));
    }
    s.push_str(&format!(
        "; a tighter {} or {} analytic computes these pairs again",
        opt("tolerance"),
        opt("method")
    ));
    sentences(&[s])
}

/// Sentences joined, each starting with a capital letter.
fn sentences(parts: &[String]) -> String {
    let cap = |s: &String| {
        let mut c = s.chars();
        c.next().map(|f| f.to_uppercase().chain(c).collect::<String>()).unwrap_or_default()
    };
    parts.iter().map(cap).collect::<Vec<_>>().join(". ")
}

fn ambient_advice(facts: &SceneFacts) -> &'static str {
    if facts.bare {
        "load the file as a [[model]] of a TOML scene with an [ambient] (a bare mesh scene is closed)"
    } else {
        "add an [ambient]"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::orientation::{Body, MeshDefect};

    /// A room (inward, around everything) with a part inside (outward): closed and enclosed.
    fn room_and_part() -> SceneFacts {
        SceneFacts {
            names: vec!["room".into(), "part".into()],
            patch_start: vec![0, 6],
            area_vector: 0.0,
            area: 60.0,
            volume: -26.0,
            bodies: vec![
                Body { surfaces: vec!["room".into()], volume: -27.0, encloses_scene: true },
                Body { surfaces: vec!["part".into()], volume: 1.0, encloses_scene: false },
            ],
            all_checked_meshes: true,
            sliver_patches: vec![7],
            ..SceneFacts::default()
        }
    }

    fn row(name: &str, sum: f64, sampled: &[(&str, f64, f64)]) -> LeakRow {
        let mut r = LeakRow::new(name, sum);
        for &(to, f, sd) in sampled {
            r.add(to, f, sd);
        }
        r
    }

    #[test]
    fn sampled_rows_in_a_sound_scene_blame_sampling_and_name_the_worst_entry() {
        let rows = [
            row("part#1", 0.906, &[("room#2", 0.1, 1e-4), ("room#3", 0.2, 3e-3), ("part#4", 0.1, 0.0)]),
            row("room#0", 0.95, &[("part#1", 0.05, 1e-3)]),
        ];
        let h = hint(&room_and_part(), &rows);
        assert!(h.starts_with("The geometry shows no cause"), "{h}");
        assert!(h.contains("sampling, not geometry, is the cause"), "{h}");
        assert!(h.contains(
            "part#1 (row sum 0.906000, 2 sampled entries), room#0 (row sum 0.950000, 1 sampled entries)"
        ));
        assert!(h.contains("worst sampled entry part#1 → room#3: F = 2.000000e-1 ± 3.0e-3"), "{h}");
        assert!(h.contains("1 of these rows are sliver triangles"), "{h}");
        assert!(!h.contains("reverse") && !h.contains("flip"), "{h}");
    }

    #[test]
    fn a_row_without_sampled_entries_is_not_blamed_on_sampling() {
        let exact = row("room#0", 0.9, &[("part#1", 0.1, 0.0)]);
        assert_eq!(hint(&room_and_part(), std::slice::from_ref(&exact)), "");
        let rows = [row("part#1", 0.9, &[("room#2", 0.1, 1e-4)]), exact, row("room#3", 0.0, &[])];
        let h = hint(&room_and_part(), &rows);
        assert!(h.starts_with("The geometry shows no cause"), "{h}");
        assert!(
            h.contains("of the 3 leaking rows, 1 carry sampled entries and 1 have no entry at all"),
            "{h}"
        );
        assert!(!h.contains("sampling, not geometry"), "{h}");
    }

    #[test]
    fn geometry_causes_come_before_sampling() {
        let mut f = room_and_part();
        f.defects.push(MeshDefect { surface: "part".into(), boundary_edges: 0, against: 3 });
        let rows = [row("part#1", 0.9, &[("room#2", 0.1, 1e-4)])];
        let h = hint(&f, &rows);
        assert!(
            h.contains("Surface 'part' has 3 triangles wound against their neighbours")
                && !h.contains("sampling")
        );
        // An opening: the area vectors do not cancel, the open mesh is named.
        let mut f = room_and_part();
        f.area_vector = 0.5;
        f.defects.push(MeshDefect { surface: "room".into(), boundary_edges: 4, against: 0 });
        let h = hint(&f, &[row("room#0", 0.9, &[])]);
        assert!(h.contains("do not close") && h.contains("'room' is an open mesh, 4 boundary edges"), "{h}");
        assert!(h.contains("add an [ambient]") && !h.contains("reverse"), "{h}");
    }

    /// An open part in a room of shapes: its small openings leave the area vectors cancelling,
    /// but its leaking rows are blamed on the openings, never on sampling.
    #[test]
    fn an_open_part_is_blamed_before_sampling_even_when_the_area_vectors_cancel() {
        let mut f = room_and_part();
        f.all_checked_meshes = false;
        f.defects.push(MeshDefect { surface: "part".into(), boundary_edges: 54, against: 0 });
        let rows = [row("part#1", 0.978, &[("room#2", 0.1, 5e-5)])];
        let h = hint(&f, &rows);
        assert!(
            h.contains("'part' is an open mesh, 54 boundary edges; radiation leaves through the openings"),
            "{h}"
        );
        assert!(!h.contains("sampling") && !h.contains("tolerance"), "{h}");
        // An open surface whose rows do not leak is not named when the checks see only part of
        // the scene.
        let h = hint(&f, &[row("room#0", 0.978, &[("part#1", 0.1, 5e-5)])]);
        assert!(h.contains("sampling, not geometry") && !h.contains("open mesh"), "{h}");
    }

    #[test]
    fn outward_bodies_without_an_enclosure_are_never_told_to_flip() {
        let f = SceneFacts {
            names: vec!["a".into(), "b".into()],
            patch_start: vec![0, 10],
            area: 10.0,
            volume: 2.0,
            bodies: vec![
                Body { surfaces: vec!["a".into()], volume: 1.0, encloses_scene: false },
                Body { surfaces: vec!["b".into()], volume: 1.0, encloses_scene: false },
            ],
            bare: true,
            ..SceneFacts::default()
        };
        let h = hint(&f, &[row("a", 0.0, &[]), row("b", 0.0, &[])]);
        assert!(
            h.starts_with("Nothing encloses the scene: its 2 closed meshes (of surface 'a', 'b')"),
            "{h}"
        );
        assert!(h.contains("[[model]] of a TOML scene with an [ambient]") && !h.contains("reverse"), "{h}");
        // One outward mesh around everything may be a wrongly wound enclosure: both options.
        let f = SceneFacts {
            bodies: vec![Body { surfaces: vec!["room".into()], volume: 27.0, encloses_scene: true }],
            names: vec!["room".into()],
            patch_start: vec![0],
            area: 54.0,
            volume: 27.0,
            ..SceneFacts::default()
        };
        let h = hint(&f, &[row("room", 0.0, &[])]);
        assert!(
            h.contains("if it is the enclosure, reverse its triangles' winding")
                && h.contains("add an [ambient]")
        );
    }

    #[test]
    fn partial_rows_merged_in_order_equal_the_rows_added_in_one_pass() {
        // Entries of one leaking row as two MPI ranks see them: rank 0 the first three,
        // rank 1 the rest. Two entries tie on the largest error: the first one seen wins.
        let entries =
            [("a", 0.1, 0.0), ("b", 0.2, 0.03), ("c", 0.0, 0.01), ("d", 0.3, 0.03), ("e", 0.1, 0.02)];
        let mut whole = LeakRow::new("w#0", 0.6);
        entries.iter().for_each(|e| whole.add(e.0, e.1, e.2));
        let mut parts = [LeakRow::new("w#0", 0.6), LeakRow::new("w#0", 0.6)];
        entries[..3].iter().for_each(|e| parts[0].add(e.0, e.1, e.2));
        entries[3..].iter().for_each(|e| parts[1].add(e.0, e.1, e.2));
        let mut merged = parts[0].emptied();
        for p in &parts {
            let bytes = p.partial_bytes();
            assert_eq!(merged.merge_bytes(&bytes), Some(&[][..]));
        }
        assert_eq!(merged, whole);
        assert_eq!(whole.worst.as_ref().map(|w| w.to.as_str()), Some("b"));
        assert!(merged.merge_bytes(&parts[1].partial_bytes()[..20]).is_none(), "a cut record is refused");
    }
}
