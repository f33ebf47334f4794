//! The library API for scenes built in code: `Scene::from_arrays` and `validate`, explicit
//! cameras, one prepared scene rendered from many cameras, progress and cancellation.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DQuat, DVec3};
use gtsphere::render::{self, Camera, Lens, PrepareOptions, Progress, RenderOptions};
use gtsphere::scene::{DirectionalLight, Light, PointLight, Radii, Scene, SphereArrays, Viewpoint};
use gtsphere::Error;

fn cloud(n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    // A small deterministic cloud (an LCG, so the test needs no RNG crate).
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let centers: Vec<f64> = (0..3 * n).map(|_| 2.0 * next() - 1.0).collect();
    let radii: Vec<f64> = (0..n).map(|_| 0.1 + 0.15 * next()).collect();
    let colors: Vec<f64> = (0..3 * n).map(|_| next()).collect();
    let transparency: Vec<f64> = (0..n)
        .map(|_| {
            if next() < 0.5 {
                0.0
            } else {
                0.2 + 0.6 * next()
            }
        })
        .collect();
    (centers, radii, colors, transparency)
}

fn lit_scene(n: usize) -> Scene {
    let (c, r, col, t) = cloud(n);
    let mut scene = Scene::from_arrays(&SphereArrays {
        colors: Some(&col),
        transparency: Some(&t),
        ..SphereArrays::new(&c, Radii::Each(&r))
    })
    .expect("valid arrays");
    scene.headlight = false;
    scene.lights.push(Light::Point(PointLight {
        location: DVec3::new(3.0, 3.0, 3.0),
        intensity: 0.8,
        ..PointLight::default()
    }));
    scene.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(-1.0, -1.0, -1.0).normalize(),
        intensity: 0.5,
        ..DirectionalLight::default()
    }));
    scene
}

fn small() -> RenderOptions {
    RenderOptions {
        width: 40,
        height: 30,
        spp: 2,
        ..RenderOptions::default()
    }
}

#[test]
fn from_arrays_keeps_order_and_shares_the_material_record() {
    let c = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0];
    let col = [0.5, 0.5, 0.5, 0.1, 0.2, 0.3, 0.5, 0.5, 0.5];
    let s = Scene::from_arrays(&SphereArrays {
        colors: Some(&col),
        ..SphereArrays::new(&c, Radii::One(0.25))
    })
    .unwrap();
    assert_eq!(s.spheres.len(), 3);
    assert_eq!(
        s.materials.len(),
        1,
        "materials that differ in colour share a record"
    );
    assert_eq!(s.spheres[0].material, s.spheres[2].material);
    assert_eq!(s.spheres[0].color, s.spheres[2].color);
    assert_eq!(s.spheres[1].center, DVec3::new(1.0, 0.0, 0.0));
    assert_eq!(
        s.material_of(&s.spheres[1]).diffuse,
        DVec3::new(0.1, 0.2, 0.3)
    );
    assert!(s.headlight, "VRML's default");
}

#[test]
fn from_arrays_errors_name_array_index_and_value() {
    let c = [0.0, 0.0, 0.0, 1.0, 0.0, f64::NAN];
    let err = |a: SphereArrays| Scene::from_arrays(&a).unwrap_err().to_string();
    assert_eq!(
        err(SphereArrays::new(&c, Radii::One(1.0))),
        "centers[1] = [1.0, 0.0, NaN]: the centre must be finite"
    );
    let c = [0.0; 6];
    assert_eq!(
        err(SphereArrays::new(&c, Radii::Each(&[1.0, 0.0]))),
        "radii[1] = 0.0: radius must be positive and finite"
    );
    assert_eq!(
        err(SphereArrays::new(&c, Radii::Each(&[1.0]))),
        "radii has 1 values for 2 centres"
    );
    assert_eq!(
        err(SphereArrays {
            transparency: Some(&[0.5, -0.1]),
            ..SphereArrays::new(&c, Radii::One(1.0))
        }),
        "transparency[1] = -0.1: transparency must be in [0, 1]"
    );
    assert_eq!(
        err(SphereArrays {
            emissive: Some(&[0.0, 0.0, 0.0, 0.0, 255.0, 0.0]),
            ..SphereArrays::new(&c, Radii::One(1.0))
        }),
        "emissive[1] = [0.0, 255.0, 0.0]: colour channels must be in [0, 1]"
    );
    assert!(matches!(
        Scene::from_arrays(&SphereArrays::new(&c[..5], Radii::One(1.0))),
        Err(Error::Invalid(_))
    ));
}

