//! The union of many plane polygons in one boolean operation (Clipper2's sweep, the
//! `clipper2-rust` crate).
//!
//! - [`Union`] collects rings ([`Union::push`]), then [`Union::run`] returns the region
//!   where their winding number is not zero (rings may cross themselves and each other; an
//!   outline whose holes turn clockwise gives its holes), optionally intersected with a
//!   second set of rings (the clip).
//! - The result is a set of oriented contours: outer boundaries counter-clockwise, holes
//!   clockwise, so any contour integral (area, Lambert's formula) over the region is the sum
//!   of the signed integrals over its contours.
//! - Coordinates go through Clipper2's 64-bit integer engine on a grid of 2⁻⁵² of the given
//!   bounds (a power of two, so the scaling itself is exact): the round-off of the inputs, so
//!   the union is exact up to the rounding of its new crossing points.
//! - One sweep, whatever the input: `i_overlay` (used before) split nearly collinear edges of
//!   a meshed part's silhouette again and again, minutes and gigabytes on thirteen rings.
use clipper2_rust::{boolean_op_64, union_subjects_64, ClipType, FillRule, Path64, Paths64, Point64};
use glam::DVec2;
use std::ops::Range;

/// Margin added around the given bounds, as a fraction of their size: the rings' round-off
/// may put points a hair outside.
const BOUNDS_MARGIN_REL: f64 = 1e-3;

/// Grid steps across the bounds: about the f64 round-off of coordinates of that size, well
/// inside the engine's coordinate range (2⁶²).
const GRID_BITS: i32 = 52;

/// Rings to unite, and the buffers of the last result (reused across calls).
#[derive(Debug, Clone, Default)]
pub struct Union {
    points: Vec<DVec2>,
    rings: Vec<Range<usize>>,
    clip_points: Vec<DVec2>,
    clip_rings: Vec<Range<usize>>,
    contour_points: Vec<DVec2>,
    contours: Vec<Range<usize>>,
}

impl Union {
    /// Forgets every ring.
    pub fn clear(&mut self) {
        self.points.clear();
        self.rings.clear();
        self.clip_points.clear();
        self.clip_rings.clear();
    }
    /// Adds a ring to unite.
    pub fn push(&mut self, ring: &[DVec2]) {
        let start = self.points.len();
        self.points.extend_from_slice(ring);
        self.rings.push(start..self.points.len());
    }
    /// Adds a ring of the clip: the union is intersected with the clip rings' union.
    pub fn push_clip(&mut self, ring: &[DVec2]) {
        let start = self.clip_points.len();
        self.clip_points.extend_from_slice(ring);
        self.clip_rings.push(start..self.clip_points.len());
    }

    /// The union of the rings (∩ the clip's, when there are clip rings), every point of which
    /// lies in the box `[lo, hi]`; its contours are read with [`Self::contours`].
    pub fn run(&mut self, [lo, hi]: [DVec2; 2]) {
        self.contour_points.clear();
        self.contours.clear();
        if self.rings.is_empty() || !(lo.x <= hi.x && lo.y <= hi.y) {
            return;
        }
        let span = (hi - lo).max_element();
        let margin = BOUNDS_MARGIN_REL * span.max(lo.abs().max(hi.abs()).max_element());
        let origin = lo - DVec2::splat(margin);
        let size = span + 2.0 * margin;
        if !(size > 0.0 && size.is_finite()) {
            return;
        }
        // A power of two: size · scale ≤ 2^GRID_BITS.
        let scale = 2f64.powi(GRID_BITS - size.log2().ceil() as i32);
        let to_int = |q: &DVec2| {
            let g = (*q - origin) * scale;
            Point64::new(g.x.round() as i64, g.y.round() as i64)
        };
        let paths = |points: &[DVec2], rings: &[Range<usize>]| -> Paths64 {
            rings.iter().map(|r| points[r.clone()].iter().map(to_int).collect::<Path64>()).collect()
        };
        let subjects = paths(&self.points, &self.rings);
        let out = if self.clip_rings.is_empty() {
            union_subjects_64(&subjects, FillRule::NonZero)
        } else {
            let clips = paths(&self.clip_points, &self.clip_rings);
            boolean_op_64(ClipType::Intersection, FillRule::NonZero, &subjects, &clips)
        };
        let inv = 1.0 / scale;
        for path in &out {
            let start = self.contour_points.len();
            self.contour_points
                .extend(path.iter().map(|p| origin + DVec2::new(p.x as f64, p.y as f64) * inv));
            self.contours.push(start..self.contour_points.len());
        }
    }

