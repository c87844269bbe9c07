//! `lambert` binary: parse, run, map errors to docs/SPEC.md exit codes (0 ok, 1 failed, 2 bad input).
//!
//! A panic is a bug whatever the input. Should one happen, the panic hook reports it as one line,
//! `lambert: internal error: <message> at <file:line>; please report it`, with no backtrace, and
//! the process exits with code 101 (Rust's code for a panic). `LAMBERT_BACKTRACE=1` adds the
//! backtrace; `RUST_BACKTRACE` alone does not.
use clap::Parser;
use std::process::ExitCode;

mod cli;

/// Environment variable that adds a backtrace to an internal-error report.
const BACKTRACE_VAR: &str = "LAMBERT_BACKTRACE";

/// Environment variable that makes the binary panic at once: tests the internal-error report.
const PANIC_SELF_TEST_VAR: &str = "LAMBERT_PANIC_SELF_TEST";

fn main() -> ExitCode {
    install_panic_hook();
    if std::env::var_os(PANIC_SELF_TEST_VAR).is_some() {
        panic!("self-test panic requested by {PANIC_SELF_TEST_VAR};\nthe report joins its lines");
    }
    let args = match cli::args::Cli::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    cli::say::set_quiet(args.quiet);
    // Under mpirun (feature `mpi`) every rank ends with rank 0's code; a no-op otherwise.
    lambert::distributed::start();
    let code = match cli::run::run(args.command) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("lambert: error: {}", e.spelled(&cli::args::flag));
            e.exit_code()
        }
    };
    ExitCode::from(lambert::distributed::finish(code))
}

/// Replaces Rust's panic report (message, thread name, backtrace hint) with one line.
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str))
            .unwrap_or("a panic without a message");
        let message = message.split_whitespace().collect::<Vec<_>>().join(" ");
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("lambert: internal error: {message}{at}; please report it");
        if std::env::var_os(BACKTRACE_VAR).is_some_and(|v| v != "0") {
            eprintln!("{}", std::backtrace::Backtrace::force_capture());
        }
    }));
}
