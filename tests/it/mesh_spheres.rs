//! IndexedFaceSets whose vertices lie on a sphere (Jmol's atoms) are lowered as that sphere;
//! other meshes become triangles. Expected centres and radii are computed here from the points
//! the test writes and the Transforms around them.

use glam::DVec3;
use gtsphere::render::{RenderOptions, SamplerKind};
use gtsphere::vrml::{load_path, LoadOptions, LoadReport};

use crate::support::{close, icosahedron, scene, uv_sphere};

/// `point [...]` of `pts` moved to `c` and scaled by `r`, with full precision.
fn points(pts: &[DVec3], c: DVec3, r: f64) -> String {
    let p: Vec<String> = pts
        .iter()
        .map(|p| {
            let q = c + r * *p;
            format!("{:?} {:?} {:?}", q.x, q.y, q.z)
        })
        .collect();
    format!("point [ {} ]", p.join(", "))
}

/// `n` triangles that use every one of `n` points (not a closed surface: recognition reads
/// only which points the faces use).
fn index_all(n: usize) -> String {
    let f: Vec<String> = (0..n)
        .map(|i| format!("{} {} {} -1", i, (i + 1) % n, (i + 2) % n))
        .collect();
    format!("coordIndex [ {} ]", f.join(" "))
}

fn ifs(pts: &[DVec3], c: DVec3, r: f64) -> String {
    format!(
        "IndexedFaceSet {{ creaseAngle 0.5 coord Coordinate {{ {} }} {} }}",
        points(pts, c, r),
        index_all(pts.len())
    )
}

fn skipped_ifs(r: &LoadReport) -> u64 {
    r.skipped.get("IndexedFaceSet").copied().unwrap_or(0)
}

#[test]
fn icosahedron_mesh_is_a_sphere_under_translation_and_uniform_scale() {
    let mesh = ifs(&icosahedron(), DVec3::new(0.1, 0.0, -0.2), 0.5);
    let (s, r) = scene(&format!(
        "Transform {{ translation 1 2 3 scale 2 2 2 children Shape {{
            appearance Appearance {{ material Material {{ diffuseColor 1 0 0 }} }}
            geometry {mesh} }} }}"
    ));
    assert_eq!(s.spheres.len(), 1);
    assert_eq!((r.mesh_spheres, skipped_ifs(&r)), (1, 0));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    let sp = s.spheres[0];
    // Centre (1, 2, 3) + 2 * (0.1, 0, -0.2), radius 2 * 0.5.
    let want = DVec3::new(1.2, 2.0, 2.6);
    assert!((sp.center - want).length() < 1e-12, "{}", sp.center);
    assert!(close(sp.radius, 1.0, 1e-12), "{}", sp.radius);
    assert_eq!(sp.ellipsoid, None);
    // The Shape's Material applies as for a Sphere.
    assert_eq!(s.material_of(&sp).diffuse, DVec3::new(1.0, 0.0, 0.0));
}

#[test]
fn def_use_mesh_gives_one_sphere_per_use() {
    let mesh = ifs(&uv_sphere(7, 12, std::f64::consts::PI), DVec3::ZERO, 1.0);
    let (s, r) = scene(&format!(
        "Transform {{ translation 0 0 0 scale 1.5 1.5 1.5 children Shape {{ geometry DEF M {mesh} }} }}
         Transform {{ translation 5 0 0 scale 0.25 0.25 0.25 children Shape {{ geometry USE M }} }}
         Transform {{ translation 0 5 0 children Shape {{ geometry USE M }} }}
         Transform {{ translation 0 0 5 scale 3 3 3 children Shape {{ geometry USE M }} }}"
    ));
    let got: Vec<(DVec3, f64)> = s.spheres.iter().map(|s| (s.center, s.radius)).collect();
    let want = [
        (DVec3::ZERO, 1.5),
        (DVec3::new(5.0, 0.0, 0.0), 0.25),
        (DVec3::new(0.0, 5.0, 0.0), 1.0),
        (DVec3::new(0.0, 0.0, 5.0), 3.0),
    ];
    assert_eq!(got.len(), 4);
    for ((c, r), (wc, wr)) in got.iter().zip(want) {
        assert!(
            (*c - wc).length() < 1e-12 && close(*r, wr, 1e-12),
            "{c} {r}"
        );
    }
    assert_eq!((r.mesh_spheres, skipped_ifs(&r)), (4, 0));
    // The USEs are looked up, not replayed, but count the same nodes: Transform, Shape,
    // IndexedFaceSet and Coordinate per instance.
    assert_eq!(r.nodes, 16);
    // Unlit white, as a Shape without Appearance.
    assert!(s.spheres.iter().all(|sp| s.material_of(sp).unlit));
}

