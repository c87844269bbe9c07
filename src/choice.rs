//! Named choices: the closed enums a user picks by name (view-factor method, exchange store,
//! solver, enforcement, conductance format, length unit, rendered field). Each derives clap's
//! [`ValueEnum`], so its names come from the compiler-checked enum (kebab or snake case of the
//! variant, as docs/SPEC.md spells them): the CLI's `--help` lists them, and [`parse`], [`names`]
//! and [`write()`] serve the library's `FromStr` / `Display` and the Python binding.
use crate::{Error, Result};
/// The trait every choice derives (re-exported so that callers name it without clap).
pub use clap::ValueEnum;
use std::fmt;

/// The value named exactly `s` (case matters), or `None`.
pub fn parse<T: ValueEnum>(s: &str) -> Option<T> {
    T::from_str(s, false).ok()
}

/// The names of the values a user may pick, in declaration order.
pub fn names<T: ValueEnum>() -> Vec<String> {
    T::value_variants()
        .iter()
        .filter_map(|v| v.to_possible_value())
        .map(|p| p.get_name().to_string())
        .collect()
}

/// The value named `s`, or a usage error in the library's words: "unknown `what` 's';
/// expected one of a, b, c".
pub fn parse_or<T: ValueEnum>(what: &str, s: &str) -> Result<T> {
    parse(s).ok_or_else(|| Error::Usage(unknown::<T>(what, s)))
}

/// "unknown `what` 's'; expected one of a, b, c" (the library's message, and the binding's
/// with its keyword as `what`).
pub fn unknown<T: ValueEnum>(what: &str, s: &str) -> String {
    format!("unknown {what} '{s}'; expected one of {}", names::<T>().join(", "))
}

/// Writes the name of `v` (a `Display` body); a value hidden from users writes its `Debug`
/// form.
pub fn write<T: ValueEnum + fmt::Debug>(v: &T, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    match v.to_possible_value() {
        Some(p) => f.pad(p.get_name()),
        None => write!(f, "{v:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exchange::Enforce;
    use crate::plan::Store;
    use crate::report::decks::DeckFormat;
    use crate::report::render::values::Field;
    use crate::scene::mesh_model::Unit;
    use crate::solve::Solver;
    use crate::viewfactor::Method;

    /// Every name round-trips through `parse` and `Display`.
    fn round_trips<T: ValueEnum + fmt::Display + PartialEq + fmt::Debug>(want: &[&str]) {
        assert_eq!(names::<T>(), want);
        for n in want {
            let v: T = parse(n).unwrap_or_else(|| panic!("{n}"));
            assert_eq!(v.to_string(), *n);
        }
        assert!(parse::<T>("nonsense").is_none());
    }

    #[test]
    fn the_names_are_spec_s_spelling() {
        round_trips::<Method>(&[
            "auto",
            "analytic",
            "hemicube",
            "single-plane",
            "mc-area",
            "mc-uniform",
            "mc-cosine",
        ]);
        round_trips::<Store>(&["auto", "dense", "hierarchical"]);
        round_trips::<Solver>(&["direct", "jacobi", "gauss-seidel"]);
        round_trips::<Enforce>(&["none", "reciprocity", "closure"]);
        round_trips::<DeckFormat>(&["csv", "sinda", "esatan"]);
        round_trips::<Unit>(&["m", "mm", "cm", "in", "ft"]);
        round_trips::<Field>(&[
            "temperature",
            "heat_flux",
            "heat_rate",
            "radiosity",
            "irradiation",
            "emissivity",
            "area",
        ]);
    }

    #[test]
    fn unknown_names_are_refused_in_the_library_s_words() {
        let e = parse_or::<Method>("method", "Auto").unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            e.to_string(),
            "unknown method 'Auto'; expected one of auto, analytic, hemicube, single-plane, mc-area, \
             mc-uniform, mc-cosine"
        );
        // The reference-only sparse store has no user name.
        assert!(parse::<Store>("sparse").is_none());
        assert_eq!(Store::Sparse.to_string(), "Sparse");
    }
}
