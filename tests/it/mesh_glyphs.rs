//! What meshes and points lower to: merged sphere glyphs (VTK/ParaView) become one exact
//! sphere each with its colour, other faces become triangles, points become particles, and
//! Box, Cylinder and Cone become exact surfaces under their Transforms. Expected values are
//! computed here from what the test writes (or, for the corpus file, read from the file
//! with a parser of the test's own).

use glam::DVec3;
use gtsphere::scene::{Scene, SurfaceShape};
use gtsphere::vrml::{load_path, load_str, LoadOptions, LoadReport};

use crate::support::{scene, shared, Rng};

/// A UV sphere like vtkSphereSource: two poles, then `phi - 2` rings of `theta` points;
/// triangles fan to the poles and quads between rings (as two triangles). Returns points and
/// triangles (indices local to the glyph).
fn glyph(theta: usize, phi: usize, c: DVec3, r: f64) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let mut pts = vec![c + DVec3::new(0.0, 0.0, r), c - DVec3::new(0.0, 0.0, r)];
    let rings = phi - 2;
    for j in 1..=rings {
        let a = std::f64::consts::PI * j as f64 / (phi - 1) as f64;
        for i in 0..theta {
            let b = std::f64::consts::TAU * i as f64 / theta as f64;
            pts.push(c + r * DVec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos()));
        }
    }
    let at = |j: usize, i: usize| 2 + (j - 1) * theta + i % theta;
    let mut tris = Vec::new();
    for i in 0..theta {
        tris.push([0, at(1, i), at(1, i + 1)]);
        tris.push([1, at(rings, i + 1), at(rings, i)]);
        for j in 1..rings {
            tris.push([at(j, i), at(j + 1, i), at(j + 1, i + 1)]);
            tris.push([at(j, i), at(j + 1, i + 1), at(j, i + 1)]);
        }
    }
    (pts, tris)
}

fn fmt3(p: DVec3) -> String {
    format!("{:?} {:?} {:?}", p.x, p.y, p.z)
}