#[test]
fn shared_coordinate_by_def_use() {
    let pts = icosahedron();
    let (s, r) = scene(&format!(
        "Shape {{ geometry IndexedFaceSet {{ coord DEF C Coordinate {{ {} }} {} }} }}
         Transform {{ translation 4 0 0 children
           Shape {{ geometry IndexedFaceSet {{ {} coord USE C }} }} }}",
        points(&pts, DVec3::new(0.0, 1.0, 0.0), 2.0),
        index_all(pts.len()),
        index_all(pts.len()),
    ));
    assert_eq!(r.mesh_spheres, 2);
    assert_eq!(s.spheres.len(), 2);
    assert!((s.spheres[1].center - DVec3::new(4.0, 1.0, 0.0)).length() < 1e-12);
    assert!(close(s.spheres[1].radius, 2.0, 1e-12));
}

#[test]
fn sphere_mesh_points_from_a_proto_interface() {
    let pts = icosahedron();
    let (s, r) = scene(&format!(
        "PROTO Ball [ field MFVec3f pts [] ] {{
           Shape {{ geometry IndexedFaceSet {{ coord Coordinate {{ point IS pts }} {} }} }} }}
         Transform {{ translation 0 0 -3 children Ball {{ {} }} }}
         Ball {{ pts [ 0 0 0 ] }}",
        index_all(pts.len()),
        points(&pts, DVec3::ZERO, 0.5).replacen("point", "pts", 1),
    ));
    // The second Ball has one point for faces that name twelve: its faces are left out.
    assert_eq!(
        (s.spheres.len(), r.mesh_spheres, s.surfaces.len()),
        (1, 1, 0)
    );
    assert_eq!(r.warnings.len(), 1);
    assert!(
        r.warnings[0].message.contains("is not one of its 1 points"),
        "{}",
        r.warnings[0]
    );
    assert!((s.spheres[0].center - DVec3::new(0.0, 0.0, -3.0)).length() < 1e-12);
    assert!(close(s.spheres[0].radius, 0.5, 1e-12));
}

#[test]
fn non_uniform_scale_makes_an_ellipsoid() {
    let mesh = ifs(&icosahedron(), DVec3::ZERO, 1.0);
    let (s, r) = scene(&format!(
        "Transform {{ scale 1 2 3 children Shape {{ geometry {mesh} }} }}"
    ));
    assert_eq!(
        (s.spheres.len(), s.ellipsoid_count(), r.mesh_spheres),
        (1, 1, 1)
    );
    let e = s.ellipsoids[s.spheres[0].ellipsoid.expect("an ellipsoid").index()];
    assert!((e.matrix3.z_axis - DVec3::new(0.0, 0.0, 3.0)).length() < 1e-12);
}

#[test]
fn cube_disk_and_half_sphere_meshes_are_triangles() {
    let cube: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2 & 1) as f64))
        .collect();
    let disk: Vec<DVec3> = uv_sphere(1, 24, std::f64::consts::PI)
        .into_iter()
        .map(|p| DVec3::new(p.x, p.y, 0.0))
        .filter(|p| p.length() > 0.5)
        .collect();
    let hemisphere = uv_sphere(6, 12, std::f64::consts::FRAC_PI_2);
    for (name, pts) in [("cube", cube), ("disk", disk), ("hemisphere", hemisphere)] {
        let mesh = ifs(&pts, DVec3::ZERO, 1.0);
        let (s, r) = scene(&format!("Shape {{ geometry {mesh} }}"));
        assert_eq!(s.spheres.len(), 0, "{name}");
        assert_eq!((r.mesh_spheres, skipped_ifs(&r)), (0, 0), "{name}");
        // `index_all` writes n triangles.
        assert_eq!(s.surface_counts().triangles, pts.len(), "{name}");
        assert!(r.warnings.is_empty(), "{name}: {:?}", r.warnings);
    }
}

