#![no_main]
//! The whole two-file check (`meshclash A B`, through `cli::run`) on two fuzzed inputs.
//!
//! Byte 0 picks the formats of A and B (2 bits each) and four switches (scene mode,
//! `--split-bodies`, `--penetration`, a clearance); byte 1 is where A ends (in 64ths of the
//! rest); the rest is split into A and B. Inputs that load into more than the small caps of
//! `meshclash_fuzz::whole` are skipped so that a legitimately large scene is not an OOM report.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::whole(data);
});