/// Points, per-vertex colours and faces (`-1`-terminated) of every glyph, merged.
fn glyph_lists(
    glyphs: &[(usize, usize, DVec3, f64, DVec3)],
) -> (Vec<String>, Vec<String>, Vec<String>) {
    let (mut pts, mut cols, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for &(theta, phi, c, r, col) in glyphs {
        let (p, t) = glyph(theta, phi, c, r);
        let base = pts.len();
        for q in &p {
            pts.push(fmt3(*q));
            cols.push(fmt3(col));
        }
        for tri in t {
            idx.push(format!(
                "{} {} {} -1",
                tri[0] + base,
                tri[1] + base,
                tri[2] + base
            ));
        }
    }
    (pts, cols, idx)
}

/// A Shape with a Material and one IndexedFaceSet of these points, colours and faces.
fn mesh_shape(pts: &[String], cols: &[String], idx: &[String]) -> String {
    format!(
        "Shape {{ appearance Appearance {{ material Material {{ diffuseColor 1 1 1 }} }} geometry IndexedFaceSet {{ \
         coord Coordinate {{ point [ {} ] }} color Color {{ color [ {} ] }} coordIndex [ {} ] }} }}",
        pts.join(", "),
        cols.join(", "),
        idx.join(" ")
    )
}

/// One IndexedFaceSet holding every glyph, coloured per vertex, in a Shape with a Material.
fn merged(glyphs: &[(usize, usize, DVec3, f64, DVec3)]) -> String {
    let (pts, cols, idx) = glyph_lists(glyphs);
    mesh_shape(&pts, &cols, &idx)
}

#[test]
fn a_merged_glyph_mesh_round_trips_to_its_centres_radii_and_colours() {
    let mut rng = Rng::new(99);
    let glyphs: Vec<_> = (0..150)
        .map(|_| {
            let c = DVec3::new(
                rng.range(-100.0, 100.0),
                rng.range(-100.0, 100.0),
                rng.range(-100.0, 100.0),
            );
            let r = 10f64.powf(rng.range(-2.0, 1.0));
            let col = DVec3::new(rng.f(), rng.f(), rng.f());
            (8 + rng.below(17), 6 + rng.below(15), c, r, col)
        })
        .collect();
    let (s, r) = scene(&merged(&glyphs));
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(
        (s.spheres.len(), r.mesh_spheres, s.surfaces.len()),
        (150, 150, 0)
    );
    for (sp, &(_, _, c, rad, col)) in s.spheres.iter().zip(&glyphs) {
        assert!(
            (sp.center - c).length() <= 1e-9 * rad,
            "{} vs {c}",
            sp.center
        );
        assert!(
            (sp.radius - rad).abs() <= 1e-9 * rad,
            "{} vs {rad}",
            sp.radius
        );
        assert_eq!(s.material_of(sp).diffuse, col);
    }
}

#[test]
fn a_mesh_of_spheres_and_a_cube_gives_spheres_and_triangles() {
    let glyphs = [
        (
            12,
            8,
            DVec3::new(-2.0, 0.0, 0.0),
            0.5,
            DVec3::new(1.0, 0.0, 0.0),
        ),
        (
            12,
            8,
            DVec3::new(2.0, 0.0, 0.0),
            0.7,
            DVec3::new(0.0, 1.0, 0.0),
        ),
    ];
    let (mut pts, mut cols, mut idx) = glyph_lists(&glyphs);
    // A cube's six quads as a second component, in blue.
    let n0 = pts.len();
    for p in [
        "10 10 10", "11 10 10", "11 11 10", "10 11 10", "10 10 11", "11 10 11", "11 11 11",
        "10 11 11",
    ] {
        pts.push(p.to_string());
        cols.push("0 0 1".to_string());
    }
    for f in [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [1, 2, 6, 5],
        [0, 4, 7, 3],
    ] {
        idx.push(format!(
            "{} {} {} {} -1",
            f[0] + n0,
            f[1] + n0,
            f[2] + n0,
            f[3] + n0
        ));
    }
    let text = mesh_shape(&pts, &cols, &idx);
    let (s, r) = scene(&text);
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(s.spheres.len(), 2, "{text}");
    assert_eq!(s.surface_counts().triangles, 12);
    for sf in &s.surfaces {
        let SurfaceShape::Triangle(t) = &sf.shape else {
            panic!("a triangle");
        };
        assert_eq!(t.color, Some([DVec3::new(0.0, 0.0, 1.0); 3]));
        assert!(t
            .p
            .iter()
            .all(|p| p.min_element() >= 10.0 && p.max_element() <= 11.0));
    }
    let area: f64 = s
        .surfaces
        .iter()
        .map(|sf| match &sf.shape {
            SurfaceShape::Triangle(t) => 0.5 * t.face_normal().length(),
            _ => 0.0,
        })
        .sum();
    assert!((area - 6.0).abs() < 1e-12, "the cube's faces: area {area}");
}

/// Points of the corpus file's Coordinate, read by the test itself: the numbers between
/// `point [` and the next `]`.
fn coordinate_points(text: &str) -> Vec<DVec3> {
    let start = text.find("point [").expect("point [") + "point [".len();
    let end = start + text[start..].find(']').expect("]");
    let nums: Vec<f64> = text[start..end]
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .map(|w| w.parse().expect("a number"))
        .collect();
    nums.chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect()
}

#[test]
fn the_vtk_glyph_export_gives_300_spheres_of_radius_004_with_their_colours() {
    let Some(dir) = shared("corpus") else {
        return;
    };
    let path = dir.join("tools/vtk/vtk_glyph300_spheres.wrl");
    let text = std::fs::read_to_string(&path).unwrap();
    // From the file: 10200 points = 300 glyphs of vtkSphereSource 8 x 6 (34 points each,
    // the two poles first), so glyph k's centre is the middle of points 34k and 34k + 1,
    // and its radius half their distance.
    let pts = coordinate_points(&text);
    assert_eq!(pts.len(), 300 * 34);
    let (s, r) = load_path(&path, &LoadOptions::default()).unwrap();
    assert_eq!(
        (s.spheres.len(), r.mesh_spheres, s.surfaces.len()),
        (300, 300, 0)
    );
    for (k, sp) in s.spheres.iter().enumerate() {
        let (a, b) = (pts[34 * k], pts[34 * k + 1]);
        let (c, rad) = (0.5 * (a + b), 0.5 * (a - b).length());
        assert!(
            (rad - 0.04).abs() < 1e-6,
            "glyph {k}: poles give radius {rad}"
        );
        assert!(
            (sp.center - c).length() < 1e-6,
            "sphere {k}: {} vs {c}",
            sp.center
        );
        assert!(
            (sp.radius - 0.04).abs() < 1e-6,
            "sphere {k}: radius {}",
            sp.radius
        );
    }
    // The scalar colours: every glyph's own colour, several distinct over the file.
    let mut colours: Vec<[u64; 3]> = s
        .spheres
        .iter()
        .map(|sp| s.material_of(sp).diffuse.to_array().map(f64::to_bits))
        .collect();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 20, "{} distinct colours", colours.len());
    assert!(text.contains("1 0.1803921568627451 0"));
    assert_eq!(
        s.material_of(&s.spheres[0]).diffuse,
        DVec3::new(1.0, 0.1803921568627451, 0.0)
    );
}

