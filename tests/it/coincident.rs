//! Coincident copies: an opaque sphere repeated in one place is drawn once (the same picture
//! and ids as one copy, one primitive in the BVH), while coincident gas adds up.

use glam::DVec3;
use gtsphere::render::{self, Aovs, RenderOptions};
use gtsphere::scene::{Material, Scene};

use crate::support::triangles;

fn scene(copies: usize, transparency: f64) -> Scene {
    let mut scene = Scene::default();
    let red = Material {
        diffuse: DVec3::new(0.8, 0.2, 0.1),
        transparency,
        ..Material::default()
    };
    for _ in 0..copies {
        scene.add_sphere(DVec3::ZERO, 1.0, &red);
    }
    // A sphere beside them, with ids after theirs.
    scene.add_sphere(DVec3::new(2.5, 0.0, 0.0), 0.5, &Material::default());
    scene
}

fn picture(scene: Scene) -> (render::Film, usize) {
    let prep = crate::support::prepare(scene);
    let opts = RenderOptions {
        width: 48,
        height: 32,
        spp: 2,
        aovs: Aovs {
            id: true,
            depth: true,
            ..Aovs::default()
        },
        ..RenderOptions::default()
    };
    let cam = prep.default_camera(48, 32).unwrap();
    let film = render::render(&prep, &cam, &opts, &()).unwrap();
    (film, prep.copies_dropped())
}

#[test]
fn opaque_copies_in_one_place_are_drawn_once() {
    let (one, dropped) = picture(scene(1, 0.0));
    assert_eq!(dropped, 0);
    let (many, dropped) = picture(scene(100_000, 0.0));
    assert_eq!(dropped, 99_999);
    assert_eq!(one.rgb, many.rgb);
    assert_eq!(one.depth, many.depth);
    // The copies' first is the one the id channel names; the sphere beside them keeps its
    // index in the scene.
    let ids = |f: &render::Film| {
        let mut v: Vec<i64> = f.id.clone().unwrap();
        v.sort();
        v.dedup();
        v
    };
    assert_eq!(ids(&one), vec![-1, 0, 1]);
    assert_eq!(ids(&many), vec![-1, 0, 100_000]);
}

#[test]
fn coincident_gas_adds_up() {
    let (one, dropped) = picture(scene(1, 0.99));
    assert_eq!(dropped, 0);
    let (two, dropped) = picture(scene(2, 0.99));
    assert_eq!(dropped, 0);
    // Twice the gas along every ray through it scatters more of the light (the background is
    // black); dropped as a copy, it would give the same pixels bit for bit.
    let light = |f: &render::Film| f.rgb.iter().map(|p| p[0]).sum::<f64>();
    assert!(
        light(&two) > light(&one) + 0.05,
        "{} {}",
        light(&two),
        light(&one)
    );
}

/// (That the copies are one primitive in the surfaces' BVH: `render::surfaces`' unit tests.)
#[test]
fn copies_of_a_triangle_keep_their_picture_and_ids() {
    let (one, _) = picture(triangles(1));
    let (many, _) = picture(triangles(50_000));
    assert_eq!(one.rgb, many.rgb);
    assert_eq!(one.id, many.id);
}

/// Two touching spheres of different radii and a third alone, each repeated, the copies
/// interleaved: the scene as `Scene::add_sphere` received it, in its order.
fn interleaved() -> Vec<(DVec3, f64)> {
    let a = (DVec3::ZERO, 1.0);
    let b = (DVec3::new(1.5, 0.0, 0.0), 0.5);
    let c = (DVec3::new(20.0, 0.0, 0.0), 1.0);
    vec![a, b, a, c, b, a, c, b, b]
}

fn scene_of(spheres: &[(DVec3, f64)]) -> Scene {
    let mut scene = Scene::default();
    for &(c, r) in spheres {
        scene.add_sphere(c, r, &Material::default());
    }
    scene
}

#[test]
fn the_spheres_in_scene_order_include_the_dropped_copies() {
    let spheres = interleaved();
    let prep = crate::support::prepare(scene_of(&spheres));
    assert_eq!(prep.copies_dropped(), 6);
    assert_eq!(prep.scene_spheres(), spheres);
    assert!(crate::support::prepare(Scene::default())
        .scene_spheres()
        .is_empty());
}

#[test]
fn each_copy_of_a_sphere_takes_its_mean_ao_and_no_copy_occludes() {
    use gtsphere::render::ao::Weighting;
    use gtsphere::render::particle_ao::particles_ao;
    let spheres = interleaved();
    let ao = (2.0, Weighting::Cosine);
    let prep = crate::support::prepare(scene_of(&spheres));
    let got = particles_ao(&prep, ao, 1e-4, &()).unwrap();
    assert_eq!(got.len(), spheres.len());
    // The three spheres once each, in another order: what each copy must take.
    let once = [spheres[3], spheres[1], spheres[0]];
    let alone = particles_ao(&crate::support::prepare(scene_of(&once)), ao, 1e-4, &()).unwrap();
    for (k, s) in spheres.iter().enumerate() {
        let j = once.iter().position(|o| o == s).unwrap();
        assert_eq!(got[k].mean, alone[j].mean, "sphere {k}");
        assert_eq!(got[k].error, alone[j].error, "sphere {k}");
    }
    // The third is alone within the reach (AO 1); the touching pair shade each other, the
    // small sphere more.
    assert_eq!(got[3].mean, 1.0);
    assert!(got[1].mean < got[0].mean && got[0].mean < 0.99, "{got:?}");
}
