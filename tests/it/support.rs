//! Helpers shared by the integration tests: the library's test helpers, compiled here from
//! the same file (`src/testing.rs`), so the two cannot drift apart. Test files add what they
//! need for their geometry in their own `impl Rng` (unit vectors, points in a box).

#[allow(dead_code)]
#[path = "../../src/testing.rs"]
mod testing;
pub use testing::*;

use gtsphere::vrml::{load_str, LoadOptions};

/// The error message of a scene that must fail under `--strict`, as printed.
pub fn strict_error_of(text: &str) -> String {
    let opts = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    match load_str("test.wrl", text, &opts) {
        Ok(_) => panic!("expected a strict error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Whether `a` is within `tol` of `b`, relative to `1 + |b|`.
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}