fn points_scene(body: &str, radius: Option<f64>) -> (Scene, LoadReport) {
    let opts = LoadOptions {
        point_radius: radius,
        ..LoadOptions::default()
    };
    load_str("test.wrl", &format!("#VRML V2.0 utf8\n{body}"), &opts).unwrap()
}

#[test]
fn points_become_particles_of_a_derived_or_given_radius() {
    // Points on a grid of spacing 0.5: the nearest neighbour is 0.5 away for each, so the
    // derived radius is 0.25.
    let mut pts = Vec::new();
    let mut cols = Vec::new();
    for i in 0..5 {
        for j in 0..4 {
            pts.push(format!("{} {} 0", 0.5 * i as f64, 0.5 * j as f64));
            cols.push(format!("{} 0 0", (i * 4 + j) as f64 / 20.0));
        }
    }
    for geometry in [
        format!(
            "PointSet {{ coord Coordinate {{ point [ {} ] }} color Color {{ color [ {} ] }} }}",
            pts.join(", "),
            cols.join(", ")
        ),
        // MeshLab's point clouds: an IndexedFaceSet with points and no faces.
        format!(
            "IndexedFaceSet {{ coord Coordinate {{ point [ {} ] }} color Color {{ color [ {} ] }} }}",
            pts.join(", "),
            cols.join(", ")
        ),
    ] {
        let body = format!("Transform {{ translation 1 2 3 children Shape {{ geometry {geometry} }} }}");
        let (s, r) = points_scene(&body, None);
        assert_eq!((s.spheres.len(), r.point_spheres), (20, 20), "{geometry}");
        assert!(s.spheres.iter().all(|sp| sp.radius == 0.25));
        assert_eq!(s.spheres[0].center, DVec3::new(1.0, 2.0, 3.0));
        // No Material: unlit, in the Color node's colours.
        let m = &s.material_of(&s.spheres[5]);
        assert!(m.unlit && m.diffuse == DVec3::new(0.25, 0.0, 0.0), "{m:?}");
        assert_eq!(r.notes.len(), 1);
        let note = r.notes[0].headline();
        assert!(
            note.starts_with("test.wrl:2:") && note.contains("20 points drawn as spheres of radius 0.25"),
            "{note}"
        );
        let (s, r) = points_scene(&body, Some(0.1));
        assert!(s.spheres.iter().all(|sp| sp.radius == 0.1) && r.notes.is_empty());
    }
}

