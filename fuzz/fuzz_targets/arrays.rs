#![no_main]
//! See `meshclash_fuzz::arrays`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::arrays(data);
});
