//! The shadow-volume query against testing every sphere: for random scenes, camera rays cut into
//! segments (asked for front to back, so that later segments use the band searches of earlier
//! ones) and lights, the shadowers `light_pieces::resolve` finds are exactly the spheres that a
//! light ray from the segment can meet, except spheres it may leave out because every point
//! they shadow lies in a piece it reports as dark (bounded in the error) or as zero (behind an
//! opaque shadower). Without truncation no piece is dark.
//!
//! "Can meet" is decided here independently of the renderer: the distance from the centre to
//! the swept region (the strip towards a directional light, the triangle towards a point light)
//! is a convex function of one parameter once the other is minimised in closed form, found by
//! ternary search; a sphere meets the region iff that distance is at most its radius.

use crate::render::light_pieces::{resolve, Buffers, Class};
use crate::render::lights::LightKind;
use crate::render::{Prepared, RenderOptions};
use glam::DVec3;

use crate::testing as support;

use crate::testing::Rng;

impl Rng {
    fn v(&mut self, s: f64) -> DVec3 {
        DVec3::new(
            self.f() * 2.0 - 1.0,
            self.f() * 2.0 - 1.0,
            self.f() * 2.0 - 1.0,
        ) * s
    }
}

fn to_segment(c: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let u = if l2 > 0.0 {
        ((c - a).dot(ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + u * ab - c).length()
}

/// Minimum of a convex function on [0, 1].
fn ternary(f: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..100 {
        let m1 = lo + (hi - lo) / 3.0;
        let m2 = hi - (hi - lo) / 3.0;
        if f(m1) <= f(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

/// Distance from `c` to the region swept from `[a, b]` towards the light.
fn region_distance(c: DVec3, a: DVec3, b: DVec3, light: &LightKind) -> f64 {
    band_distance(c, a, b, light, (0.0, f64::INFINITY))
}

/// Distance from `c` to the band `f` of that region: `f` is the distance along the light's
/// direction (directional) or the fraction of the way to the light (point; clipped to 1).
/// Both are convex sets, and so is the distance once the inner parameter is minimised in
/// closed form.
pub fn band_distance(c: DVec3, a: DVec3, b: DVec3, light: &LightKind, (f0, f1): (f64, f64)) -> f64 {
    match *light {
        LightKind::Directional { to_light: l, .. } => ternary(|u| {
            let x = a + u * (b - a);
            let s = (c - x).dot(l).clamp(f0, f1);
            (x + s * l - c).length()
        }),
        LightKind::Point { position: p, .. } => {
            let (f0, f1) = (f0.clamp(0.0, 1.0), f1.clamp(0.0, 1.0));
            ternary(|g| {
                let g = f0 + g * (f1 - f0);
                to_segment(c, a + g * (p - a), b + g * (p - b))
            })
        }
    }
}

/// Whether the light ray from `x` meets the ball (c, r) before the light.
fn ray_meets(x: DVec3, light: &LightKind, c: DVec3, r: f64) -> bool {
    match *light {
        LightKind::Directional { to_light: l, .. } => {
            let s = (c - x).dot(l).max(0.0);
            (x + s * l - c).length() <= r
        }
        LightKind::Point { position: p, .. } => to_segment(c, x, p) <= r,
    }
}

fn scene(rng: &mut Rng, n: usize, lights: &str) -> Prepared {
    let mut body = format!("NavigationInfo {{ headlight FALSE }}\n{lights}\n");
    for k in 0..n {
        let c = rng.v(1.0);
        let r = 0.02 + 0.2 * rng.f().powi(2);
        // Mostly gas of every density, a few opaque spheres.
        let mat = if k % 7 == 3 {
            "diffuseColor 0.5 0.5 0.5".to_string()
        } else {
            format!(
                "transparency {} diffuseColor 0.7 0.7 0.7",
                (-8.0 * rng.f()).exp()
            )
        };
        body.push_str(&format!(
            "Transform {{ translation {} {} {} children Shape {{ appearance Appearance {{ material Material {{ {mat} }} }} geometry Sphere {{ radius {r} }} }} }}\n",
            c.x, c.y, c.z
        ));
    }
    let (scene, _) = support::scene(&body);
    support::prepare(scene)
}

fn check(
    prep: &Prepared,
    rng: &mut Rng,
    tau_cut: f64,
    cases: usize,
    grids: bool,
) -> (usize, usize) {
    // The lights a default render uses.
    let view = support::view(prep, &RenderOptions::default());
    // Every light of these gas scenes has a grid, so `grids` chooses the path tested.
    assert!(view.grids.iter().all(Option::is_some));
    let mut buffers = Buffers::default();
    let mut active = Vec::new();
    let (mut found_total, mut left_out) = (0, 0);
    for _ in 0..cases {
        let o = DVec3::new(rng.f() - 0.5, rng.f() - 0.5, 4.0);
        let target = rng.v(0.9);
        let d = (target - o).normalize();
        let (t_first, t_last) = (2.5 + rng.f(), 3.5 + 2.0 * rng.f());
        // The camera ray's part, cut into up to four segments asked for front to back, as the
        // integrator does: the later ones use the band searches of the earlier ones.
        let cuts = 1 + (rng.f() * 4.0) as usize;
        let mut ends: Vec<f64> = (1..cuts)
            .map(|_| t_first + (t_last - t_first) * rng.f())
            .collect();
        ends.sort_by(f64::total_cmp);
        ends.insert(0, t_first);
        ends.push(t_last);
        buffers.start_ray(o, d, (t_first, t_last));
        for w in ends.windows(2) {
            let (ta, tb) = (w[0], w[1]);
            let (a, b) = (o + ta * d, o + tb * d);
            for (slot, light) in view.lights.iter().enumerate() {
                active.clear();
                let (pieces, n) = resolve(
                    prep,
                    o,
                    d,
                    (ta, tb),
                    (slot, light, view.grids[slot].as_ref().filter(|_| grids)),
                    tau_cut,
                    &mut buffers,
                    &mut active,
                );
                let pieces = pieces.to_vec();
                let mut got: Vec<u32> = buffers.shadowers().collect();
                got.sort_unstable();
                assert_eq!(got.len(), n);
                found_total += n;
                // Pieces tile the segment.
                assert_eq!(pieces.first().unwrap().t0, ta);
                assert_eq!(pieces.last().unwrap().t1, tb);
                for w in pieces.windows(2) {
                    assert_eq!(w[0].t1, w[1].t0);
                }
                if tau_cut.is_infinite() {
                    assert!(!pieces.iter().any(|p| matches!(p.class, Class::Dark(_))));
                }
                for (i, p) in (0..prep.bvh.len() as u32).map(|i| (i as usize, prep.bvh.prim(i))) {
                    let dist = region_distance(p.center, a, b, &light.kind);
                    let listed = got.binary_search(&(i as u32)).is_ok();
                    if listed {
                        // Nothing far from the region is listed.
                        assert!(
                            dist <= p.radius * (1.0 + 1e-6) + 1e-9,
                            "listed sphere {i} is {dist} from the region, radius {}",
                            p.radius
                        );
                        continue;
                    }
                    if dist > p.radius * (1.0 - 1e-6) {
                        continue;
                    }
                    // Missed: allowed only where everything it shadows is dark (bounded) or zero
                    // (behind an opaque shadower: nothing more can change it).
                    left_out += 1;
                    for k in 0..=2000 {
                        let t = ta + (tb - ta) * k as f64 / 2000.0;
                        if !ray_meets(o + t * d, &light.kind, p.center, p.radius * (1.0 - 1e-6)) {
                            continue;
                        }
                        let piece = pieces
                            .iter()
                            .find(|q| q.t0 <= t && t <= q.t1)
                            .expect("a piece");
                        assert!(
                            !matches!(piece.class, Class::Lit(_)),
                            "sphere {i} (distance {dist}, radius {}) shadows t = {t} in a lit \
                         piece {piece:?} but was left out",
                            p.radius
                        );
                    }
                }
            }
        }
    }
    (found_total, left_out)
}

#[test]
fn shadowers_found_equal_every_sphere_tested() {
    let mut rng = Rng(2026);
    let lights = "DirectionalLight { direction -1 -0.7 -0.4 }\n\
                  DirectionalLight { direction 0.3 -1 0.2 }\n\
                  PointLight { location 1.5 1.2 0.8 }\n\
                  PointLight { location 0.1 -0.2 0.3 }";
    for n in [10, 60, 250] {
        let prep = scene(&mut rng, n, lights);
        // Through the lights' grids, and through the BVH (what a query falls back on).
        for grids in [true, false] {
            let (found, _) = check(&prep, &mut rng, f64::INFINITY, 12, grids);
            assert!(found > 0);
        }
    }
}

#[test]
fn truncated_queries_leave_out_only_what_lies_in_dark_pieces() {
    let mut rng = Rng(77);
    let lights = "DirectionalLight { direction -1 -1 -1 }\nPointLight { location 3 3 3 }";
    let prep = scene(&mut rng, 400, lights);
    let (_, left_out) = check(&prep, &mut rng, 6.0, 20, true);
    // The test is only meaningful if truncation actually left some spheres out.
    assert!(
        left_out > 0,
        "no sphere was left out: truncation not exercised"
    );
}