#[test]
fn colored_partial_or_malformed_sphere_meshes_are_not_spheres() {
    let pts = icosahedron();
    let p = points(&pts, DVec3::ZERO, 1.0);
    let all = index_all(pts.len());
    let twelve = pts.len();
    // (case, IndexedFaceSet body, spheres, triangles, skipped, warning).
    for (name, body, spheres, triangles, skipped, warning) in [
        // One colour for twelve points: not one colour over the sphere, so triangles, and the
        // corners past the colour list say so.
        (
            "short color",
            format!("coord Coordinate {{ {p} }} {all} color Color {{ color [1 0 0] }}"),
            0,
            twelve,
            0,
            Some("some corners have no colour"),
        ),
        // Faces over only some of the points: a piece of the sphere, drawn as triangles.
        (
            "unused point",
            format!("coord Coordinate {{ {p} }} {}", index_all(11)),
            0,
            11,
            0,
            None,
        ),
        (
            "bad index",
            format!("coord Coordinate {{ {p} }} {all} coordIndex [0 1 12 -1]"),
            0,
            0,
            0,
            Some("coordIndex[2] = 12 is not one of its 12 points"),
        ),
        // No faces: a point cloud of 12 particles.
        (
            "no coordIndex",
            format!("coord Coordinate {{ {p} }}"),
            12,
            0,
            0,
            None,
        ),
        // Not integers: skipped as before, not an error.
        (
            "float index",
            format!("coord Coordinate {{ {p} }} coordIndex [0.5 1 2]"),
            0,
            0,
            1,
            None,
        ),
        ("no coord", all.clone(), 0, 0, 1, None),
    ] {
        let (s, r) = scene(&format!(
            "Shape {{ geometry IndexedFaceSet {{ {body} normal Normal {{ vector [0 0 1] }} }} }}"
        ));
        assert_eq!(s.spheres.len(), spheres, "{name}");
        assert_eq!(s.surface_counts().triangles, triangles, "{name}");
        // Nodes inside the IndexedFaceSet (Color, Normal) are not counted on their own.
        assert_eq!(skipped_ifs(&r), skipped, "{name}: {:?}", r.skipped);
        assert_eq!(r.skipped.len() as u64, skipped, "{name}: {:?}", r.skipped);
        // The one Normal (for every corner, normalPerVertex) is short too, where faces are.
        let warned: Vec<String> = r.warnings.iter().map(|w| w.message.clone()).collect();
        match warning {
            Some(w) => assert!(warned.iter().any(|m| m.contains(w)), "{name}: {warned:?}"),
            None => assert!(
                warned.iter().all(|m| m.contains("no normal")),
                "{name}: {warned:?}"
            ),
        }
    }
}

#[test]
fn sphere_mesh_outside_a_shape_is_not_drawn_nor_counted_as_a_sphere() {
    let mesh = ifs(&icosahedron(), DVec3::ZERO, 1.0);
    let (s, r) = scene(&format!("Group {{ children [ {mesh} ] }}"));
    assert_eq!(
        (s.spheres.len(), r.mesh_spheres, skipped_ifs(&r)),
        (0, 0, 1)
    );
}

#[test]
fn coordinate_outside_an_indexed_face_set_is_still_skipped() {
    let (_, r) = scene(
        "Shape { geometry IndexedLineSet { coord Coordinate { point [0 0 0, 1 1 1] } coordIndex [0 1] } }
         Shape { geometry PointSet { coord Coordinate { point [0 0 0] } } }",
    );
    assert_eq!(r.skipped.get("IndexedLineSet"), Some(&1));
    // A PointSet is drawn: its point is a particle.
    assert_eq!((r.skipped.get("PointSet"), r.point_spheres), (None, 1));
    assert_eq!(r.skipped.get("Coordinate"), None);
}

/// `gtsphere render jmol_peptide20_spacefill.wrl` shows the atoms.
#[test]
fn jmol_spacefill_renders_its_atoms() {
    let Some(corpus) = crate::support::shared("corpus") else {
        return;
    };
    let path = corpus.join("tools/jmol/jmol_peptide20_spacefill.wrl");
    let (s, r) = load_path(&path, &LoadOptions::default()).unwrap();
    assert_eq!((s.spheres.len(), r.mesh_spheres), (324, 324));
    let opts = RenderOptions {
        width: 64,
        height: 64,
        spp: 1,
        sampler: SamplerKind::Center,
        ..RenderOptions::default()
    };
    let img = crate::support::render_auto(s, &opts).image();
    let covered = img.alpha.iter().filter(|&&a| a > 0.0).count();
    let frac = covered as f64 / img.alpha.len() as f64;
    // Jmol's own view (its Viewpoint) of a 20-residue peptide fills a good part of the frame.
    assert!(frac > 0.15 && frac < 0.95, "covered fraction {frac}");
    // Lit and coloured by element: oxygen (1 .055 .055) is red, nitrogen (.191 .316 .973) blue.
    let red = img
        .rgb
        .iter()
        .any(|p| p[0] > 0.3 && p[1] < 0.1 && p[2] < 0.1);
    let blue = img.rgb.iter().any(|p| p[2] > 0.3 && p[0] < 0.2);
    assert!(red && blue);
}
