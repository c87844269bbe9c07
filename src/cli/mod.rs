//! Command line: clap arguments ([`args`]) become a validated [`config::Config`] before any
//! work starts ([`limits`]: ranges, caps and cost warnings); [`run`] orchestrates library
//! calls and holds no physics ([`points`]: `viewfactors --points`; [`say`]: notes that `-q`
//! silences, and warnings; [`shards`]: `viewfactors --shard` and `merge`).
pub mod args;
pub mod config;
pub mod limits;
pub mod points;
pub mod run;
pub mod say;
pub mod shards;
