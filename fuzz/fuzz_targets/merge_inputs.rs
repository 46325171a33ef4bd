#![no_main]
//! See `meshclash_fuzz::merge_inputs`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::merge_inputs(data);
});
