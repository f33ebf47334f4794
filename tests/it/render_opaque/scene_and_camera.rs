//! The headlight, light scoping, unlit shapes, VRML defaults, framing, orthographic rays, viewpoint names and thread counts.

use super::*;

#[test]
fn headlight_on_and_off() {
    let (w, h) = (24, 24);
    let shape = sphere_shape("diffuseColor 0.5 0.6 0.7 specularColor 0.2 0.2 0.2 shininess 0.25");
    let m = Mat {
        diffuse: DVec3::new(0.5, 0.6, 0.7),
        specular: DVec3::splat(0.2),
        shininess: 0.25,
        ambient: 0.2,
        ..ZERO_MAT
    };
    let on = render_body(
        &format!("Viewpoint {{ position 0 0 5 fieldOfView 0.6 }}\n{shape}"),
        &center_opts(w, h),
    );
    // The headlight shines along the view direction (-z here): L = +z, intensity 1, no ambient.
    let hits = check_image(&on, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        let t = hit(o, d, DVec3::ZERO, 1.0)?;
        let n = (o + t * d).normalize();
        Some(vrml_term(
            &m,
            n,
            -d,
            DVec3::Z,
            DVec3::ONE,
            1.0,
            0.0,
            1.0,
            1.0,
        ))
    });
    assert!(hits > 50);
    let off = render_body(
        &format!("Viewpoint {{ position 0 0 5 fieldOfView 0.6 }}\nNavigationInfo {{ headlight FALSE }}\n{shape}"),
        &center_opts(w, h),
    );
    check_image(&off, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        hit(o, d, DVec3::ZERO, 1.0).map(|_| DVec3::ZERO)
    });
}

/// A DirectionalLight lights its siblings and their descendants only.
#[test]
fn directional_light_scoping() {
    let (w, h) = (48, 24);
    let shape = "Shape { appearance Appearance { material Material { diffuseColor 1 1 1 ambientIntensity 0 } } geometry Sphere { radius 0.8 } }";
    let body = format!(
        "Viewpoint {{ position 0 0 6 fieldOfView 0.6 }}\nNavigationInfo {{ headlight FALSE }}\n\
         Group {{ children [ DirectionalLight {{ direction 0 0 -1 }} Transform {{ translation -1 0 0 children {shape} }} ] }}\n\
         Transform {{ translation 1 0 0 children {shape} }}"
    );
    let img = render_body(&body, &center_opts(w, h));
    let (mut a, mut b) = (0, 0);
    check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 6.0), 0.6, w, h, i, j);
        let ta = hit(o, d, DVec3::new(-1.0, 0.0, 0.0), 0.8);
        let tb = hit(o, d, DVec3::new(1.0, 0.0, 0.0), 0.8);
        match (ta, tb) {
            (Some(t), _) if tb.is_none_or(|tb| t < tb) => {
                a += 1;
                let n = (o + t * d - DVec3::new(-1.0, 0.0, 0.0)) / 0.8;
                Some(DVec3::splat(n.dot(DVec3::Z).max(0.0)))
            }
            (_, Some(_)) => {
                b += 1;
                Some(DVec3::ZERO)
            }
            _ => None,
        }
    });
    assert!(a > 30 && b > 30);
}

#[test]
fn unlit_white_and_background() {
    let (w, h) = (20, 16);
    let body = "Viewpoint { position 0 0 5 fieldOfView 0.6 }\nBackground { skyColor 0.1 0.2 0.3 }\nDirectionalLight { }\nShape { geometry Sphere { } }";
    let img = render_body(body, &center_opts(w, h));
    let hits = check_image(&img, DVec3::new(0.1, 0.2, 0.3), |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        hit(o, d, DVec3::ZERO, 1.0).map(|_| DVec3::ONE)
    });
    assert!(hits > 30);
}

/// Material {}, DirectionalLight {} and VRML's default camera: everything from the spec's
/// defaults (diffuse 0.8, ambientIntensity 0.2, shininess 0.2, specular 0; light white,
/// intensity 1, ambientIntensity 0, direction 0 0 -1; camera (0,0,10), fieldOfView pi/4).
#[test]
fn vrml_defaults() {
    let (w, h) = (32, 24);
    let body = "NavigationInfo { headlight FALSE }\nDirectionalLight { }\nShape { appearance Appearance { material Material { } } geometry Sphere { } }";
    let img = render_body_from(
        body,
        &CameraChoice::VrmlDefault,
        Projection::PERSPECTIVE,
        &center_opts(w, h),
    );
    let m = Mat {
        diffuse: DVec3::splat(0.8),
        ambient: 0.2,
        ..ZERO_MAT
    };
    let hits = check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(
            DVec3::new(0.0, 0.0, 10.0),
            std::f64::consts::FRAC_PI_4,
            w,
            h,
            i,
            j,
        );
        let t = hit(o, d, DVec3::ZERO, 1.0)?;
        let n = (o + t * d).normalize();
        Some(vrml_term(
            &m,
            n,
            -d,
            DVec3::Z,
            DVec3::ONE,
            1.0,
            0.0,
            1.0,
            1.0,
        ))
    });
    assert!(hits > 20);
}

