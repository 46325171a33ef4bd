#![no_main]
//! The clash-set file parser (`clash_set::parse`) on fuzzed text: every check merged with the
//! defaults, turned into its command line and validated. An `Err` must be one line naming the
//! file.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::clash_set(data);
});
