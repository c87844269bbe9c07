//! Watertight clipping by several half-spaces k·(p, 1) ≥ 0 (Sutherland–Hodgman, crossings
//! interpolated from the inside vertex): projection windows in the eye's local frame, before
//! the perspective divide.
//!
//! A projection window (a hemicube face, the single plane) is a pyramid whose four side planes
//! pass through the eye, so clipping by them is exact for polygons that straddle the patch
//! plane or several faces; only a near plane w ≥ ε (ε ≪ every patch) guards the divide.
use glam::{DVec3, DVec4};

/// A half-space a·x + b·y + c·z + d ≥ 0, local coordinates.
pub(crate) type HalfSpace = DVec4;

/// Signed value of `h` at `p`.
#[inline]
fn eval(h: HalfSpace, p: DVec3) -> f64 {
    h.x * p.x + h.y * p.y + h.z * p.z + h.w
}

/// True when the sphere (centre, radius) lies wholly outside one of the half-spaces.
pub(crate) fn sphere_outside(planes: &[HalfSpace], centre: DVec3, radius: f64) -> bool {
    planes.iter().any(|h| eval(*h, centre) < -radius * h.truncate().length())
}

/// Clips the ring `input` by every half-space; the result is left in `out` (fewer than three
/// vertices means nothing is left). `tmp` is scratch.
pub(crate) fn clip_polygon(
    input: &[DVec3],
    planes: &[HalfSpace],
    out: &mut Vec<DVec3>,
    tmp: &mut Vec<DVec3>,
) {
    out.clear();
    out.extend_from_slice(input);
    for h in planes {
        if out.len() < 3 {
            out.clear();
            return;
        }
        let (mut inside, mut outside) = (0usize, 0usize);
        for p in out.iter() {
            if eval(*h, *p) >= 0.0 {
                inside += 1;
            } else {
                outside += 1;
            }
        }
        if outside == 0 {
            continue;
        }
        if inside == 0 {
            out.clear();
            return;
        }
        tmp.clear();
        let n = out.len();
        for k in 0..n {
            let (a, b) = (out[k], out[(k + 1) % n]);
            let (da, db) = (eval(*h, a), eval(*h, b));
            if da >= 0.0 {
                tmp.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                // Interpolate from the inside vertex so the new point is bit-identical for
                // the two polygons that share this edge.
                let (p, q, dp, dq) = if da >= 0.0 { (a, b, da, db) } else { (b, a, db, da) };
                tmp.push(p + (q - p) * (dp / (dp - dq)));
            }
        }
        std::mem::swap(out, tmp);
    }
    if out.len() < 3 {
        out.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shoelace area of a ring projected on z = const.
    fn area_xy(v: &[DVec3]) -> f64 {
        let n = v.len();
        0.5 * (0..n).map(|k| v[k].x * v[(k + 1) % n].y - v[(k + 1) % n].x * v[k].y).sum::<f64>()
    }

    #[test]
    fn square_clipped_by_a_pyramid_keeps_the_inside_part() {
        // Square [-2, 2]² at z = 1 against the top-face pyramid |x| ≤ z, |y| ≤ z.
        let sq = [
            DVec3::new(-2.0, -2.0, 1.0),
            DVec3::new(2.0, -2.0, 1.0),
            DVec3::new(2.0, 2.0, 1.0),
            DVec3::new(-2.0, 2.0, 1.0),
        ];
        let planes = [
            DVec4::new(-1.0, 0.0, 1.0, 0.0),
            DVec4::new(1.0, 0.0, 1.0, 0.0),
            DVec4::new(0.0, -1.0, 1.0, 0.0),
            DVec4::new(0.0, 1.0, 1.0, 0.0),
        ];
        let (mut out, mut tmp) = (Vec::new(), Vec::new());
        clip_polygon(&sq, &planes, &mut out, &mut tmp);
        assert!((area_xy(&out) - 4.0).abs() < 1e-14, "{out:?}");
        assert!(!sphere_outside(&planes, DVec3::new(0.0, 0.0, 1.0), 0.1));
        assert!(sphere_outside(&planes, DVec3::new(5.0, 0.0, 1.0), 1.0));
    }

    #[test]
    fn polygon_straddling_the_eye_plane_is_cut_at_it() {
        // A wall x = 0.5, z ∈ [-1, 1], against z ≥ 0: half remains.
        let wall = [
            DVec3::new(0.5, -0.5, -1.0),
            DVec3::new(0.5, 0.5, -1.0),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(0.5, -0.5, 1.0),
        ];
        let (mut out, mut tmp) = (Vec::new(), Vec::new());
        clip_polygon(&wall, &[DVec4::new(0.0, 0.0, 1.0, 0.0)], &mut out, &mut tmp);
        assert_eq!(out.len(), 4);
        assert!(out.iter().all(|p| p.z >= 0.0));
        clip_polygon(&wall, &[DVec4::new(0.0, 0.0, 1.0, -2.0)], &mut out, &mut tmp);
        assert!(out.is_empty());
    }
}
