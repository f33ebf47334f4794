//! Inputs that once broke an invariant, named after what they guard.

use std::path::Path;

use gtsphere::vrml::{load_path, LoadOptions};

/// fuzz/regressions: nested Transforms whose product overflows or underflows. Each matrix is
/// finite alone, so the check must be on what the contents became. Found by hand while fuzzing.
#[test]
fn composed_transforms_that_overflow_are_positioned_errors() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions");
    let cases = [
        (
            "scale-overflow-radius-inf.wrl",
            "2:46: this Transform makes a sphere radius overflow or underflow (inf)",
        ),
        // The inner Transform already overflows the radius (1e300 * 1e300) before any NaN.
        (
            "scale-overflow-radius-nan.wrl",
            "2:46: this Transform makes a sphere radius overflow or underflow (inf)",
        ),
        (
            "translation-overflow-centre-inf.wrl",
            "2:1: this Transform makes a sphere centre overflow ([inf, 0, 0])",
        ),
        (
            "scale-underflow-radius-zero.wrl",
            "2:1: this Transform makes a sphere radius overflow or underflow (0)",
        ),
    ];
    for (file, want) in cases {
        let path = dir.join(file);
        let e = load_path(&path, &LoadOptions::default())
            .expect_err(file)
            .to_string();
        let head = e.lines().next().unwrap_or("");
        assert_eq!(head, format!("{}:{want}", path.display()), "{file}");
    }
}

#[test]
fn large_but_representable_transforms_still_load() {
    let text = "#VRML V2.0 utf8\nTransform { scale 1e150 1e150 1e150 translation 1e300 0 0 children Shape { geometry Sphere { radius 1e-100 } } }";
    let (s, _) =
        gtsphere::vrml::load_bytes("big.wrl", text.as_bytes().to_vec(), &LoadOptions::default())
            .expect("representable");
    assert_eq!(s.spheres[0].radius, 1e50);
    assert_eq!(s.spheres[0].center.x, 1e300);
}
