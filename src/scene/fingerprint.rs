//! The geometry fingerprint of a scene: a 64-bit FNV-1a hash of every patch polygon (its
//! surface index and the bits of its vertices, in scene order) and every obstruction polygon.
//! View factors depend on nothing else, so a saved `viewfactors` file carries it and
//! `solve --viewfactors` refuses a file written for another geometry (report::read_vf).
//!
//! Exact bits, not rounded values: the same scene file loads to the same patches, and a
//! tolerance would need a boundary that round-off can cross. Moving, reshaping or
//! re-subdividing a surface changes the fingerprint; emissivities, temperatures, names and
//! `[ambient]` do not.
use super::Scene;
use crate::geometry::Polygon;
use std::hash::Hasher;

/// Prefix naming the hash, so the value never reads as a number and a later scheme can be told
/// apart.
pub const PREFIX: &str = "fnv1a64:";

/// The fingerprint as written in files: [`PREFIX`] and 16 lowercase hex digits.
pub fn geometry(scene: &Scene) -> String {
    let mut h = fnv::FnvHasher::default();
    word(&mut h, scene.patches.len() as u64);
    for p in &scene.patches {
        polygon(&mut h, p.surface as u64, &p.polygon);
    }
    word(&mut h, scene.obstructions.len() as u64);
    for (k, o) in scene.obstructions.iter().enumerate() {
        for p in &o.polygons {
            polygon(&mut h, k as u64, p);
        }
    }
    format!("{PREFIX}{:016x}", h.finish())
}

/// Little-endian bytes, so the value is the same on every platform.
fn word(h: &mut fnv::FnvHasher, x: u64) {
    h.write(&x.to_le_bytes());
}

/// An owner index, the vertex count and every coordinate's bits.
fn polygon(h: &mut fnv::FnvHasher, owner: u64, p: &Polygon) {
    word(h, owner);
    word(h, p.vertices().len() as u64);
    for v in p.vertices() {
        for c in v.to_array() {
            word(h, c.to_bits());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::DVec3;
    use crate::scene::BoundaryCondition;

    fn square(z: f64, flip: bool) -> Polygon {
        let mut v = vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(0.0, 1.0, z),
        ];
        if flip {
            v.reverse();
        }
        Polygon::new(v).unwrap()
    }

    fn plates(gap: f64, eps: f64, name: &str) -> Scene {
        Scene::builder()
            .surface(name, vec![square(0.0, false)], eps, Some(BoundaryCondition::Temperature(300.0)))
            .surface("top", vec![square(gap, true)], 0.5, None)
            .build()
    }

    #[test]
    fn geometry_changes_the_fingerprint_and_properties_do_not() {
        let base = geometry(&plates(1.0, 0.8, "bottom"));
        assert!(base.starts_with(PREFIX) && base.len() == PREFIX.len() + 16, "{base}");
        assert_eq!(base, geometry(&plates(1.0, 0.8, "bottom")), "stable");
        assert_eq!(base, geometry(&plates(1.0, 0.3, "floor")), "emissivity and names are not geometry");
        assert_ne!(base, geometry(&plates(1.0 + 1e-15, 0.8, "bottom")), "a moved plate");
        let mut ambient = plates(1.0, 0.8, "bottom");
        ambient.ambient = Some(crate::scene::Ambient { temperature: 300.0 });
        assert_eq!(base, geometry(&ambient));
        let blocked = Scene::builder()
            .surface("bottom", vec![square(0.0, false)], 0.8, None)
            .surface("top", vec![square(1.0, true)], 0.5, None)
            .obstruction("shade", vec![square(0.5, false)])
            .build();
        assert_ne!(base, geometry(&blocked), "an obstruction");
    }
}
