//! What the command line prints on stderr besides errors and the progress report: notes
//! (summaries, timings, row sums, the route, what was written) that `-q` silences, and
//! warnings, which always show. Both are printed with the progress bar out of the way.
use lambert::viewfactor::progress::Display;
use std::fmt::Arguments;
use std::sync::atomic::{AtomicBool, Ordering};

static QUIET: AtomicBool = AtomicBool::new(false);

/// Sets `-q` for the rest of the process.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// True under `-q`.
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A note line, as given (nothing under `-q`).
pub fn note(line: Arguments<'_>) {
    if !quiet() {
        Display::suspend(|| eprintln!("{line}"));
    }
}

/// A warning line, as given (also under `-q`).
pub fn warning(line: Arguments<'_>) {
    let line = lambert::error::spell_options(&line.to_string(), &super::args::flag);
    Display::suspend(|| eprintln!("{line}"));
}
