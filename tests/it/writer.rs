//! The VRML writer against the reader: parse(write(ir)) equals ir, on the samples, the tool
//! exports of the corpus and generated scenes with nested light scopes and ellipsoids; and
//! the written file renders to the same image.

use glam::{DAffine3, DQuat, DVec3};
use gtsphere::render::{RenderOptions, SamplerKind};
use gtsphere::scene::{
    DirectionalLight, EllipsoidId, Light, LightScope, Material, Origin, PointLight, Profile, Scene,
    Sphere,
};
use gtsphere::vrml::{load_path, load_str, write_scene, LoadOptions};

fn written(scene: &Scene) -> String {
    let mut out = Vec::new();
    write_scene(scene, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

fn reread(scene: &Scene) -> Scene {
    let text = written(scene);
    match load_str("written.wrl", &text, &LoadOptions::default()) {
        Ok((s, r)) => {
            assert!(
                r.warnings.is_empty(),
                "{:?}",
                r.warnings.iter().map(|w| w.headline()).collect::<Vec<_>>()
            );
            s
        }
        Err(e) => panic!("re-reading failed: {e}\n{text}"),
    }
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

fn close3(a: DVec3, b: DVec3, tol: f64) -> bool {
    (0..3).all(|k| close(a[k], b[k], tol))
}

/// The same scene up to the writer's rounding (rotations via axis-angle: 1e-12).
fn assert_same(a: &Scene, b: &Scene) {
    assert_eq!(a.spheres.len(), b.spheres.len());
    for (k, (s, t)) in a.spheres.iter().zip(&b.spheres).enumerate() {
        assert_eq!(a.material_of(s), b.material_of(t), "material of sphere {k}");
        assert_eq!(s.ellipsoid.is_none(), t.ellipsoid.is_none(), "sphere {k}");
        if let (Some(es), Some(et)) = (s.ellipsoid, t.ellipsoid) {
            let (m, n) = (a.ellipsoids[es.index()], b.ellipsoids[et.index()]);
            // The same ellipsoid: M M^T (the quadric) and the centre agree.
            let (q, r) = (
                m.matrix3 * m.matrix3.transpose(),
                n.matrix3 * n.matrix3.transpose(),
            );
            let scale = q.to_cols_array().iter().fold(0.0f64, |x, y| x.max(y.abs()));
            for (x, y) in q.to_cols_array().iter().zip(r.to_cols_array()) {
                assert!((x - y).abs() <= 1e-12 * scale, "ellipsoid {k}: {q} vs {r}");
            }
            assert!(close3(m.translation, n.translation, 1e-15));
        } else {
            assert_eq!((s.center, s.radius), (t.center, t.radius), "sphere {k}");
        }
    }
    assert_same_surfaces(a, b);
    // Scoped DirectionalLights are written inside the Group of their spheres, so the order of
    // lights may change: compare them sorted.
    let key = |l: &&Light| match l {
        Light::Point(p) => (0, 0, 0, p.intensity.to_bits(), p.location.x.to_bits()),
        Light::Directional(d) => (
            1,
            d.scope.range(usize::MAX).0,
            d.scope.range(usize::MAX).1,
            d.intensity.to_bits(),
            d.color.x.to_bits(),
        ),
    };
    let (mut la, mut lb): (Vec<&Light>, Vec<&Light>) =
        (a.lights.iter().collect(), b.lights.iter().collect());
    la.sort_by_key(key);
    lb.sort_by_key(key);
    assert_eq!(la.len(), lb.len());
    for (l, m) in la.into_iter().zip(lb) {
        match (l, m) {
            (Light::Point(p), Light::Point(q)) => assert_eq!(
                (
                    p.location,
                    p.color,
                    p.intensity,
                    p.ambient_intensity,
                    p.attenuation,
                    p.radius,
                    p.on
                ),
                (
                    q.location,
                    q.color,
                    q.intensity,
                    q.ambient_intensity,
                    q.attenuation,
                    q.radius,
                    q.on
                )
            ),
            (Light::Directional(p), Light::Directional(q)) => {
                assert!(close3(p.direction, q.direction, 1e-15));
                assert_eq!(
                    (p.color, p.intensity, p.ambient_intensity, p.on, p.scope),
                    (q.color, q.intensity, q.ambient_intensity, q.on, q.scope)
                );
            }
            _ => panic!("light kinds differ"),
        }
    }
    assert_eq!(a.viewpoints.len(), b.viewpoints.len());
    for (v, w) in a.viewpoints.iter().zip(&b.viewpoints) {
        assert_eq!(
            (v.position, v.field_of_view, &v.description),
            (w.position, w.field_of_view, &w.description)
        );
        // (angle_between's acos cannot resolve below ~1e-8; compare rotated axes instead.)
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            assert!(close3(v.orientation * axis, w.orientation * axis, 1e-12));
        }
    }
    assert_eq!((a.headlight, a.background), (b.headlight, b.background));
}

/// The same surfaces: kinds, parts and materials equal, triangles exact (normals to 1e-15),
/// and each solid's map equal to 1e-12 of its size, or equal after the mirror about its
/// x = 0 plane that the writer uses for mirroring maps (the three solids are symmetric
/// about it).
fn assert_same_surfaces(a: &Scene, b: &Scene) {
    use gtsphere::scene::SurfaceShape;
    assert_eq!(a.surfaces.len(), b.surfaces.len());
    for (k, (s, t)) in a.surfaces.iter().zip(&b.surfaces).enumerate() {
        assert_eq!(
            a.surface_material(s),
            b.surface_material(t),
            "material of surface {k}"
        );
        match (&s.shape, &t.shape) {
            (
                SurfaceShape::Solid { solid, to_world },
                SurfaceShape::Solid {
                    solid: solid2,
                    to_world: w2,
                },
            ) => {
                assert_eq!(solid, solid2, "surface {k}");
                let size = to_world
                    .matrix3
                    .to_cols_array()
                    .iter()
                    .fold(0.0f64, |x, y| x.max(y.abs()));
                let near = |m: glam::DMat3| {
                    m.to_cols_array()
                        .iter()
                        .zip(to_world.matrix3.to_cols_array())
                        .all(|(x, y)| (x - y).abs() <= 1e-12 * size)
                };
                let mirror = glam::DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0));
                assert!(
                    near(w2.matrix3) || near(w2.matrix3 * mirror),
                    "surface {k}: {to_world} vs {w2}"
                );
                assert!(close3(to_world.translation, w2.translation, 1e-15));
            }
            (SurfaceShape::Triangle(x), SurfaceShape::Triangle(y)) => {
                assert_eq!(
                    (x.p, x.color, x.solid),
                    (y.p, y.color, y.solid),
                    "surface {k}"
                );
                assert_eq!(x.n.is_some(), y.n.is_some(), "surface {k}");
                if let (Some(n), Some(m)) = (x.n, y.n) {
                    assert!((0..3).all(|c| close3(n[c], m[c], 1e-15)), "surface {k}");
                }
            }
            _ => panic!("surface {k}: kinds differ"),
        }
    }
}

