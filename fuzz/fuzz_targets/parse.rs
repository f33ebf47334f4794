//! Raw bytes into `gtsphere::vrml::load_bytes` (plain or gzip, any encoding).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    common::check(data.to_vec());
});
