#![no_main]
//! See `meshclash_fuzz::writers`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::writers(data);
});
