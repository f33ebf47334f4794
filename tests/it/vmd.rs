//! VMD's exporter colours every sphere through `PROTO VMDMat`: expansion decides whether VMD
//! scenes have colour at all. The fixture copies VMD 1.9.4's Vrml2DisplayDevice byte layout;
//! the expected values are worked out by hand in tests/data/vmd_style.expected.md.

use std::path::Path;

use gtsphere::vrml::{load_path, LoadOptions};

use super::support::close;

// 0.3927 below is the radius VMD printed with %g, not an approximation of pi/8.
#[allow(clippy::approx_constant)]
const R6: f64 = 0.3927;

#[test]
fn vmd_style_file_reads_with_colours_from_the_proto() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/vmd_style.wrl");
    let (s, r) = load_path(&path, &LoadOptions::default()).expect("vmd fixture");
    // (centre, radius, diffuse, transparency) from the expected table.
    let want: [([f64; 3], f64, [f64; 3], f64); 6] = [
        (
            [-0.145635, 0.0161001, -0.0417191],
            0.098175,
            [0.1625, 0.4875, 0.4875],
            0.0,
        ),
        (
            [0.107269, -0.00437832, -0.157858],
            0.08778,
            [0.65, 0.0, 0.0],
            0.0,
        ),
        (
            [-0.504363, 0.654327, 0.119128],
            0.0895125,
            [0.0, 0.0, 0.65],
            0.0,
        ),
        (
            [-0.52118, -0.373684, 0.541287],
            0.0693,
            [0.65, 0.65, 0.65],
            0.0,
        ),
        (
            [0.563471, 0.29673, -0.711657],
            0.35112,
            [0.65, 0.0, 0.0],
            0.0,
        ),
        (
            [0.500438, -0.589095, 0.25082],
            R6,
            [0.1625, 0.4875, 0.4875],
            0.7,
        ),
    ];
    assert_eq!(s.spheres.len(), 6);
    for (b, (c, rad, kd, t)) in s.spheres.iter().zip(want) {
        for k in 0..3 {
            assert!(close(b.center[k], c[k], 1e-12), "{} vs {c:?}", b.center);
        }
        assert!(close(b.radius, rad, 1e-12));
        let m = s.material_of(b);
        assert!(!m.unlit, "VMDMat must give a lit material");
        for k in 0..3 {
            assert!(close(m.diffuse[k], kd[k], 1e-12), "{} vs {kd:?}", m.diffuse);
            assert!(close(m.specular[k], 0.5, 1e-12));
            assert_eq!(m.emissive[k], 0.0);
        }
        assert_eq!(m.transparency, t);
        assert_eq!(m.ambient_intensity, 0.0);
        // VMD writes shininess 40 (its raw exponent); VRML97 clamps to [0, 1].
        assert_eq!(m.shininess, 1.0);
    }
    // 5 distinct VMD materials, four opaque ones apart from their colours, one gas: two
    // records, plus the built-in unlit white.
    assert_eq!(s.materials.len(), 3);
    assert_eq!(s.gas_count(), 1);
    // Its two bonds are Cylinders, drawn now.
    assert_eq!(
        (r.skipped.get("Cylinder"), s.surface_counts().cylinders),
        (None, 2)
    );
    assert!(s.lights.is_empty() && s.viewpoints.is_empty() && s.headlight);
    let shin: Vec<_> = r
        .warnings
        .iter()
        .filter(|w| w.message.contains("shininess 40"))
        .collect();
    assert_eq!(shin.len(), 1, "{:?}", r.warnings);
}