fn files() -> Vec<String> {
    let mut v: Vec<String> = ["cluster", "cloud", "lattice", "ellipsoids", "gas"]
        .iter()
        .map(|s| format!("{}/samples/{s}.wrl", env!("CARGO_MANIFEST_DIR")))
        .collect();
    // The tool exports of the corpus, when it is there (the samples are tested without it).
    if let Some(corpus) = crate::support::shared("corpus") {
        for tool in ["pymol", "jmol", "vtk", "meshlab"] {
            for e in std::fs::read_dir(corpus.join("tools").join(tool)).unwrap() {
                v.push(e.unwrap().path().display().to_string());
            }
        }
    }
    v.push(format!(
        "{}/tests/data/vmd_style.wrl",
        env!("CARGO_MANIFEST_DIR")
    ));
    v
}

#[test]
fn samples_and_tool_exports_round_trip() {
    for f in files() {
        let (a, _) = load_path(std::path::Path::new(&f), &LoadOptions::default()).unwrap();
        let b = reread(&a);
        assert_same(&a, &b);
    }
}

#[test]
fn written_file_renders_the_same_picture() {
    for s in ["cluster", "ellipsoids", "gas", "lattice"] {
        let f = format!("{}/samples/{s}.wrl", env!("CARGO_MANIFEST_DIR"));
        let (a, _) = load_path(std::path::Path::new(&f), &LoadOptions::default()).unwrap();
        let b = reread(&a);
        let opts = RenderOptions {
            width: 48,
            height: 36,
            spp: 4,
            sampler: SamplerKind::Stratified,
            ..RenderOptions::default()
        };
        let (x, y) = (
            crate::support::render_auto(a, &opts).image(),
            crate::support::render_auto(b, &opts).image(),
        );
        let max = x
            .rgb
            .iter()
            .zip(&y.rgb)
            .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
            .fold(0.0f32, f32::max);
        assert!(max < 1e-5, "{s}: max pixel difference {max:e}");
    }
}

