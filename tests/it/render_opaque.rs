//! Opaque rendering against closed forms: every expected value here is computed in the test
//! from the VRML97 lighting equation (docs/model.md section 2), with its own camera rays, its own
//! (textbook) ray/sphere intersection and its own shadow test; nothing is compared with a
//! saved image.

use glam::DVec3;
use gtsphere::output::Image;
use gtsphere::render::{self, CameraChoice, Prepared, Projection, RenderOptions, SamplerKind};

use crate::support;

mod scene_and_camera;

// ---------------------------------------------------------------------------------------------
// The independent reference

/// Material as the test sees it.
#[derive(Clone, Copy)]
pub(crate) struct Mat {
    pub(crate) diffuse: DVec3,
    pub(crate) emissive: DVec3,
    pub(crate) specular: DVec3,
    pub(crate) shininess: f64,
    pub(crate) ambient: f64,
}

/// One light's contribution per the VRML equation, given the geometry and the visibility.
#[allow(clippy::too_many_arguments)]
pub(crate) fn vrml_term(
    m: &Mat,
    n: DVec3,
    v: DVec3,
    l: DVec3,
    color: DVec3,
    intensity: f64,
    ambient_intensity: f64,
    att: f64,
    vis: f64,
) -> DVec3 {
    let ambient = ambient_intensity * m.diffuse * m.ambient;
    let h = (l + v).normalize();
    let diff = m.diffuse * n.dot(l).max(0.0);
    let spec = m.specular * n.dot(h).max(0.0).powf(128.0 * m.shininess);
    att * color * (ambient + vis * intensity * (diff + spec))
}

/// Textbook ray/sphere: nearest root in front of the origin (all test geometry is benign).
fn hit(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<f64> {
    let f = o - c;
    let b = f.dot(d);
    let disc = b * b - (f.dot(f) - r * r);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 0.0).then_some(t)
}

/// Perspective ray through pixel (i, j)'s centre for a camera at `p` looking down -z with
/// `fov` on the smaller side.
pub(crate) fn pixel_ray(p: DVec3, fov: f64, w: u32, h: u32, i: u32, j: u32) -> (DVec3, DVec3) {
    let (u, v) = ((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
    let t = (fov / 2.0).tan();
    let (sx, sy) = if w >= h {
        (t * w as f64 / h as f64, t)
    } else {
        (t, t * h as f64 / w as f64)
    };
    let d = DVec3::new((2.0 * u - 1.0) * sx, (1.0 - 2.0 * v) * sy, -1.0).normalize();
    (p, d)
}

pub(crate) fn center_opts(w: u32, h: u32) -> RenderOptions {
    RenderOptions {
        width: w,
        height: h,
        spp: 1,
        sampler: SamplerKind::Center,
        ..RenderOptions::default()
    }
}

fn prepared(body: &str) -> Prepared {
    let (scene, _) = support::scene(body);
    support::prepare(scene)
}

fn render_body(body: &str, opts: &RenderOptions) -> Image {
    support::render_prepared(&prepared(body), opts).image()
}

/// [`render_body`] from the camera `choice` and `projection` ask for (the command line's
/// `--camera` and `--ortho`).
fn render_body_from(
    body: &str,
    choice: &CameraChoice,
    projection: Projection,
    opts: &RenderOptions,
) -> Image {
    let prep = prepared(body);
    let (camera, _) = prep
        .camera(choice, projection, opts.width, opts.height)
        .expect("camera");
    render::render(&prep, &camera, opts, &())
        .expect("render")
        .image()
}

/// Every pixel equals `expect(i, j)` (None: background `bg`, alpha 0) to `1e-6` relative.
fn check_image(img: &Image, bg: DVec3, mut expect: impl FnMut(u32, u32) -> Option<DVec3>) -> usize {
    let mut hits = 0;
    for j in 0..img.height as u32 {
        for i in 0..img.width as u32 {
            let at = j as usize * img.width + i as usize;
            let got = DVec3::from_array(img.rgb[at].map(f64::from));
            let (want, alpha) = match expect(i, j) {
                Some(c) => {
                    hits += 1;
                    (c, 1.0)
                }
                None => (bg, 0.0),
            };
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-6 * (1.0 + want[k].abs()),
                    "pixel ({i},{j}) channel {k}: got {got} want {want}"
                );
            }
            assert_eq!(img.alpha[at], alpha, "alpha at ({i},{j})");
        }
    }
    hits
}

const CAM: &str =
    "Viewpoint { position 0 0 5 fieldOfView 0.6 }\nNavigationInfo { headlight FALSE }\n";

