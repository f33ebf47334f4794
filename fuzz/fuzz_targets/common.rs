// Shared by the fuzz targets: load bytes and check the scene's invariants.

use gtsphere::vrml::{load_bytes, LoadOptions};

pub fn check(bytes: Vec<u8>) {
    let opts = LoadOptions {
        expansion_base: 200_000,
        inline: false,
        ..Default::default()
    };
    // Any input: Ok or Err, never a panic, hang or unbounded memory.
    let Ok((scene, report)) = load_bytes("fuzz.wrl", bytes, &opts) else {
        return;
    };
    // The expansion limit: the base plus max_expansion per byte read; nodes spend from it.
    let limit = opts.expansion_base + opts.max_expansion * report.bytes;
    assert!(
        report.nodes <= report.expansion && report.expansion <= limit,
        "nodes {}, spent {}, limit {limit}",
        report.nodes,
        report.expansion
    );
    for (i, s) in scene.spheres.iter().enumerate() {
        assert!(
            s.radius.is_finite() && s.radius > 0.0,
            "sphere {i}: radius {} not finite and > 0",
            s.radius
        );
        assert!(s.center.is_finite(), "sphere {i}: centre {} not finite", s.center);
        assert!(
            (s.material as usize) < scene.materials.len(),
            "sphere {i}: material index {} out of range ({})",
            s.material,
            scene.materials.len()
        );
        assert!(
            scene.materials.holds(s.color),
            "sphere {i}: colour {:?} not in the materials",
            s.color
        );
        assert!(
            s.ellipsoid.is_none_or(|e| e.index() < scene.ellipsoids.len()),
            "sphere {i}: ellipsoid index {:?} out of range ({})",
            s.ellipsoid,
            scene.ellipsoids.len()
        );
    }
    for (i, s) in scene.surfaces.iter().enumerate() {
        assert!(s.is_sound(), "surface {i}: not finite or not invertible: {s:?}");
        assert!(
            (s.material as usize) < scene.materials.len(),
            "surface {i}: material index {} out of range ({})",
            s.material,
            scene.materials.len()
        );
        assert!(
            scene.materials.holds(s.color),
            "surface {i}: colour {:?} not in the materials",
            s.color
        );
    }
    // Touch the derived values.
    let b = scene.bounds();
    assert_eq!(
        b.is_some(),
        !scene.spheres.is_empty() || !scene.surfaces.is_empty()
    );
    let _ = scene.surface_counts();
    let _ = scene.gas_count();
    let _ = scene.ellipsoid_count();
    let _ = scene.point_light_count();
    let _ = scene.directional_light_count();
    let _ = scene.heap_bytes();
    std::hint::black_box((&b, &report.warnings, &report.skipped));
}