#[test]
fn box_cylinder_and_cone_lower_to_surfaces_under_their_transforms() {
    let (s, r) = scene(
        "Transform { translation 1 0 0 scale 2 2 2 children [
           Shape { geometry Box { size 1 2 3 } }
           Shape { geometry Cylinder { radius 0.5 height 4 top FALSE } }
           Shape { geometry Cone { } }
         ] }",
    );
    assert!(
        r.warnings.is_empty() && r.skipped.is_empty(),
        "{:?} {:?}",
        r.warnings,
        r.skipped
    );
    let c = s.surface_counts();
    assert_eq!((c.boxes, c.cylinders, c.cones, c.triangles), (1, 1, 1, 0));
    let b = s.bounds().unwrap();
    // The cylinder reaches y = +-4 after the scale; the box x from 1 - 1 to 1 + 1 ... the cone
    // (radius 1, height 2) reaches x = 1 + 2 = 3.
    assert_eq!((b.min[1], b.max[1]), (-4.0, 4.0));
    assert_eq!(b.max[0], 3.0);
    for bad in [
        "Box { size 1 0 1 }",
        "Cylinder { radius -1 }",
        "Cone { height 0 }",
    ] {
        let text = format!("#VRML V2.0 utf8\nShape {{ geometry {bad} }}");
        let e = load_str("test.wrl", &text, &LoadOptions::default())
            .err()
            .unwrap_or_else(|| panic!("{bad} must be refused"))
            .to_string();
        assert!(
            e.starts_with("test.wrl:2:") && e.contains("must be positive"),
            "{e}"
        );
    }
}

#[test]
fn spheres_only_leaves_other_surfaces_out() {
    let body = "Shape { geometry Box { } }\nShape { geometry Sphere { } }\n\
                Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 1 0 ] } coordIndex [ 0 1 2 ] } }";
    let (s, _) = scene(body);
    assert_eq!((s.spheres.len(), s.surfaces.len()), (1, 2));
    let opts = LoadOptions {
        spheres_only: true,
        ..LoadOptions::default()
    };
    let (s, r) = load_str("t.wrl", &format!("#VRML V2.0 utf8\n{body}"), &opts).unwrap();
    assert_eq!((s.spheres.len(), s.surfaces.len()), (1, 0));
    assert_eq!(r.skipped.values().sum::<u64>(), 2, "{:?}", r.skipped);
}

#[test]
fn a_directional_light_lights_the_surfaces_of_its_group_only() {
    let (s, _) = scene(
        "Group { children [ DirectionalLight { } Shape { geometry Box { } } ] }
         Shape { geometry Cone { } }",
    );
    let gtsphere::scene::Light::Directional(l) = s.lights[0] else {
        panic!("a directional light");
    };
    assert!(l.surface_scope.contains(0) && !l.surface_scope.contains(1));
}

/// What a new user does first: every tool export of the corpus renders with no options
/// (small, centre samples), and draws something (PyMOL's 800-residue chain is thin in its
/// own Viewpoint: a few hundred pixels of 160 x 120).
#[test]
fn every_tool_export_renders_with_no_options() {
    use gtsphere::render::{RenderOptions, SamplerKind};
    let Some(dir) = shared("corpus") else {
        return;
    };
    let mut files: Vec<_> = std::fs::read_dir(dir.join("tools"))
        .unwrap()
        .flat_map(|d| std::fs::read_dir(d.unwrap().path()).unwrap())
        .map(|f| f.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "wrl"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 15, "{files:?}");
    for path in files {
        let (scene, _) = load_path(&path, &LoadOptions::default()).unwrap();
        let opts = RenderOptions {
            width: 160,
            height: 120,
            sampler: SamplerKind::Center,
            spp: 1,
            ..RenderOptions::default()
        };
        let img = crate::support::render_auto(scene, &opts).image();
        let covered = img.alpha.iter().filter(|a| **a > 0.0).count();
        assert!(covered > 20, "{}: {covered} pixels drawn", path.display());
        assert!(img.rgb.iter().flatten().all(|v| v.is_finite()));
    }
}

