#![no_main]
//! `meshclash::load::load_bytes` as Glb on arbitrary bytes; invariants checked on `Ok`.

use libfuzzer_sys::fuzz_target;
use meshclash::load::Format;

fuzz_target!(|data: &[u8]| {
    meshclash_fuzz::check("fuzz.glb", data, Format::Glb);
});
