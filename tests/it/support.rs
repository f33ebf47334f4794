//! Helpers shared by the integration tests.

use gtsphere::scene::Scene;
// load_str goes through the streaming reader (1 MiB chunks), as files do.
use gtsphere::vrml::{load_str, LoadOptions, LoadReport};

pub fn load(text: &str) -> (Scene, LoadReport) {
    match load_str("test.wrl", text, &LoadOptions::default()) {
        Ok(r) => r,
        Err(e) => panic!("load failed:\n{e}"),
    }
}

/// Loads `#VRML V2.0 utf8` + `body`.
pub fn scene(body: &str) -> (Scene, LoadReport) {
    load(&format!("#VRML V2.0 utf8\n{body}"))
}

/// The error message of a scene that must fail, as printed (`file:line:col: message` ...).
pub fn error_of(text: &str) -> String {
    match load_str("test.wrl", text, &LoadOptions::default()) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

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

pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// A fresh, empty directory `group/name` under the target dir's test scratch space.
pub fn scratch(group: &str, name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(group)
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// SplitMix64: a small deterministic generator for the tests (`f` uniform in [0, 1)).
pub struct Rng(pub u64);

impl Rng {
    pub fn f(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
