//! `lambert` binary: parse, run, map errors to SPEC.md exit codes (0 ok, 1 failed, 2 bad input).
use clap::Parser;
use std::process::ExitCode;

mod cli;

fn main() -> ExitCode {
    let args = match cli::args::Cli::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    match cli::run::run(args.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("lambert: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