/// Surfaces under rotations, non-uniform scales and a mirror, triangles with normals and
/// colours, and a DirectionalLight lighting one Group's sphere and surfaces only: the written
/// file renders to the same picture (the scoped light is written once per kind of thing it
/// lights).
#[test]
fn surfaces_round_trip_and_render_the_same() {
    let text = "#VRML V2.0 utf8\nNavigationInfo { headlight FALSE }\nViewpoint { position 0 0 9 }\n\
        PointLight { location 4 5 6 intensity 0.7 }\n\
        Group { children [ DirectionalLight { direction -1 -1 -2 intensity 0.6 }\n\
          Transform { rotation 1 2 3 0.7 scale 1 2 0.5 children Shape { appearance Appearance { material Material { diffuseColor 0.9 0.4 0.2 } } geometry Cylinder { radius 0.5 height 2 top FALSE } } }\n\
          Transform { translation 2 0 0 children Shape { appearance Appearance { material Material { } } geometry Sphere { radius 0.6 } } } ] }\n\
        Transform { translation -2 1 0 scale -1 1 1 rotation 0 1 0 0.4 children Shape { appearance Appearance { material Material { diffuseColor 0.2 0.8 0.3 } } geometry Cone { } } }\n\
        Transform { translation 0 -2 0 rotation 1 0 0 0.3 children Shape { appearance Appearance { material Material { } } geometry Box { size 3 0.4 2 } } }\n\
        Shape { appearance Appearance { material Material { } } geometry IndexedFaceSet { solid FALSE creaseAngle 3 coord Coordinate { point [ -3 2 0, -1 2 -1, -2 3 0, -1 3 1 ] } color Color { color [ 1 0 0, 0 1 0, 0 0 1, 1 1 0 ] } coordIndex [ 0 1 2 -1 1 3 2 -1 ] } }";
    let (a, r) = load_str("s.wrl", text, &LoadOptions::default()).unwrap();
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    assert_eq!(a.surfaces.len(), 5);
    let b = reread(&a);
    assert_same_surfaces(&a, &b);
    assert_eq!(
        b.lights.len(),
        3,
        "the scoped light is written for its sphere and for its surface"
    );
    let opts = RenderOptions {
        width: 64,
        height: 48,
        spp: 1,
        sampler: SamplerKind::Center,
        ..RenderOptions::default()
    };
    let (x, y) = (
        crate::support::render_auto(a, &opts).rgb,
        crate::support::render_auto(b, &opts).rgb,
    );
    let lit = x.iter().filter(|p| p[0] > 0.05).count();
    assert!(lit > 300, "{lit} pixels lit");
    let max = x
        .iter()
        .zip(&y)
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] - q[k]).abs()))
        .fold(0.0f64, f64::max);
    assert!(max < 1e-9, "max pixel difference {max:e}");
}

