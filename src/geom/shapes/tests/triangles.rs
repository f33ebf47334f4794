//! Triangles against Cramer's rule; watertight shared edges and vertices.

use super::*;

fn det3(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    a.dot(b.cross(c))
}

/// `(t, b1, b2)` with `o + t d = p0 + b1 (p1 - p0) + b2 (p2 - p0)`, by Cramer's rule.
fn cramer(p: &[DVec3; 3], o: DVec3, d: DVec3) -> (f64, f64, f64) {
    let (e1, e2, r) = (p[1] - p[0], p[2] - p[0], o - p[0]);
    let den = det3(e1, e2, -d);
    (
        det3(e1, e2, r) / den,
        det3(r, e2, -d) / den,
        det3(e1, r, -d) / den,
    )
}

#[test]
fn triangle_matches_cramer() {
    let mut rng = Rng::new(0x7_71a9);
    let (mut hits, mut misses, mut near) = (0, 0, 0);
    for _ in 0..100_000 {
        let scale = rng.log10(-6.0, 6.0);
        let c = cube(&mut rng) * 10.0 * scale;
        let p = [0; 3].map(|_| c + cube(&mut rng) * scale);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let target = p[0] + rng.range(-0.2, 1.2) * e1 + rng.range(-0.2, 1.2) * e2;
        let d = unit(&mut rng) * scale * rng.log10(-1.0, 1.0);
        let t0 = rng.range(0.5, 2.0);
        let o = target - t0 * d;
        let tmax = if rng.below(2) == 0 {
            f64::INFINITY
        } else {
            t0 * rng.range(0.5, 1.5)
        };
        let got = triangle_hit(&p, o, d, 0.0, tmax);
        let cos = d.normalize().dot(e1.cross(e2).normalize()).abs();
        let (t, b1, b2) = cramer(&p, o, d);
        let margin = b1.min(b2).min(1.0 - b1 - b2).min((tmax - t) / t);
        let tol = 1e-12 / cos.max(1e-300);
        if margin > tol {
            let h = got.unwrap_or_else(|| panic!("missed {p:?} o {o} d {d}: {t} {b1} {b2}"));
            assert!(
                (h.t - t).abs() <= tol * t && (h.b1 - b1).abs() <= tol && (h.b2 - b2).abs() <= tol
            );
            hits += 1;
        } else if margin < -tol {
            assert!(got.is_none(), "{p:?} o {o} d {d}: {got:?} vs {t} {b1} {b2}");
            misses += 1;
        } else {
            near += 1;
        }
    }
    println!("triangle vs Cramer: {hits} hits, {misses} misses, {near} within rounding");
    assert!(hits > 15_000 && misses > 50_000);
}

/// Rays through shared edges and `inner` vertices of a mesh, each crossing the surface there
/// (`d(target)` is no silhouette direction there): at least one triangle is hit. Returns
/// (rays, rays hitting two or more triangles, rays missed by a Cramer-rule test).
fn watertight(
    rng: &mut Rng,
    tris: &[[DVec3; 3]],
    inner: impl Fn(DVec3) -> bool,
    d: impl Fn(&mut Rng, DVec3) -> DVec3,
) -> (usize, usize, usize) {
    let (mut rays, mut both, mut leaky) = (0, 0, 0);
    for (i, a) in tris.iter().enumerate() {
        for b in &tris[i + 1..] {
            let shared: Vec<DVec3> = a.iter().copied().filter(|v| b.contains(v)).collect();
            let s = [0.5, rng.f(), 1.0 / 3.0][rng.below(3)];
            let mut targets = shared.clone();
            if let [v, w] = shared[..] {
                targets.extend([v + s * (w - v), w + (1.0 - s) * (v - w)]);
            }
            targets.retain(|&t| !shared.contains(&t) || inner(t));
            for target in targets {
                let d = d(rng, target);
                let o = target - rng.range(0.5, 2.0) * d;
                let n = tris
                    .iter()
                    .filter(|p| triangle_hit(p, o, d, 0.0, f64::INFINITY).is_some())
                    .count();
                assert!(n >= 1, "leak at {target} o {o} d {d}");
                let naive = tris.iter().any(|p| {
                    let (t, b1, b2) = cramer(p, o, d);
                    t > 0.0 && b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0
                });
                (rays, both, leaky) = (rays + 1, both + (n > 1) as usize, leaky + !naive as usize);
            }
        }
    }
    (rays, both, leaky)
}

