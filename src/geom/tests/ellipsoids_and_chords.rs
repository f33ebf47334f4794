//! Ellipsoid roots and normals against brute force, segment chords against sampling, and the entering test against the careful roots.

use super::*;

/// An affine map with rotation, non-uniform scale 0.1..10, shear, overall size 1e-3..1e3 and
/// translation up to 1e4.
fn random_affine(rng: &mut Rng) -> DAffine3 {
    let q = DQuat::from_axis_angle(rng.dir(), rng.range(0.0, std::f64::consts::TAU));
    let s = DVec3::new(
        rng.log_uniform(0.1, 10.0),
        rng.log_uniform(0.1, 10.0),
        rng.log_uniform(0.1, 10.0),
    );
    let shear = DMat3::from_cols(
        DVec3::X,
        DVec3::new(rng.range(-0.5, 0.5), 1.0, 0.0),
        DVec3::new(rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), 1.0),
    );
    let m = DMat3::from_quat(q) * DMat3::from_diagonal(s) * shear * rng.log_uniform(1e-3, 1e3);
    DAffine3::from_mat3_translation(m, rng.dir() * rng.log_uniform(1e-2, 1e4))
}

fn frobenius(m: &DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

/// Brute-force roots of `F(t) = |to_object(o + t d)|^2 - 1` in world space: 4000 samples over
/// the ray's passage through a ball that bounds the ellipsoid, then bisection of each sign
/// change down to adjacent floats.
fn brute_force_roots(o: DVec3, d: DVec3, to_world: &DAffine3, to_object: &DAffine3) -> Vec<f64> {
    let f = |t: f64| to_object.transform_point3(o + t * d).length_squared() - 1.0;
    let radius = frobenius(&to_world.matrix3); // >= the largest semi-axis
    let tc = (to_world.translation - o).dot(d) / d.dot(d);
    let half = 1.01 * radius / d.length();
    let n = 4000;
    let ts: Vec<f64> = (0..=n)
        .map(|i| tc - half + 2.0 * half * i as f64 / n as f64)
        .collect();
    let mut roots = Vec::new();
    for w in ts.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        let (flo, fhi) = (f(lo), f(hi));
        if (flo <= 0.0) == (fhi <= 0.0) {
            continue;
        }
        let inside_at_lo = flo <= 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if (f(mid) <= 0.0) == inside_at_lo {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        roots.push(0.5 * (lo + hi));
    }
    roots
}

#[test]
fn ellipsoid_roots_and_normals_match_brute_force() {
    let mut rng = Rng(0x5eed_0005);
    let (mut max_root, mut max_normal) = (0f64, 0f64);
    for i in 0..400 {
        let to_world = random_affine(&mut rng);
        let to_object = to_world.inverse();
        // Build the line in object space (so hits are well inside and misses clearly out),
        // then hand only its world image to the code under test.
        let u = rng.dir();
        let (o_obj, hit) = match i % 3 {
            0 => (
                rng.dir() * rng.range(0.0, 0.5) - u * rng.range(2.0, 20.0),
                true,
            ),
            1 => (rng.dir() * rng.range(0.0, 0.5), true), // origin inside
            _ => (rng.perp(u) * 1.2 - u * rng.range(-5.0, 5.0), false),
        };
        let o = to_world.transform_point3(o_obj);
        let d = to_world.transform_vector3(u) * rng.log_uniform(1e-2, 1e2);
        let want = brute_force_roots(o, d, &to_world, &to_object);
        let got = ellipsoid_roots(o, d, &to_object);
        if !hit {
            assert!(want.is_empty() && got.is_none(), "{want:?} {got:?}");
            continue;
        }
        assert_eq!(want.len(), 2, "{want:?}");
        let (t0, t1) = got.expect("hit");
        // Both sides map world points to object space, which rounds by ~u |x| in world
        // length: ~u |M^-1| |x| in object space, |M^-1| the Frobenius norm. Errors are
        // measured in units of that (roots along d_obj = M^-1 d, whose cosine with the
        // normal is >= 0.87 here; normals, rotated by M^-T, amplify by cond(M)).
        let inv = frobenius(&to_object.matrix3);
        let cond = inv * frobenius(&to_world.matrix3);
        let d_obj = to_object.transform_vector3(d).length();
        for (t, w) in [(t0, want[0]), (t1, want[1])] {
            let p = o + t * d;
            let world = o.length() + to_world.translation.length() + p.length();
            let unit = U * inv * world;
            max_root = max_root.max((t - w).abs() * d_obj / unit);
            // Central differences are exact for a quadratic up to rounding, so a step as
            // large as the ellipsoid costs no truncation error.
            let f = |x: DVec3| to_object.transform_point3(x).length_squared() - 1.0;
            let h = frobenius(&to_world.matrix3);
            let grad = DVec3::new(
                f(p + h * DVec3::X) - f(p - h * DVec3::X),
                f(p + h * DVec3::Y) - f(p - h * DVec3::Y),
                f(p + h * DVec3::Z) - f(p - h * DVec3::Z),
            );
            let n = ellipsoid_normal(p, &to_object);
            max_normal = max_normal.max((n - grad.normalize()).length() / (cond * unit));
            assert!((n.length() - 1.0).abs() < 1e-15);
            assert!(n.dot(p - to_world.translation) > 0.0, "outward");
        }
    }
    eprintln!(
        "ellipsoid roots within {max_root:.1} and normals within {max_normal:.1} units of \
         u |M^-1| |x| (normals: times cond M)"
    );
    assert!(max_root < 16.0, "{max_root}");
    assert!(max_normal < 16.0, "{max_normal}");
}

#[test]
fn segment_chord_matches_sampling() {
    let mut rng = Rng(0x5eed_0006);
    let n = 20_000;
    for i in 0..300 {
        let r = rng.log_uniform(1e-2, 1e2);
        let c = rng.dir() * rng.log_uniform(1e-2, 1e3);
        let o = c + rng.dir() * r * rng.log_uniform(0.1, 100.0);
        let d = (c + rng.dir() * r * 1.2 - o) * rng.log_uniform(1e-2, 1e2);
        // A segment around where the sphere could be, sometimes reversed (empty).
        let tc = (c - o).dot(d) / d.dot(d);
        let span = 2.0 * r / d.length();
        let (mut ta, mut tb) = (
            tc + span * rng.range(-2.0, 2.0),
            tc + span * rng.range(-2.0, 2.0),
        );
        if i % 4 != 0 && ta > tb {
            (ta, tb) = (tb, ta);
        }
        let got = segment_chord(o, d, c, r, ta, tb);
        let want = if tb <= ta {
            0.0
        } else {
            // Midpoint samples: each of the two chord ends costs at most one cell.
            let dt = (tb - ta) / n as f64;
            let inside = (0..n)
                .filter(|&k| (o + (ta + (k as f64 + 0.5) * dt) * d - c).length() <= r)
                .count();
            inside as f64 * dt
        };
        let tol = 2.0 * (tb - ta).max(0.0) / n as f64 + 1e-12 * (ta.abs() + tb.abs());
        assert!((got - want).abs() <= tol, "{got} vs {want} (tol {tol})");
    }
}

/// `enters_between` (the shadow rays' test of an opaque sphere, which skips the careful roots
/// when a plain estimate is clear by a margin) answers exactly as the careful roots do, on
/// lines made to sit at its margins: entries near 0 (origins on or near the surface, as a
/// shadow ray leaving a touching or overlapping sphere), near `dist` (the light just before
/// or behind the sphere), closest approaches near `0.999 r` (where the estimate stops) and
/// near tangency, directions of any length, infinite `dist`. Where the exact oracle's entry is
/// clear of 0 and `dist`, both agree with it.
#[test]
fn enters_between_decides_as_the_careful_roots_do() {
    let mut rng = Rng(0x5eed_0008);
    let (mut cases, mut entering, mut oracle_checked) = (0, 0, 0);
    for i in 0..40_000 {
        let r = rng.log_uniform(1e-4, 1e4);
        let c = rng.dir() * rng.log_uniform(1e-3, 1e6);
        let k = i % 5;
        // The origin: on or near the surface (k = 0, 1), or anywhere around.
        let o = if k <= 1 {
            let off = if k == 0 {
                0.0
            } else {
                rng.sign() * rng.log_uniform(1e-16, 1e-3)
            };
            c + rng.dir() * r * (1.0 + off)
        } else {
            c + rng.dir() * r * rng.log_uniform(1e-2, 1e4)
        };
        // Aimed at a point `rho` from the centre across the line of sight: around 0.999 r
        // (k = 2), near tangency (k = 3), or anywhere within 1.2 r.
        let u = (c - o).normalize_or(DVec3::X);
        let rho = match k {
            2 => 0.999 * (1.0 + rng.sign() * rng.log_uniform(1e-12, 1e-2)),
            3 => 1.0 - rng.sign() * rng.log_uniform(1e-15, 1e-6),
            _ => rng.range(0.0, 1.2),
        };
        let aim = c + rng.perp(u) * r * rho;
        let mut d = (aim - o) * rng.log_uniform(1e-3, 1e3);
        if rng.u64() % 3 == 0 {
            // Away from the sphere too (an entry behind the origin).
            d = -d;
        }
        if rng.u64() % 50 == 0 {
            d *= rng.log_uniform(1e-200, 1e200);
        }
        if d == DVec3::ZERO || !d.is_finite() {
            continue;
        }
        // The light: infinitely far, anywhere, or within a hair of the careful entry.
        let t0 = sphere_roots(o, d, c, r).map(|(t0, _)| t0);
        let dist = match (rng.u64() % 4, t0) {
            (0, _) => f64::INFINITY,
            (1, Some(t0)) => t0 * (1.0 + rng.sign() * rng.log_uniform(1e-16, 1e-4)),
            (2, Some(t0)) => t0,
            _ => rng.log_uniform(1e-3, 1e3) * r / d.length(),
        };
        let want = t0.is_some_and(|t0| t0 > 0.0 && t0 < dist);
        assert_eq!(
            enters_between(o, d, c, r, dist),
            want,
            "o {o:?} d {d:?} c {c:?} r {r:e} dist {dist:e}"
        );
        cases += 1;
        entering += usize::from(want);
        // Against the exact entry, where it is clear of both ends by 1e-12 of the scale.
        if d.length() < 1e100 && d.length() > 1e-100 {
            let e = Exact::new(o, d, c, r);
            let scale = ((o - c).length() + r) / d.length();
            let clear = |t: f64| (t.abs() > 1e-12 * scale) && (t - dist).abs() > 1e-12 * scale;
            match e.roots() {
                Some([(lo, hi), _]) if clear(lo) && clear(hi) && e.margin() > 1e-12 => {
                    assert_eq!(
                        want,
                        lo > 0.0 && hi < dist,
                        "oracle: o {o:?} d {d:?} c {c:?}"
                    );
                    oracle_checked += 1;
                }
                None if e.margin() < -1e-12 => {
                    assert!(!want);
                    oracle_checked += 1;
                }
                _ => {}
            }
        }
    }
    eprintln!(
        "{cases} lines, {entering} entering, {oracle_checked} checked against the exact entry"
    );
    assert!(cases > 35_000 && entering > 5_000 && oracle_checked > 20_000);
}