/// Generated scenes: nested and disjoint DirectionalLight scopes, ellipsoids with rotations,
/// shears and reflections, shared and unlit materials.
#[test]
fn generated_scenes_round_trip() {
    let mut rng = crate::support::Rng(3);
    let mut rnd = move || rng.f();
    for case in 0..30 {
        let mut s = Scene {
            headlight: case % 2 == 0,
            background: DVec3::new(rnd(), rnd(), rnd()),
            ..Scene::default()
        };
        let mut paints = vec![s.materials.add(&Material::unlit())];
        for _ in 0..4 {
            let m = Material {
                diffuse: DVec3::new(rnd(), rnd(), rnd()),
                emissive: DVec3::new(rnd(), rnd(), rnd()),
                specular: DVec3::new(rnd(), rnd(), rnd()),
                shininess: rnd(),
                ambient_intensity: rnd(),
                transparency: if rnd() < 0.5 { 0.0 } else { rnd() },
                unlit: false,
                // Profiled materials are written as GasParticle instances (opaque ones too:
                // the profile comes back either way).
                profile: match (rnd() * 5.0) as u32 {
                    0 => Profile::Linear,
                    1 => Profile::Quadratic,
                    2 => Profile::Gaussian {
                        width: rnd().max(1e-3),
                    },
                    _ => Profile::Constant,
                },
            };
            paints.push(s.materials.add(&m));
        }
        let n = 20;
        for k in 0..n {
            let center = DVec3::new(rnd(), rnd(), rnd()) * 10.0 - 5.0;
            let paint = paints[(rnd() * 5.0) as usize];
            if k % 4 == 3 {
                let lin = glam::DMat3::from_cols(
                    DVec3::new(rnd(), rnd(), rnd()) - 0.5,
                    DVec3::new(rnd(), rnd(), rnd()) - 0.5,
                    DVec3::new(rnd(), rnd(), rnd()) - 0.5,
                ) + glam::DMat3::IDENTITY;
                s.ellipsoids
                    .push(DAffine3::from_mat3_translation(lin, center));
                let l = lin;
                let radius =
                    DVec3::new(l.row(0).length(), l.row(1).length(), l.row(2).length()).length();
                s.spheres.push(Sphere {
                    center,
                    radius,
                    color: paint.color,
                    material: paint.material,
                    ellipsoid: EllipsoidId::new(s.ellipsoids.len() - 1),
                    origin: Origin::default(),
                });
            } else {
                s.spheres.push(Sphere {
                    center,
                    radius: 0.1 + rnd(),
                    color: paint.color,
                    material: paint.material,
                    ellipsoid: None,
                    origin: Origin::default(),
                });
            }
        }
        // Scopes: everything, a nested pair, a disjoint one, an empty one.
        for scope in [(0, n), (2, 12), (4, 8), (14, 18), (9, 9)] {
            s.lights.push(Light::Directional(DirectionalLight {
                direction: DVec3::new(rnd() - 0.5, rnd() - 0.5, -1.0).normalize(),
                color: DVec3::new(rnd(), rnd(), rnd()),
                intensity: rnd(),
                ambient_intensity: rnd(),
                on: rnd() < 0.8,
                scope: LightScope::Range {
                    start: scope.0,
                    end: scope.1,
                },
                surface_scope: LightScope::All,
                origin: Origin::default(),
            }));
        }
        s.lights.push(Light::Point(PointLight {
            location: DVec3::new(rnd(), rnd(), rnd()),
            color: DVec3::ONE,
            intensity: rnd(),
            ambient_intensity: rnd(),
            attenuation: DVec3::new(1.0, rnd(), rnd()),
            radius: 10.0 + rnd(),
            on: true,
            origin: Origin::default(),
        }));
        s.viewpoints.push(gtsphere::scene::Viewpoint {
            name: Some("Front".into()),
            description: "a \"quoted\" \\ view".into(),
            position: DVec3::new(rnd(), rnd(), 10.0),
            orientation: DQuat::from_axis_angle(DVec3::new(rnd(), rnd(), rnd()).normalize(), rnd()),
            field_of_view: 0.3 + rnd(),
            origin: Origin::default(),
        });
        let b = reread(&s);
        assert_same(&s, &b);
    }
}

/// A scene of few materials shares one Appearance per material; one with a colour per sphere
/// (more than the writer remembers) still reads back with every sphere's own colour.
#[test]
fn appearances_are_shared_and_every_colour_kept() {
    let mut s = Scene::default();
    let few = [0.25, 0.5, 0.75];
    for k in 0..9000 {
        let colour = if k % 2 == 0 {
            DVec3::splat(few[k % 3])
        } else {
            DVec3::new(k as f64 / 9000.0, 1.0 / (k as f64 + 3.0), 0.5)
        };
        let m = Material {
            diffuse: colour,
            ..Material::default()
        };
        s.add_sphere(DVec3::new(k as f64, 0.0, 0.0), 0.4, &m);
    }
    let text = written(&s);
    // The few colours: DEF'd once each and USE'd after (the others need no sharing).
    assert!(
        text.matches("appearance USE").count() >= 4000,
        "too few USEs"
    );
    let back = reread(&s);
    assert_eq!(back.spheres.len(), s.spheres.len());
    for (a, b) in s.spheres.iter().zip(&back.spheres) {
        assert_eq!(s.material_of(a), back.material_of(b));
    }
}