    /// The oriented contours of the last [`Self::run`] (outer boundaries counter-clockwise,
    /// holes clockwise).
    pub fn contours(&self) -> impl Iterator<Item = &[DVec2]> + '_ {
        self.contours.iter().map(|r| &self.contour_points[r.clone()])
    }

    /// Area of the last result: the sum of its contours' signed areas (each taken about its
    /// first point, so that far from the origin no digits cancel).
    pub fn area(&self) -> f64 {
        let twice = |c: &[DVec2]| {
            let o = c[0];
            c.windows(2).map(|w| (w[0] - o).perp_dot(w[1] - o)).sum::<f64>()
        };
        0.5 * self.contours().filter(|c| !c.is_empty()).map(twice).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, s: f64) -> Vec<DVec2> {
        vec![DVec2::new(x, y), DVec2::new(x + s, y), DVec2::new(x + s, y + s), DVec2::new(x, y + s)]
    }

    #[test]
    fn overlapping_squares_unite_and_a_ring_of_squares_keeps_its_hole() {
        let mut u = Union::default();
        u.push(&square(0.0, 0.0, 2.0));
        u.push(&square(1.0, 1.0, 2.0));
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        assert!((u.area() - 7.0).abs() < 1e-14, "{}", u.area());
        // Eight unit squares around a missing middle one: area 8, one hole turning clockwise.
        u.clear();
        for k in 0..9 {
            if k != 4 {
                u.push(&square((k % 3) as f64, (k / 3) as f64, 1.0));
            }
        }
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        assert!((u.area() - 8.0).abs() < 1e-14, "{}", u.area());
        let signs: Vec<bool> = u.contours().map(|c| super::super::convex::twice_area(c) > 0.0).collect();
        assert_eq!(signs.len(), 2, "an outer boundary and a hole");
        assert_eq!(signs.iter().filter(|&&s| s).count(), 1);
    }

    #[test]
    fn the_clip_cuts_the_union_and_an_empty_union_is_empty() {
        let mut u = Union::default();
        u.push(&square(0.0, 0.0, 2.0));
        u.push(&square(1.0, 1.0, 2.0));
        // Two clip pieces: [0, 1.5] × [0, 3] and [1.5, 3] × [2.5, 3].
        u.push_clip(&[
            DVec2::new(0.0, 0.0),
            DVec2::new(1.5, 0.0),
            DVec2::new(1.5, 3.0),
            DVec2::new(0.0, 3.0),
        ]);
        u.push_clip(&[
            DVec2::new(1.5, 2.5),
            DVec2::new(3.0, 2.5),
            DVec2::new(3.0, 3.0),
            DVec2::new(1.5, 3.0),
        ]);
        u.run([DVec2::ZERO, DVec2::splat(3.0)]);
        // Left part: 1.5 × 2 + 0.5 × 1 = 3.5; top strip: 1.5 × 0.5 = 0.75.
        assert!((u.area() - 4.25).abs() < 1e-14, "{}", u.area());
        u.clear();
        u.run([DVec2::ZERO, DVec2::ONE]);
        assert_eq!(u.contours().count(), 0);
        assert_eq!(u.area(), 0.0);
    }

    #[test]
    fn tiny_coordinates_keep_their_precision() {
        // Squares of side 2⁻²³ far from the origin, every coordinate exact in f64: the union's
        // area to 1e-12 relative.
        let (o, s) = (DVec2::new(3.0, -2.0), 2f64.powi(-23));
        let mut u = Union::default();
        u.push(&square(o.x, o.y, s));
        u.push(&square(o.x + 0.25 * s, o.y + 0.5 * s, s));
        u.run([o, o + DVec2::splat(1.5 * s)]);
        let want = 2.0 * s * s - 0.75 * s * 0.5 * s;
        assert!((u.area() - want).abs() < 1e-12 * want, "{} vs {want}", u.area());
    }

    /// Six outline loops of a meshed channel seen from one viewpoint (nearly collinear long
    /// edges, ends one ulp apart), on which `i_overlay` 9.1 split edges without end.
    const CHANNEL_LOOPS: &[&[f64]] = &[
        &[
            -0.0014938329914733685,
            0.00202981381340265,
            -0.0015010716060390424,
            -0.0003370609919546455,
            -0.0015028119399266657,
            -0.0009061135909227004,
            0.002949488379304664,
            -0.001121419806060896,
            0.0029506691829240092,
            -0.0011214769078599376,
            0.0029569474755177104,
            -0.001121780516178999,
            0.0029570223163143967,
            -0.0010958745711891552,
            0.002950855396381693,
            -0.0010915437474104915,
            0.0029496145108026477,
            -0.0010906723145346028,
            -0.00019143007550256354,
            0.00111517934766626,
        ],
        &[
            -0.001502811939926666,
            -0.0009061135909227009,
            -0.001425468187367813,
            -0.0009098538127033615,
            0.002961453995661763,
            -0.0011219984443792753,
            0.0029632216908431993,
            -0.0011220839273278064,
            0.0029642204643786007,
            -0.0011221322264393372,
            0.002966221957724869,
            -0.0011222290154980505,
            0.0029696915341681394,
            -0.0011223967987378527,
            0.002973195735366047,
            -0.0011225662563761308,
            0.0029754310967450167,
            -0.001122674354923728,
            0.0029765068926651947,
            -0.001122726378716201,
            0.002980152815870145,
            -0.0011229026898070212,
            0.002982807424447498,
            -0.001123031062487317,
            0.0029828400149251606,
            -0.0011140054865040963,
            0.0029801803078591256,
            -0.0011121376622528392,
            0.002976554974767677,
            -0.0011095917108006788,
            0.0029754862541466493,
            -0.0011088411836771225,
            0.002973267049149662,
            -0.0011072827094508377,
            0.002969750379242274,
            -0.001104813068556708,
            0.00296626248869199,
            -0.0011023636384526391,
            0.0029642862232185257,
            -0.001100975772613804,
            0.0029633010683876903,
            -0.0011002839309791454,
            0.002961559154016595,
            -0.0010990606421638117,
            0.0008979045023740735,
            0.0003501757244198346,
            -0.001493832991473369,
            0.00202981381340265,
            -0.0015003929531347763,
            -0.00011515575772560674,
            -0.0015026684673677478,
            -0.0008592010799882262,
        ],
        &[
            0.0029881308256931795,
            -0.001123288493768158,
            0.0029905363866821366,
            -0.0011234048229002206,
            0.0029917672705965814,
            -0.0011234643465032781,
            0.002991778942575758,
            -0.001120282999565303,
            0.0029905533244882223,
            -0.0011194222885434343,
            0.0029881509386225154,
            -0.0011177351724552952,
            0.0016245446647614305,
            -0.00016011961395659077,
            -0.001075371648526496,
            0.0017359422609481978,
            -0.0014938329914733685,
            0.0020298138134026496,
            -0.0014947484122417062,
            0.001730490464546042,
            -0.0015028119399266655,
            -0.0009061135909227005,
            0.001012822176771793,
            -0.0010277656856835429,
        ],
        &[
            0.00277177729886731,
            -0.0011128259787416064,
            0.0027725522215525785,
            -0.0009663273285518397,
            0.0027628511582919986,
            -0.0009595145928741084,
            0.0027556202015366817,
            -0.0009544365312485072,
            0.002750949944074079,
            -0.0009511567639915561,
            0.002741230910674557,
            -0.0009443314084799554,
            0.0027109073971378138,
            -0.0009230362084594181,
            0.002692628586646898,
            -0.0009101996047766067,
            -0.0014938329914733687,
            0.002029813813402649,
            -0.0015028119399266655,
            -0.0009061135909227011,
            0.0026918788152874924,
            -0.0011089622142016124,
            0.0027096470478539525,
            -0.0011098214578799987,
            0.002740793958412101,
            -0.0011113276733067889,
            0.002750432303528582,
            -0.0011117937684617498,
            0.0027552250314484736,
            -0.0011120255372182636,
            0.0027622864665276564,
            -0.0011123670170716726,
        ],
        &[
            0.0028492965300147633,
            -0.0010202223165834794,
            0.002842658076574899,
            -0.001015560350427821,
            0.0028293802787948213,
            -0.001006235792466674,
            0.002828127020960877,
            -0.0010053556709656213,
            0.0028189936156682274,
            -0.0009989415826925083,
            0.002804707387497075,
            -0.0009889088374410357,
            0.002795757724110816,
            -0.0009826237850279658,
            0.0027865071618367035,
            -0.0009761274212840035,
            0.002046927204747527,
            -0.0004567448933223065,
            0.001891345654896056,
            -0.0003474851197285343,
            0.001105998935621146,
            0.0002040378906959427,
            -0.001499207365621088,
            0.0002725064378831556,
            -0.001500231891922486,
            -6.249212685633377e-05,
            -0.0015019333003339294,
            -0.0006188169133374836,
            -0.0015028119399266657,
            -0.0009061135909227007,
            0.0027860017058234936,
            -0.0011135138486076833,
            0.0027951770180730984,
            -0.0011139575522241326,
            0.0028040623394169238,
            -0.001114387232338157,
            0.0028185101546961567,
            -0.0011150859058780692,
            0.0028277372210350556,
            -0.0011155321122405801,
            0.0028289103111561026,
            -0.0011155888410270198,
            0.0028414105378960115,
            -0.0011161933322595904,
            0.0028487020251201835,
            -0.001116545937071576,
            0.002850287106093626,
            -0.0011166225890852789,
            0.002852841355406326,
            -0.0011167461085499612,
            0.0028530891231865326,
            -0.0010228857292546888,
            0.0028507467717988617,
            -0.0010212407733936736,
        ],
        &[
            0.002946920322518714,
            -0.0011212956188886027,
            0.002946903916469125,
            -0.0010887687538394687,
            0.0029446460021879555,
            -0.0010871830953639607,
            0.002943415932267418,
            -0.0010863192579671046,
            0.002937371746956005,
            -0.0010820746266511539,
            0.0029353814291741198,
            -0.001080676892341166,
            0.002932630632724743,
            -0.0010787450990305302,
            -0.0014938329914733672,
            0.002029813813402649,
            -0.0014995507415990904,
            0.00016022971093157827,
            -0.0015028119399266657,
            -0.0009061135909227006,
            -0.0005080684831366193,
            -0.000954217814213713,
            0.0029324882259823795,
            -0.0011205977054822838,
            0.0029352155119350956,
            -0.0011207295927257248,
            0.00293719046072162,
            -0.0011208250981314335,
            0.0029431964389730722,
            -0.0011211155377587733,
            0.002944513482245984,
            -0.0011211792278923967,
        ],
    ];
    const CHANNEL_BOUNDS: [f64; 4] =
        [-0.0015028119399266655, -0.0011237002224799694, 0.002996644931400048, 0.002029813813402649];

    /// Winding number of the closed ring about q (crossings of the ray to +x).
    fn winding(ring: &[DVec2], q: DVec2) -> i32 {
        let mut w = 0;
        for (a, b) in ring.iter().zip(ring.iter().cycle().skip(1)) {
            if (a.y <= q.y) != (b.y <= q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > q.x {
                    w += if b.y > a.y { 1 } else { -1 };
                }
            }
        }
        w
    }

    #[test]
    fn a_meshed_part_s_crossing_silhouette_loops_unite_in_one_sweep() {
        let rings: Vec<Vec<DVec2>> =
            CHANNEL_LOOPS.iter().map(|r| r.chunks(2).map(|c| DVec2::new(c[0], c[1])).collect()).collect();
        let [x0, y0, x1, y1] = CHANNEL_BOUNDS;
        let mut u = Union::default();
        for r in &rings {
            u.push(r);
        }
        u.run([DVec2::new(x0, y0), DVec2::new(x1, y1)]);
        // Independent estimate: cell centres of a 1000 × 1000 grid over the bounds where the
        // summed winding number is not zero; its error is about the perimeter times a cell.
        let n = 1000;
        let cell = DVec2::new((x1 - x0) / n as f64, (y1 - y0) / n as f64);
        let mut inside = 0usize;
        for i in 0..n {
            for j in 0..n {
                let q = DVec2::new(x0, y0) + cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5);
                if rings.iter().map(|r| winding(r, q)).sum::<i32>() != 0 {
                    inside += 1;
                }
            }
        }
        let estimate = inside as f64 * cell.x * cell.y;
        let box_area = (x1 - x0) * (y1 - y0);
        assert!(u.area() > 0.0 && u.area() < box_area);
        assert!((u.area() - estimate).abs() < 5e-3 * box_area, "{} vs grid {estimate}", u.area());
        assert!(u.contours().all(|c| c.len() >= 3));
    }
}