#[test]
fn shared_edges_and_vertices_are_watertight() {
    let mut rng = Rng::new(0xface);
    let mut total = (0, 0, 0);
    for _ in 0..6 {
        // Height field, slopes below 1, seen from below at less than 45 degrees off -z; far
        // from the origin so the shear rounds.
        let (scale, off) = (rng.log10(-3.0, 3.0), cube(&mut rng) * 1e4);
        let z: Vec<f64> = (0..49).map(|_| rng.range(0.0, 0.5)).collect();
        let v = |i: usize, j: usize| off + scale * DVec3::new(i as f64, j as f64, z[7 * i + j]);
        let mut tris = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                let (a, b, c, e) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
                tris.extend(if rng.below(2) == 0 {
                    [[a, b, c], [a, c, e]]
                } else {
                    [[a, b, e], [b, c, e]]
                });
            }
        }
        let inner = |p: DVec3| {
            let (i, j) = ((p.x - off.x) / scale, (p.y - off.y) / scale);
            (0.5..5.5).contains(&i) && (0.5..5.5).contains(&j)
        };
        let r = watertight(&mut rng, &tris, inner, |rng, _| {
            DVec3::new(rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), -1.0) * rng.log10(-3.0, 3.0)
        });
        // Closed octahedron, rays towards a point inside.
        let (c, s) = (cube(&mut rng) * 1e3, rng.log10(-3.0, 3.0));
        let ax = |i: usize, sg: f64| c + DVec3::AXES[i] * sg * s;
        let mut oct = Vec::new();
        for m in 0..8 {
            let sg = |k: usize| if m >> k & 1 == 0 { 1.0 } else { -1.0 };
            oct.push([ax(0, sg(0)), ax(1, sg(1)), ax(2, sg(2))]);
        }
        let inner = c + cube(&mut rng) * 0.3 * s;
        let q = watertight(
            &mut rng,
            &oct,
            |_| true,
            |rng, t| (inner - t) * rng.log10(-3.0, 3.0),
        );
        total = (
            total.0 + r.0 + q.0,
            total.1 + r.1 + q.1,
            total.2 + r.2 + q.2,
        );
    }
    let (n, two, naive) = total;
    println!("watertight: {n} rays at shared edges/vertices all hit, {two} hit 2+, {naive} missed by Cramer");
    assert!(total.0 > 3000);
}

#[test]
fn triangles_in_plane_and_degenerate() {
    let mut rng = Rng::new(0xde9);
    for _ in 0..20_000 {
        let scale = rng.log10(-3.0, 3.0);
        let p = [0; 3].map(|_| cube(&mut rng) * scale);
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        // Rays in the plane: no panic; any hit lies within the triangle's range.
        let o = p[0] + rng.range(-2.0, 2.0) * e1 + rng.range(-2.0, 2.0) * e2;
        let d = rng.range(-1.0, 1.0) * e1 + rng.range(-1.0, 1.0) * e2;
        if let Some(h) = triangle_hit(&p, o, d, f64::NEG_INFINITY, f64::INFINITY) {
            assert!(h.t.is_finite() && h.b1 >= 0.0 && h.b2 >= 0.0 && h.b1 + h.b2 <= 1.0 + 1e-12);
        }
        // Exactly collinear points (dyadic, so the f64 arithmetic below is exact), coincident
        // points.
        let int = |rng: &mut Rng, n: usize| {
            DVec3::from_array([0; 3].map(|_| rng.below(n) as f64 - (n / 2) as f64))
        };
        let unit = 2f64.powi(rng.below(40) as i32 - 20);
        let (a, step) = (int(&mut rng, 64), int(&mut rng, 9));
        let m = [-3.0, -1.0, 2.0, 5.0][rng.below(4)];
        let line = [
            [a * unit, (a + step) * unit, (a + m * step) * unit],
            [p[0], p[0], p[1]],
        ];
        for t in &line {
            let target = t[0] + rng.range(-1.0, 2.0) * (t[2] - t[0]);
            let d = dir(&mut rng);
            assert!(
                triangle_hit(t, target - d, d, f64::NEG_INFINITY, f64::INFINITY).is_none(),
                "{t:?}"
            );
        }
    }
}