#[test]
fn an_elevation_grid_is_its_quads_as_triangles_facing_up() {
    // 4 x 3 heights, spacings 0.5 and 2, one colour per quad in row order (i fastest).
    let heights = "0 0.1 0.2 0.3  1 1.1 1.2 1.3  2 2.1 2.2 2.3";
    let colours = "1 0 0, 0 1 0, 0 0 1, 1 1 0, 0 1 1, 1 0 1";
    let (s, r) = scene(&format!(
        "Shape {{ geometry ElevationGrid {{ xDimension 4 zDimension 3 xSpacing 0.5 zSpacing 2 \
         height [ {heights} ] colorPerVertex FALSE color Color {{ color [ {colours} ] }} }} }}"
    ));
    assert!(
        r.warnings.is_empty() && r.skipped.is_empty(),
        "{:?} {:?}",
        r.warnings,
        r.skipped
    );
    assert_eq!(s.surface_counts().triangles, 2 * 3 * 2);
    let want_colour = [
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
    ];
    let mut area_xz = 0.0;
    for sf in &s.surfaces {
        let SurfaceShape::Triangle(t) = &sf.shape else {
            panic!("a triangle");
        };
        let n = t.face_normal();
        assert!(n.y > 0.0, "the front faces +y: {n}");
        area_xz += 0.5 * n.y;
        // Each triangle lies in one quad: its centroid says which (i along x, j along z).
        let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        let (i, j) = ((c.x / 0.5) as usize, (c.z / 2.0) as usize);
        assert_eq!(
            t.color,
            Some([want_colour[i + 3 * j]; 3]),
            "quad ({i}, {j})"
        );
        // Heights: y = height[i + 4 j] at each corner.
        for p in t.p {
            let (pi, pj) = ((p.x / 0.5).round() as usize, (p.z / 2.0).round() as usize);
            assert!((p.y - (pj as f64 + 0.1 * pi as f64)).abs() < 1e-12, "{p}");
        }
    }
    // The triangles cover the grid's 1.5 x 4 extent once, seen from above.
    assert!((area_xz - 1.5 * 4.0).abs() < 1e-12, "{area_xz}");
    let (s, r) =
        scene("Shape { geometry ElevationGrid { xDimension 3 zDimension 3 height [ 0 0 0 ] } }");
    assert!(s.surfaces.is_empty());
    assert!(
        r.warnings[0].message.contains("3 heights for a 3 x 3 grid"),
        "{:?}",
        r.warnings
    );
}

#[test]
fn the_point_radius_note_is_said_once_and_a_bad_radius_is_refused() {
    let body = "PROTO Cloud [ ] { Shape { geometry PointSet { coord Coordinate { point [ 0 0 0, 1 0 0 ] } } } }\n\
                Cloud { } Cloud { } Cloud { }";
    let (s, r) = points_scene(body, None);
    assert_eq!(s.spheres.len(), 6);
    assert_eq!(r.notes.len(), 1, "{:?}", r.notes);
    assert_eq!(r.notes[0].repeats, 2);
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let opts = LoadOptions {
            point_radius: Some(bad),
            ..LoadOptions::default()
        };
        let e = load_str("t.wrl", &format!("#VRML V2.0 utf8\n{body}"), &opts)
            .err()
            .unwrap_or_else(|| panic!("point radius {bad} must be refused"));
        assert!(
            e.to_string()
                .contains("point radius must be a positive number"),
            "{e}"
        );
    }
}