#[test]
fn prepare_validates_scenes_built_by_hand() {
    let mut s = lit_scene(3);
    s.spheres[2].radius = -1.0;
    let e = render::prepare(s, &PrepareOptions::default())
        .err()
        .unwrap();
    assert_eq!(
        e.to_string(),
        "spheres[2]: radius -1.0 must be positive and finite"
    );
    let mut s = lit_scene(3);
    s.lights.push(Light::Directional(DirectionalLight {
        direction: DVec3::new(0.0, 0.0, -2.0),
        ..DirectionalLight::default()
    }));
    let e = render::prepare(s, &PrepareOptions::default())
        .err()
        .unwrap();
    assert_eq!(
        e.to_string(),
        "lights[2]: the direction must be a unit vector"
    );
    let mut s = lit_scene(3);
    s.spheres[0].material = 99;
    assert!(render::prepare(s, &PrepareOptions::default()).is_err());
    // A material pushed in code is checked too, and named by its index.
    let mut s = lit_scene(3);
    s.materials.add(&gtsphere::scene::Material {
        transparency: 2.0,
        ..Default::default()
    });
    let e = render::prepare(s, &PrepareOptions::default())
        .err()
        .unwrap();
    assert!(
        e.to_string().starts_with("materials[")
            && e.to_string()
                .ends_with("transparency 2.0 must be in [0, 1]"),
        "{e}"
    );
    // Lights changed after prepare are checked when rendered.
    let mut prepared = render::prepare(lit_scene(3), &PrepareOptions::default()).unwrap();
    prepared.lights.push(Light::Point(PointLight {
        intensity: f64::NAN,
        ..PointLight::default()
    }));
    let cam = prepared.default_camera(8, 8).unwrap();
    let e = render::render(&prepared, &cam, &small(), &())
        .err()
        .unwrap();
    assert_eq!(
        e.to_string(),
        "lights[2]: colour and intensities must be finite and non-negative"
    );
}

#[test]
fn camera_constructors() {
    let c = Camera::look_at(
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::ZERO,
        DVec3::Y,
        Lens::default(),
    )
    .unwrap();
    let vp = Camera::from_viewpoint(&Viewpoint {
        position: DVec3::new(0.0, 0.0, 5.0),
        ..Viewpoint::default()
    })
    .unwrap();
    assert_eq!(
        c, vp,
        "look_at down -z equals the VRML default orientation bit for bit"
    );
    let turned = Camera::oriented(
        DVec3::ZERO,
        DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2),
        Lens::default(),
    )
    .unwrap();
    assert!((turned.forward - DVec3::NEG_X).length() < 1e-15);
    let bad = |r: Result<Camera, Error>| r.unwrap_err().to_string();
    assert!(bad(Camera::look_at(
        DVec3::ONE,
        DVec3::ONE,
        DVec3::Y,
        Lens::default()
    ))
    .contains("target is its own position"));
    assert!(bad(Camera::look_at(
        DVec3::Z,
        DVec3::ZERO,
        DVec3::Z,
        Lens::default()
    ))
    .contains("parallel"));
    assert!(bad(Camera::look_at(
        DVec3::Z,
        DVec3::ZERO,
        DVec3::Y,
        Lens::Perspective { fov: 0.0 }
    ))
    .contains("field of view 0"));
    // Framing: the ball's silhouette fits the smaller side of the image exactly, with margin.
    let (centre, radius) = (DVec3::new(1.0, 2.0, 3.0), 2.0);
    let f = Camera::frame(
        (centre, radius),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::Y,
        Lens::default(),
        0.0,
    )
    .unwrap();
    let d = (centre - f.position).length();
    let half = match f.lens {
        Lens::Perspective { fov } => 0.5 * fov,
        Lens::Orthographic { .. } => unreachable!(),
    };
    assert!(((radius / d).asin() - half).abs() < 1e-12);
    assert!(((centre - f.position).normalize() - f.forward).length() < 1e-12);
}

