#![no_main]
//! `--baseline REPORT` on a fuzzed report: `baseline::parse`, and on success the whole check
//! of two small meshes compared against it (`cli::run` with `--baseline` and `--fail-on new`).

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::baseline(data);
});