fn sphere_shape(material: &str) -> String {
    format!("Shape {{ appearance Appearance {{ material Material {{ {material} }} }} geometry Sphere {{ radius 1 }} }}")
}

/// A single unit sphere at the origin lit by one DirectionalLight; `material` and the
/// expected material `m` must agree.
fn directional_case(material: &str, m: Mat) {
    let (w, h) = (40, 30);
    let light = "DirectionalLight { direction -0.3 -0.4 -1 color 1 0.8 0.6 intensity 0.9 ambientIntensity 0.5 }";
    let body = format!("{CAM}{light}\n{}", sphere_shape(material));
    let img = render_body(&body, &center_opts(w, h));
    let l = -DVec3::new(-0.3, -0.4, -1.0).normalize();
    let hits = check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        let t = hit(o, d, DVec3::ZERO, 1.0)?;
        let n = (o + t * d).normalize();
        // A unit sphere alone: the only shadow is its own (N.L <= 0).
        let vis = if n.dot(l) > 0.0 { 1.0 } else { 0.0 };
        Some(m.emissive + vrml_term(&m, n, -d, l, DVec3::new(1.0, 0.8, 0.6), 0.9, 0.5, 1.0, vis))
    });
    assert!(hits > 200, "the sphere covers {hits} pixels");
}

const ZERO_MAT: Mat = Mat {
    diffuse: DVec3::ZERO,
    emissive: DVec3::ZERO,
    specular: DVec3::ZERO,
    shininess: 0.2,
    ambient: 0.0,
};

#[test]
fn directional_diffuse_alone() {
    directional_case(
        "diffuseColor 0.6 0.5 0.4 ambientIntensity 0",
        Mat {
            diffuse: DVec3::new(0.6, 0.5, 0.4),
            ..ZERO_MAT
        },
    );
}

#[test]
fn directional_specular_alone() {
    directional_case(
        "diffuseColor 0 0 0 specularColor 0.7 0.6 0.5 shininess 0.3 ambientIntensity 0",
        Mat {
            specular: DVec3::new(0.7, 0.6, 0.5),
            shininess: 0.3,
            ..ZERO_MAT
        },
    );
}

#[test]
fn directional_ambient_alone() {
    // The light's intensity is 0: only its ambient part is left.
    let (w, h) = (20, 20);
    let body = format!(
        "{CAM}DirectionalLight {{ intensity 0 ambientIntensity 0.7 color 0.5 1 0.25 }}\n{}",
        sphere_shape("diffuseColor 0.6 0.5 0.4 ambientIntensity 0.8")
    );
    let img = render_body(&body, &center_opts(w, h));
    let want = DVec3::new(0.5, 1.0, 0.25) * 0.7 * DVec3::new(0.6, 0.5, 0.4) * 0.8;
    let hits = check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        hit(o, d, DVec3::ZERO, 1.0).map(|_| want)
    });
    assert!(hits > 50);
}

#[test]
fn emissive_alone() {
    let (w, h) = (20, 20);
    let body = format!(
        "{CAM}{}",
        sphere_shape("diffuseColor 0 0 0 emissiveColor 0.2 0.3 0.4")
    );
    let img = render_body(&body, &center_opts(w, h));
    check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        hit(o, d, DVec3::ZERO, 1.0).map(|_| DVec3::new(0.2, 0.3, 0.4))
    });
}

#[test]
fn point_light_with_attenuation() {
    let (w, h) = (36, 36);
    let lp = DVec3::new(2.0, 1.5, 3.0);
    let body = format!(
        "{CAM}PointLight {{ location 2 1.5 3 attenuation 0.5 0.3 0.1 intensity 0.8 ambientIntensity 0.25 color 1 0.9 0.7 radius 100 }}\n{}",
        sphere_shape("diffuseColor 0.6 0.5 0.4 specularColor 0.3 0.3 0.3 shininess 0.1 ambientIntensity 0.4 emissiveColor 0.01 0.02 0.03")
    );
    let m = Mat {
        diffuse: DVec3::new(0.6, 0.5, 0.4),
        emissive: DVec3::new(0.01, 0.02, 0.03),
        specular: DVec3::splat(0.3),
        shininess: 0.1,
        ambient: 0.4,
    };
    let img = render_body(&body, &center_opts(w, h));
    let hits = check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        let t = hit(o, d, DVec3::ZERO, 1.0)?;
        let x = o + t * d;
        let n = x.normalize();
        let dist = (lp - x).length();
        let l = (lp - x) / dist;
        let att = 1.0 / (0.5 + 0.3 * dist + 0.1 * dist * dist).max(1.0);
        let vis = if n.dot(l) > 0.0 { 1.0 } else { 0.0 };
        Some(m.emissive + vrml_term(&m, n, -d, l, DVec3::new(1.0, 0.9, 0.7), 0.8, 0.25, att, vis))
    });
    assert!(hits > 300);
}

