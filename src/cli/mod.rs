//! Command line: clap arguments ([`args`]) become a validated [`config::Config`] before any
//! work starts; [`run`] orchestrates library calls and holds no physics.
pub mod args;
pub mod config;
pub mod run;
