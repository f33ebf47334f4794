use super::*;

/// A directional light towards `l` for even `k`, a point light at `p` for odd `k`.
fn light_for(k: usize, l: DVec3, p: DVec3) -> LightKind {
    if k % 2 == 0 {
        LightKind::Directional {
            to_light: l,
            scope: crate::scene::LightScope::All,
            surface_scope: crate::scene::LightScope::All,
        }
    } else {
        LightKind::Point {
            position: p,
            attenuation: DVec3::X,
            radius: 100.0,
        }
    }
}

/// The light ray of a point outside `reach_on_ray` never meets the ball (dense sampling of
/// the camera ray, the light ray tested in closed form).
#[test]
fn reach_on_ray_contains_every_parameter_whose_light_ray_meets_the_ball() {
    let mut rng = crate::testing::Rng::new(7);
    let mut rnd = || rng.range(-2.0, 2.0);
    let (mut met, mut narrow) = (0, 0);
    for k in 0..400 {
        let o = DVec3::new(rnd(), rnd(), rnd());
        let d = DVec3::new(rnd(), rnd(), rnd()).normalize();
        let c = DVec3::new(rnd(), rnd(), rnd());
        let r = 0.05 + 0.2 * (rnd() + 2.0);
        let p = DVec3::new(rnd(), rnd(), rnd()) * 2.0;
        let l = DVec3::new(rnd(), rnd(), rnd()).normalize();
        let light = light_for(k, l, p);
        let (t0, t1) = reach_on_ray(&light, o, d, c, r);
        narrow += usize::from(t1 - t0 < 6.0);
        for i in 0..=4000 {
            let t = -6.0 + 12.0 * i as f64 / 4000.0;
            let x = o + t * d;
            // The light ray from x: x + s u, s in [0, len].
            let (u, len) = match light {
                LightKind::Directional { to_light, .. } => (to_light, f64::INFINITY),
                LightKind::Point { position, .. } => {
                    ((position - x).normalize(), (position - x).length())
                }
            };
            let s = (c - x).dot(u).clamp(0.0, len);
            if (x + s * u - c).length() <= r {
                met += 1;
                assert!(t0 <= t && t <= t1, "t {t} outside {t0}..{t1} (case {k})");
            }
        }
    }
    assert!(met > 1000, "the test should meet balls ({met})");
    // And the intervals should prune: most are narrower than half the sampled range.
    assert!(narrow > 200, "only {narrow} narrow intervals");
}

/// Distances against dense sampling of the regions.
#[test]
fn band_and_triangle_distances_against_sampling() {
    let mut rng = crate::testing::Rng::new(99);
    let mut rnd = || rng.range(-2.0, 2.0);
    for k in 0..200 {
        let a = DVec3::new(rnd(), rnd(), rnd());
        let b = DVec3::new(rnd(), rnd(), rnd());
        let q = DVec3::new(rnd(), rnd(), rnd());
        let c = DVec3::new(rnd(), rnd(), rnd());
        let l = DVec3::new(rnd(), rnd(), rnd()).normalize();
        let (f0, f1) = (0.25 * (rnd() + 2.0), 2.0 + rnd() + 2.0);
        let light = light_for(k, l, c);
        let (f0, f1) = if k % 2 == 0 {
            (f0, f1)
        } else {
            (f0 * 0.25, (f1 * 0.25).min(1.0))
        };
        let band = Region::band(&light, a, b, f0, f1);
        let (mut best_b, mut best_t) = (f64::INFINITY, f64::INFINITY);
        for i in 0..=200 {
            let u = i as f64 / 200.0;
            let x = a + u * (b - a);
            for j in 0..=200 {
                let f = f0 + (f1 - f0) * j as f64 / 200.0;
                let y = match light {
                    LightKind::Directional { .. } => x + f * l,
                    LightKind::Point { .. } => x + f * (c - x),
                };
                best_b = best_b.min((y - q).length());
                let v = j as f64 / 200.0 * (1.0 - u);
                best_t = best_t.min((a + u * (b - a) + v * (c - a) - q).length());
            }
        }
        let db = band.distance(q);
        let dt = to_triangle(q, a, b, c);
        // The cheap tests never reject a ball, or a box around it, that meets the band.
        for r in [0.5 * db, db * (1.0 + 1e-9) + 1e-12, 1.5 * db, db + 1.0] {
            assert_eq!(band.meets(q, r), db <= r, "meets at r {r}, distance {db}");
            assert!(
                band.may_meet(q, r) || db > r,
                "may_meet at r {r}, distance {db}"
            );
            let h = DVec3::new(r, 1.5 * r, 2.0 * r); // contains the ball
            assert!(
                band.may_meet_box(q - h, q + h, 1e-12) || db > r,
                "may_meet_box at r {r}, distance {db}"
            );
        }
        assert!(
            db <= best_b + 1e-12 && db > best_b - 0.05,
            "band {db} vs {best_b}"
        );
        assert!(
            dt <= best_t + 1e-12 && dt > best_t - 0.05,
            "triangle {dt} vs {best_t}"
        );
    }
}
