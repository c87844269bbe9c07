//! False colour: the viridis map (perceptually uniform, readable in grey and by colour-blind
//! viewers), value ranges and "nice" colour-bar ticks.

/// Viridis at t = 0, 1/8, …, 1 (matplotlib's table, rounded to 8 bits); linear in between.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 145, 140],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Colour of t ∈ [0, 1] (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let mut c = [0u8; 3];
    for i in 0..3 {
        let (a, b) = (VIRIDIS[k][i] as f64, VIRIDIS[k + 1][i] as f64);
        c[i] = (a + (b - a) * f).round() as u8;
    }
    c
}

/// The colour range of `values` (finite ones), widened when they are all equal so a constant
/// field maps to the middle colour.
pub fn range(values: &[f64]) -> (f64, f64) {
    let (lo, hi) = values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi > lo {
        (lo, hi)
    } else {
        let pad = (lo.abs() * 1e-3).max(1e-12);
        (lo - pad, hi + pad)
    }
}

/// Tick values inside [lo, hi] on a 1–2–2.5–5 × 10^k step, about `target` of them, with the
/// decimals needed to tell them apart.
pub fn ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, usize) {
    let raw = (hi - lo) / target.max(1) as f64;
    if !(raw > 0.0) || !raw.is_finite() {
        return (vec![lo], 0);
    }
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
    let first = (lo / step).ceil();
    let last = (hi / step).floor();
    let ticks: Vec<f64> = (0..=((last - first) as i64).max(0)).map(|k| (first + k as f64) * step).collect();
    let mut decimals = (-step.log10().floor()).max(0.0) as usize;
    if (step / 10f64.powi(-(decimals as i32)) - 2.5).abs() < 1e-9 {
        decimals += 1;
    }
    (ticks, decimals)
}

/// Tick label with `decimals` digits after the point; exponent form for huge or tiny values.
pub fn label(v: f64, decimals: usize) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-4..1e7).contains(&a) {
        format!("{v:.2e}")
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_middle_of_viridis() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        assert_eq!(viridis(-3.0), VIRIDIS[0]);
        assert_eq!(viridis(f64::NAN), VIRIDIS[0]);
    }

    #[test]
    fn nice_ticks() {
        let (t, d) = ticks(400.0, 1000.0, 6);
        assert_eq!(t, vec![400.0, 500.0, 600.0, 700.0, 800.0, 900.0, 1000.0]);
        assert_eq!(d, 0);
        let (t, d) = ticks(0.12, 0.93, 4);
        assert_eq!(t, vec![0.25, 0.5, 0.75]);
        assert_eq!((label(t[0], d), label(t[1], d)), ("0.25".to_string(), "0.50".to_string()));
        let (t, d) = ticks(0.12, 0.93, 8);
        assert_eq!((t.len(), d, label(t[0], d)), (4, 1, "0.2".to_string()));
        let (t, d) = ticks(0.0, 1.0, 4);
        assert_eq!(t, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(label(t[1], d), "0.25");
        assert_eq!(range(&[3.0, 3.0]), (3.0 - 3e-3, 3.0 + 3e-3));
    }
}
