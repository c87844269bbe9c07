//! Reports: the one place that turns results into bytes (CSV, charts) and reads saved results
//! back.
//! - [`csv`]: the `viewfactors` matrix;
//! - [`solve_csv`]: the `solve` table and radiative conductances;
//! - [`decks`]: conductances as SINDA/FLUINT and ESATAN network decks;
//! - [`points_csv`]: points read for `viewfactors --points`, and their factors written;
//! - [`read_vf`]: a saved `viewfactors` CSV, matched to a scene (`solve --viewfactors`);
//! - [`charts`]: log–log charts of the validation studies (SVG, PNG);
//! - `mesh`: patch polygons as a welded mesh, cell values averaged to vertices;
//! - [`vtk`]: VTK XML (.vtu/.vtp) for ParaView (`--vtk`);
//! - [`outputs`]: the files of a run, checked before any work and put in place together;
//! - [`render`]: false-colour pictures of a result on the geometry (`lambert render`).
pub mod charts;
pub mod csv;
pub mod decks;
pub(crate) mod dense_csv;
pub(crate) mod mesh;
pub mod outputs;
pub mod points_csv;
pub mod read_vf;
pub mod render;
pub mod solve_csv;
pub mod vtk;
pub mod writers;

/// Characters the exponent form must save before it replaces the plain form (keeps "1000").
const EXPONENT_MIN_SAVING: usize = 3;

/// Full-precision text for an f64 (docs/SPEC.md): the shortest round-trip digits, in plain form unless
/// the exponent form is clearly shorter (tiny or huge magnitudes); both forms round-trip exactly.
/// Negative zero is written `0`: the sign of a zero is round-off, never a result.
pub fn fmt_f64(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
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
    if x == 0.0 {
        // The standard error of every deterministic entry: no formatting machinery; -0 is 0.
        out.push('0');
        return;
    }
    if !x.is_finite() {
        out.push_str(&fmt_f64(x));
        return;
    }
    let mut buf = Small::default();
    let _ = write!(buf, "{x:e}");
    let sci = buf.as_str();
    let (mant, exp) = sci.split_once('e').expect("exponent form");
    let exp: i64 = exp.parse().expect("exponent");
    let (neg, mant) = mant.strip_prefix('-').map_or((false, mant), |m| (true, m));
    let (lead, frac) = mant.split_once('.').unwrap_or((mant, ""));
    let m = (lead.len() + frac.len()) as i64;
    let plain_len = i64::from(neg)
        + if exp < 0 {
            2 + (-exp - 1) + m
        } else if m <= exp + 1 {
            exp + 1
        } else {
            m + 1
        };
    if sci.len() as i64 + EXPONENT_MIN_SAVING as i64 <= plain_len {
        out.push_str(sci);
        return;
    }
    if neg {
        out.push('-');
    }
    let digit = |k: i64| if k == 0 { lead } else { &frac[(k - 1) as usize..k as usize] };
    if exp < 0 {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', (-exp - 1) as usize));
        out.push_str(lead);
        out.push_str(frac);
    } else if m <= exp + 1 {
        out.push_str(lead);
        out.push_str(frac);
        out.extend(std::iter::repeat_n('0', (exp + 1 - m) as usize));
    } else {
        for k in 0..=exp {
            out.push_str(digit(k));
        }
        out.push('.');
        out.push_str(&frac[exp as usize..]);
    }
}

/// A stack buffer for one formatted f64 (the exponent form takes at most 24 bytes).
#[derive(Default)]
struct Small {
    buf: [u8; 32],
    len: usize,
}

impl Small {
    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.buf[..self.len]).expect("ASCII")
    }
}

impl std::fmt::Write for Small {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        if end > self.buf.len() {
            return Err(std::fmt::Error);
        }
        self.buf[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
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

    #[test]
    fn negative_zero_is_written_as_zero() {
        assert_eq!(fmt_f64(-0.0), "0");
        let mut s = String::new();
        push_f64(&mut s, -0.0);
        assert_eq!(s, "0");
        assert_eq!(fmt_f64(-1e-300), "-1e-300", "a negative number keeps its sign");
    }
}
