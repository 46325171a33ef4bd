//! The app layer, in the binary's module tree (the library never sees clap or the spinner):
//! [`args`] the clap definitions, [`config`] their validation into a [`config::Config`],
//! [`run`] running one, [`clash_set`] the `clash-set` runner (each check becomes the same
//! `Config` as its command line), [`self_cmd`] the `self` subcommand, [`progress`] the spinner,
//! [`man`] the generated texts (schema, completions, man page).
//!
//! Sibling modules are named through `super::`, the library through `meshclash::`.

pub mod args;
pub mod clash_set;
pub mod config;
pub mod man;
pub mod progress;
pub mod run;
pub mod self_cmd;
pub mod shard;
