#![no_main]
//! See `meshclash_fuzz::self_fans`.

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::self_fans(data);
});
