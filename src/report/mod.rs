//! Reports: the one place that turns results into bytes (CSV, charts) and reads saved results
//! back.
//! - [`csv`]: the `viewfactors` matrix;
//! - [`solve_csv`]: the `solve` table and radiative conductances;
//! - [`decks`]: conductances as SINDA/FLUINT and ESATAN network decks;
//! - [`read_vf`]: a saved `viewfactors` CSV, matched to a scene (`solve --viewfactors`);
//! - [`charts`]: log–log charts of the validation studies (SVG, PNG).
pub mod charts;
pub mod csv;
pub mod decks;
pub mod dense_csv;
pub mod read_vf;
pub mod solve_csv;

/// Characters the exponent form must save before it replaces the plain form (keeps "1000").
const EXPONENT_MIN_SAVING: usize = 3;

/// Full-precision text for an f64 (SPEC.md): the shortest round-trip digits, in plain form unless
/// the exponent form is clearly shorter (tiny or huge magnitudes); both forms round-trip exactly.
pub fn fmt_f64(x: f64) -> String {
    let plain = x.to_string();
    let sci = format!("{x:e}");
    if sci.len() + EXPONENT_MIN_SAVING <= plain.len() {
        sci
    } else {
        plain
    }
}

/// Appends exactly [`fmt_f64`]`(x)` to `out` with one shortest-digits conversion: the plain
/// form is rebuilt from the exponent form's digits (both forms print the same shortest digits).
pub fn push_f64(out: &mut String, x: f64) {
    use std::fmt::Write;
    if x == 0.0 || !x.is_finite() {
        out.push_str(&fmt_f64(x));
        return;
    }
    let start = out.len();
    let _ = write!(out, "{x:e}");
    let sci = out[start..].to_string();
    let (mant, exp) = sci.split_once('e').expect("exponent form");
    let exp: i64 = exp.parse().expect("exponent");
    let (neg, mant) = mant.strip_prefix('-').map_or((false, mant), |m| (true, m));
    let digits: String = mant.chars().filter(|c| *c != '.').collect();
    let m = digits.len() as i64;
    let sign = usize::from(neg);
    let plain_len = sign as i64
        + if exp < 0 {
            2 + (-exp - 1) + m
        } else if m <= exp + 1 {
            exp + 1
        } else {
            m + 1
        };
    if sci.len() as i64 + EXPONENT_MIN_SAVING as i64 <= plain_len {
        return;
    }
    out.truncate(start);
    if neg {
        out.push('-');
    }
    if exp < 0 {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-exp - 1) as usize));
        out.push_str(&digits);
    } else if m <= exp + 1 {
        out.push_str(&digits);
        out.extend(std::iter::repeat_n('0', (exp + 1 - m) as usize));
    } else {
        out.push_str(&digits[..(exp + 1) as usize]);
        out.push('.');
        out.push_str(&digits[(exp + 1) as usize..]);
    }
}

#[cfg(test)]
mod tests {
    use super::{fmt_f64, push_f64};

    #[test]
    fn push_f64_equals_fmt_f64() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let mut xs = vec![0.0, -0.0, 1.0, -1.0, 1000.0, 1e300, 1e-300, 0.001, 12345.678, -7.5e-5, 1e21, 1e22];
        for _ in 0..20000 {
            let e: i32 = rng.random_range(-30..30);
            let x: f64 = rng.random_range(-1.0..1.0) * 10f64.powi(e);
            xs.push(x);
            xs.push(x.round());
        }
        for x in xs {
            let mut s = String::from("prefix,");
            push_f64(&mut s, x);
            assert_eq!(&s[7..], fmt_f64(x), "{x:e}");
        }
    }

    #[test]
    fn shortest_round_trip() {
        for x in [0.0, 1.0, -0.5, 7.275957614183426e-12, 1e300, 0.19982489569838732, 21386.617834354303] {
            let s = fmt_f64(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
            assert!(s.len() <= x.to_string().len(), "{s}");
        }
        assert_eq!(fmt_f64(7.275957614183426e-12), "7.275957614183426e-12");
        assert_eq!(fmt_f64(1000.0), "1000");
        assert_eq!(fmt_f64(1e300), "1e300");
    }
}
