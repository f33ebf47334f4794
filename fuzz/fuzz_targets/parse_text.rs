//! Like `parse`, with a valid VRML97 header prepended so the fuzzer starts past it.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

const HEADER: &[u8] = b"#VRML V2.0 utf8\n";

fuzz_target!(|data: &[u8]| {
    let mut bytes = Vec::with_capacity(HEADER.len() + data.len());
    bytes.extend_from_slice(HEADER);
    bytes.extend_from_slice(data);
    common::check(bytes);
});