#[test]
fn point_light_radius_limits_its_reach() {
    // The light reaches only points within radius 4.3 of (0,0,5): the sphere's front cap.
    let (w, h) = (30, 30);
    let lp = DVec3::new(0.0, 0.0, 5.0);
    let body = format!(
        "{CAM}PointLight {{ location 0 0 5 radius 4.3 ambientIntensity 0.5 }}\n{}",
        sphere_shape("diffuseColor 1 1 1 ambientIntensity 1")
    );
    let img = render_body(&body, &center_opts(w, h));
    let (mut inside, mut outside) = (0, 0);
    check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(lp, 0.6, w, h, i, j);
        let t = hit(o, d, DVec3::ZERO, 1.0)?;
        let x = o + t * d;
        let dist = (lp - x).length();
        if dist > 4.3 {
            outside += 1;
            return Some(DVec3::ZERO);
        }
        inside += 1;
        let n = x.normalize();
        let l = (lp - x) / dist;
        Some(DVec3::splat(0.5 + n.dot(l).max(0.0)))
    });
    assert!(inside > 20 && outside > 20, "{inside} {outside}");
}

/// A small sphere between the light and a big one: shadowed points get exactly the ambient
/// term; elsewhere the full equation. The test's own shadow test decides which is which.
#[test]
fn shadowed_points_get_exactly_the_ambient_term() {
    let (w, h) = (64, 48);
    let blocker = (DVec3::new(1.8, 0.1, 0.3), 0.4);
    let body = format!(
        "{CAM}DirectionalLight {{ direction -1 -0.05 0 ambientIntensity 0.3 }}\n{}\nTransform {{ translation 1.8 0.1 0.3 children Shape {{ appearance Appearance {{ material Material {{ diffuseColor 0.2 0.9 0.2 ambientIntensity 0 }} }} geometry Sphere {{ radius 0.4 }} }} }}",
        sphere_shape("diffuseColor 0.9 0.6 0.3 ambientIntensity 0.5")
    );
    let img = render_body(&body, &center_opts(w, h));
    let l = -DVec3::new(-1.0, -0.05, 0.0).normalize();
    let m = Mat {
        diffuse: DVec3::new(0.9, 0.6, 0.3),
        ambient: 0.5,
        ..ZERO_MAT
    };
    let mb = Mat {
        diffuse: DVec3::new(0.2, 0.9, 0.2),
        ..ZERO_MAT
    };
    let (mut shadowed, mut lit) = (0, 0);
    check_image(&img, DVec3::ZERO, |i, j| {
        let (o, d) = pixel_ray(DVec3::new(0.0, 0.0, 5.0), 0.6, w, h, i, j);
        let ta = hit(o, d, DVec3::ZERO, 1.0);
        let tb = hit(o, d, blocker.0, blocker.1);
        match (ta, tb) {
            (None, None) => None,
            (_, Some(tb)) if ta.is_none_or(|ta| tb < ta) => {
                let x = o + tb * d;
                let n = (x - blocker.0).normalize();
                let vis = if n.dot(l) > 0.0 { 1.0 } else { 0.0 };
                Some(vrml_term(&mb, n, -d, l, DVec3::ONE, 1.0, 0.3, 1.0, vis))
            }
            (Some(ta), _) => {
                let x = o + ta * d;
                let n = x.normalize();
                let blocked = hit(x, l, blocker.0, blocker.1).is_some();
                let vis = if n.dot(l) > 0.0 && !blocked { 1.0 } else { 0.0 };
                if n.dot(l) > 0.0 {
                    if blocked {
                        shadowed += 1;
                        // Exactly the ambient term.
                        let amb = 0.3 * m.diffuse * m.ambient;
                        let full = vrml_term(&m, n, -d, l, DVec3::ONE, 1.0, 0.3, 1.0, vis);
                        assert_eq!(amb, full);
                    } else {
                        lit += 1;
                    }
                }
                Some(vrml_term(&m, n, -d, l, DVec3::ONE, 1.0, 0.3, 1.0, vis))
            }
            _ => unreachable!(),
        }
    });
    assert!(shadowed > 20 && lit > 100, "shadowed {shadowed}, lit {lit}");
}