#[test]
fn one_prepared_scene_many_cameras_equals_fresh_prepares() {
    let prepared = render::prepare(lit_scene(80), &PrepareOptions::default()).unwrap();
    for k in 0..4 {
        let a = f64::from(k) * std::f64::consts::FRAC_PI_2;
        let cam = Camera::look_at(
            DVec3::new(4.0 * a.sin(), 1.0, 4.0 * a.cos()),
            DVec3::ZERO,
            DVec3::Y,
            Lens::default(),
        )
        .unwrap();
        let shared = render::render(&prepared, &cam, &small(), &()).unwrap();
        let fresh = render::prepare(lit_scene(80), &PrepareOptions::default()).unwrap();
        let alone = render::render(&fresh, &cam, &small(), &()).unwrap();
        assert_eq!(shared.rgb, alone.rgb);
        assert_eq!(shared.alpha, alone.alpha);
        assert!(shared.alpha.iter().any(|&a| a > 0.0));
    }
}

/// Cancels once `after` tiles are done; counts the tiles.
struct CancelAfter {
    after: u64,
    done: AtomicU64,
    total: AtomicU64,
}

impl Progress for CancelAfter {
    fn start(&self, tiles: u64) {
        self.total.store(tiles, Ordering::Relaxed);
    }
    fn tile_done(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        self.done.load(Ordering::Relaxed) >= self.after
    }
}

#[test]
fn progress_is_told_every_tile_and_can_cancel() {
    let prepared = render::prepare(lit_scene(50), &PrepareOptions::default()).unwrap();
    let cam = prepared.default_camera(64, 48).unwrap();
    let opts = RenderOptions {
        width: 64,
        height: 48,
        spp: 1,
        ..RenderOptions::default()
    };
    let count = CancelAfter {
        after: u64::MAX,
        done: AtomicU64::new(0),
        total: AtomicU64::new(0),
    };
    render::render(&prepared, &cam, &opts, &count).unwrap();
    assert_eq!(count.total.load(Ordering::Relaxed), 4 * 3);
    assert_eq!(count.done.load(Ordering::Relaxed), 4 * 3);

    let stop = CancelAfter {
        after: 1,
        done: AtomicU64::new(0),
        total: AtomicU64::new(0),
    };
    let big = RenderOptions {
        width: 2048,
        height: 2048,
        spp: 64,
        ..opts
    };
    let r = render::render(&prepared, &cam, &big, &stop);
    assert!(matches!(r, Err(Error::Cancelled)));
    // Of 16384 tiles, the first and those in flight when it cancelled are done.
    let done = stop.done.load(Ordering::Relaxed);
    assert!(done <= 1 + rayon::current_num_threads() as u64, "{done}");
    let flag = render::Cancel::default();
    flag.cancel();
    assert!(matches!(
        render::render(&prepared, &cam, &opts, &flag),
        Err(Error::Cancelled)
    ));
}

#[test]
fn render_option_errors_are_typed() {
    let prepared = render::prepare(lit_scene(5), &PrepareOptions::default()).unwrap();
    let cam = prepared.default_camera(10, 10).unwrap();
    for (opts, want) in [
        (
            RenderOptions {
                width: 0,
                ..small()
            },
            "the image size 0x30 is empty",
        ),
        (
            RenderOptions {
                tol: -1.0,
                ..small()
            },
            "tol = -1: the tolerance must be positive and finite",
        ),
        (
            RenderOptions {
                region: Some((0, 0, 50, 10)),
                ..small()
            },
            "the region 0,0,50,10 is empty or outside the 40x30 image",
        ),
    ] {
        match render::render(&prepared, &cam, &opts, &()) {
            Err(Error::Invalid(m)) => assert_eq!(m, want),
            other => panic!("expected Error::Invalid, got {:?}", other.map(|f| f.width)),
        }
    }
}