/// No Viewpoint: the camera looks down -z and frames the scene; every sphere is in view.
#[test]
fn no_viewpoint_frames_the_scene() {
    let body = "Transform { translation 100 50 -20 children Shape { geometry Sphere { radius 3 } } }\n\
                Transform { translation 130 40 -25 children Shape { geometry Sphere { radius 2 } } }";
    let opts = center_opts(64, 48);
    let prep = prepared(body);
    let (camera, description) = prep
        .camera(&CameraChoice::Auto, Projection::PERSPECTIVE, 64, 48)
        .expect("camera");
    assert!(description.contains("no Viewpoint"), "{description}");
    assert_eq!(camera.forward, DVec3::NEG_Z);
    let img = render::render(&prep, &camera, &opts, &())
        .expect("render")
        .image();
    // Both spheres are drawn (unlit white) and nothing touches the image border.
    let covered: f32 = img.alpha.iter().sum();
    assert!(covered > 50.0);
    for j in 0..48 {
        for i in [0, 63] {
            assert_eq!(img.alpha[j * 64 + i], 0.0);
        }
    }
    for i in 0..64 {
        assert_eq!(img.alpha[i], 0.0);
        assert_eq!(img.alpha[47 * 64 + i], 0.0);
    }
}

#[test]
fn orthographic_rays_are_parallel() {
    // An orthographic view of a unit sphere with height 4: the disc's radius in pixels is
    // exactly H / 4; the centre pixel sees N = +z.
    let (w, h) = (40, 40);
    let body = format!(
        "{CAM}DirectionalLight {{ direction 0 0 -1 }}\n{}",
        sphere_shape("diffuseColor 1 1 1 ambientIntensity 0")
    );
    let img = render_body_from(
        &body,
        &CameraChoice::Auto,
        Projection::Ortho { height: Some(4.0) },
        &center_opts(w, h),
    );
    check_image(&img, DVec3::ZERO, |i, j| {
        let x = ((i as f64 + 0.5) / w as f64 * 2.0 - 1.0) * 2.0;
        let y = (1.0 - (j as f64 + 0.5) / h as f64 * 2.0) * 2.0;
        let r2 = x * x + y * y;
        (r2 < 1.0).then(|| DVec3::splat((1.0 - r2).sqrt()))
    });
}

#[test]
fn unknown_viewpoint_name_is_a_clear_error() {
    let (scene, _) = support::scene(
        "DEF Top Viewpoint { description \"top view\" }\nShape { geometry Sphere {} }",
    );
    let prep = support::prepare(scene);
    let err = prep
        .camera(
            &CameraChoice::Named("side".into()),
            Projection::PERSPECTIVE,
            4,
            4,
        )
        .expect_err("must fail")
        .to_string();
    assert!(
        err.contains("no Viewpoint named \"side\"") && err.contains("Top"),
        "{err}"
    );
    // By description too.
    let (scene, _) = support::scene(
        "DEF Top Viewpoint { description \"top view\" }\nShape { geometry Sphere {} }",
    );
    let prep = support::prepare(scene);
    assert!(prep
        .camera(
            &CameraChoice::Named("top view".into()),
            Projection::PERSPECTIVE,
            4,
            4
        )
        .is_ok());
}

/// The same seed gives the same image, bit for bit, on 1 and 2 threads.
#[test]
fn image_is_the_same_on_any_thread_count() {
    let body = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/samples/cluster.wrl"))
        .expect("sample");
    let (scene, _) = support::load(&body);
    let opts = RenderOptions {
        width: 64,
        height: 48,
        spp: 9,
        seed: 3,
        ..RenderOptions::default()
    };
    let prep = support::prepare(scene);
    let camera = support::default_camera(&prep, &opts);
    let run = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| render::render(&prep, &camera, &opts, &()).expect("render"))
            .image()
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.rgb, b.rgb);
    assert_eq!(a.alpha, b.alpha);
    // And the samples do matter: another seed changes some edge pixels.
    let other = RenderOptions {
        seed: 4,
        ..opts.clone()
    };
    let c = render::render(&prep, &camera, &other, &())
        .expect("render")
        .image();
    assert_ne!(a.rgb, c.rgb);
}
