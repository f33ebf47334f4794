//! Tests against independent references: each part's implicit function sampled densely along
//! the ray with bisection (crossings), Cramer's rule (triangles), and `shadowed` sampled on a
//! dense grid (shadow breaks). Counts go to stdout (`--nocapture`).

use super::shadow::{breaks, ALL, BOUNDARY, SURFACE, TANGENT};
use super::*;
use crate::testing::Rng;
use glam::DVec3;
use std::f64::consts::TAU;

/// Uniform in the cube `[-1, 1]^3`.
fn cube(rng: &mut Rng) -> DVec3 {
    DVec3::from_array([(); 3].map(|_| rng.range(-1.0, 1.0)))
}

fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = cube(rng);
        if (1e-4..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// A random direction of random length (1e-3 .. 1e3).
fn dir(rng: &mut Rng) -> DVec3 {
    unit(rng) * rng.log10(-3.0, 3.0)
}

fn cyl(radius: f64, half_height: f64, [bottom, side, top]: [bool; 3]) -> Solid {
    Solid::Cylinder {
        radius,
        half_height,
        bottom,
        side,
        top,
    }
}

fn cone(radius: f64, half_height: f64, [side, bottom]: [bool; 2]) -> Solid {
    Solid::Cone {
        radius,
        half_height,
        side,
        bottom,
    }
}

/// The parameter span of the line inside the box `|x_i| <= hi_i`, written apart from cuboid.rs.
fn extent(o: DVec3, d: DVec3, hi: DVec3) -> Option<(f64, f64)> {
    let (mut lo_t, mut hi_t) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..3 {
        if d[i] == 0.0 {
            if o[i].abs() > hi[i] {
                return None;
            }
        } else {
            let (a, b) = ((-hi[i] - o[i]) / d[i], (hi[i] - o[i]) / d[i]);
            lo_t = lo_t.max(a.min(b));
            hi_t = hi_t.min(a.max(b));
        }
    }
    (lo_t < hi_t).then_some((lo_t, hi_t))
}

/// Solids of sizes 1e-9 .. 1e9, with every combination of parts.
fn solids(rng: &mut Rng) -> Vec<Solid> {
    let mut v = Vec::new();
    for scale in [1e-9, 1e-3, 1.0, 1e3, 1e9] {
        let mut len = || scale * rng.log10(-1.0, 1.0);
        v.push(Solid::Cuboid {
            half: DVec3::new(len(), len(), len()),
        });
        for m in 0..8 {
            v.push(cyl(len(), len(), [m & 1 != 0, m & 2 != 0, m & 4 != 0]));
        }
        for m in 0..4 {
            v.push(cone(len(), len(), [m & 1 != 0, m & 2 != 0]));
        }
    }
    v
}

/// A surface patch: an implicit function (outward positive) and the patch that it is cut to.
#[derive(Clone, Copy, Debug)]
enum Part {
    /// Box face `x_axis = at` of the box `half`.
    Face(usize, f64, DVec3),
    /// Cap disc at `y`, radius `r`.
    Disc(f64, f64),
    /// Cylinder side `r`, `|y| <= h`.
    Tube(f64, f64),
    /// Cone side `r`, `h` (apex at `y = h`).
    Mantle(f64, f64),
}

impl Part {
    fn g(self, p: DVec3) -> f64 {
        match self {
            Part::Face(i, at, _) => (p[i] - at) * at.signum(),
            Part::Disc(y, _) => (p.y - y) * y.signum(),
            Part::Tube(r, _) => p.x * p.x + p.z * p.z - r * r,
            Part::Mantle(r, h) => p.x * p.x + p.z * p.z - (r / (2.0 * h) * (h - p.y)).powi(2),
        }
    }
    /// How far `p` lies outside the patch (<= 0 inside).
    fn outside(self, p: DVec3) -> f64 {
        match self {
            Part::Face(i, _, half) => (0..3)
                .filter(|&j| j != i)
                .map(|j| p[j].abs() - half[j])
                .fold(f64::NEG_INFINITY, f64::max),
            Part::Disc(_, r) => p.x.hypot(p.z) - r,
            Part::Tube(_, h) => p.y.abs() - h,
            Part::Mantle(_, h) => (p.y - h).max(-h - p.y),
        }
    }
    fn normal(self, p: DVec3) -> DVec3 {
        match self {
            Part::Face(i, at, _) => DVec3::AXES[i] * at.signum(),
            Part::Disc(y, _) => DVec3::Y * y.signum(),
            Part::Tube(..) => DVec3::new(p.x, 0.0, p.z).normalize(),
            Part::Mantle(r, h) => {
                DVec3::new(p.x, (r / (2.0 * h)).powi(2) * (h - p.y), p.z).normalize()
            }
        }
    }
}

/// The solid's present parts, and whether it is closed.
fn parts(s: &Solid) -> (Vec<Part>, bool) {
    let hi = s.bounds().1;
    let (r, h) = (hi.x, hi.y);
    let all = match *s {
        Solid::Cuboid { half } => (0..6)
            .map(|i| {
                (
                    true,
                    Part::Face(i % 3, if i < 3 { 1.0 } else { -1.0 } * half[i % 3], half),
                )
            })
            .collect(),
        Solid::Cylinder {
            bottom, side, top, ..
        } => {
            vec![
                (bottom, Part::Disc(-h, r)),
                (side, Part::Tube(r, h)),
                (top, Part::Disc(h, r)),
            ]
        }
        Solid::Cone { side, bottom, .. } => {
            vec![(side, Part::Mantle(r, h)), (bottom, Part::Disc(-h, r))]
        }
    };
    let closed = all.iter().all(|p| p.0);
    (
        all.into_iter().filter(|p| p.0).map(|p| p.1).collect(),
        closed,
    )
}

/// Distance from `p` to the solid's boundary curves (rims, edges, apex): about 0 there.
fn edge_distance(s: &Solid, p: DVec3) -> f64 {
    let hi = s.bounds().1;
    let rim = |y: f64| (p.x.hypot(p.z) - hi.x).hypot(y);
    match s {
        Solid::Cuboid { .. } => {
            let mut e = (p.abs() - hi).to_array();
            e.sort_by(f64::total_cmp);
            e[1].abs().max(e[2].abs())
        }
        Solid::Cylinder { .. } => rim(p.y.abs() - hi.y),
        Solid::Cone { .. } => (p - DVec3::Y * hi.y).length().min(rim(p.y + hi.y)),
    }
}

/// A random point on a rim, edge, corner or the apex.
fn boundary_point(rng: &mut Rng, s: &Solid) -> DVec3 {
    let hi = s.bounds().1;
    let phi = rng.range(0.0, TAU);
    let sign = |rng: &mut Rng| if rng.below(2) == 0 { 1.0 } else { -1.0 };
    match (s, rng.below(3)) {
        (Solid::Cuboid { .. }, k) => {
            let mut p = DVec3::new(sign(rng), sign(rng), sign(rng)) * hi;
            if k != 0 {
                let i = rng.below(3);
                p[i] = rng.range(-1.0, 1.0) * hi[i];
            }
            p
        }
        (Solid::Cone { .. }, 0) => DVec3::Y * hi.y,
        (Solid::Cone { .. }, _) => DVec3::new(hi.x * phi.cos(), -hi.y, hi.x * phi.sin()),
        (Solid::Cylinder { .. }, _) => {
            DVec3::new(hi.x * phi.cos(), sign(rng) * hi.y, hi.x * phi.sin())
        }
    }
}

/// A random point on the solid's surface (all parts, present or not).
fn surface_point(rng: &mut Rng, s: &Solid) -> DVec3 {
    let hi = s.bounds().1;
    let (r, h, f) = (hi.x, hi.y, rng.f());
    let (c, sn) = rng.range(0.0, TAU).sin_cos();
    match (s, rng.below(3)) {
        (Solid::Cuboid { .. }, i) => {
            let mut p = cube(rng) * hi;
            p[i] = hi[i].copysign(p[i]);
            p
        }
        (Solid::Cylinder { .. }, 0) => DVec3::new(r * c, rng.range(-h, h), r * sn),
        (Solid::Cone { .. }, 0) => DVec3::new(r * f * c, h - 2.0 * h * f, r * f * sn),
        (_, k) => {
            let y = if k == 1 && matches!(s, Solid::Cylinder { .. }) {
                h
            } else {
                -h
            };
            DVec3::new(r * f.sqrt() * c, y, r * f.sqrt() * sn)
        }
    }
}

/// Random rays: anywhere, through rims/edges/apex, through surface points, parallel to the
/// axis (exactly or nearly), with zero direction components.
fn ray(rng: &mut Rng, s: &Solid) -> (DVec3, DVec3) {
    let hi = s.bounds().1;
    let o = cube(rng) * 3.0 * hi;
    let d = dir(rng);
    match rng.below(8) {
        0 => (o, d),
        1 => (o, (cube(rng) * hi - o) * rng.log10(-3.0, 3.0)),
        2 | 3 => (o, (boundary_point(rng, s) - o) * rng.log10(-3.0, 3.0)),
        4 => (o, (surface_point(rng, s) - o) * rng.log10(-3.0, 3.0)),
        5 => {
            let eps = [0.0, 1e-14, 1e-9, 1e-5][rng.below(4)];
            (
                cube(rng) * 1.2 * hi,
                (DVec3::Y + eps * unit(rng)) * d.y.signum() * d.length(),
            )
        }
        _ => {
            let mut d = d;
            d[rng.below(3)] = 0.0;
            if rng.below(2) == 0 {
                d[rng.below(3)] = 0.0;
            }
            (o, if d == DVec3::ZERO { DVec3::X } else { d })
        }
    }
}

/// Every root of each part's implicit function along the ray in `[t0, t1]`: sign changes
/// between `n` samples, and pairs of roots closer than a step around a sample where `|g|` is
/// least (the extremum found by ternary search), bisected to the last bit.
fn reference(
    parts: &[Part],
    o: DVec3,
    d: DVec3,
    (t0, t1): (f64, f64),
    n: usize,
) -> Vec<(f64, Part)> {
    let mut out = Vec::new();
    for &part in parts {
        let g = |t: f64| part.g(o + t * d);
        let at = |i: usize| t0 + (t1 - t0) * i as f64 / n as f64;
        let bisect = |mut lo: f64, mut hi: f64| {
            let pos = g(lo) > 0.0;
            loop {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    return mid;
                }
                if (g(mid) > 0.0) == pos {
                    lo = mid
                } else {
                    hi = mid
                }
            }
        };
        let v: Vec<f64> = (0..=n).map(|i| g(at(i))).collect();
        for i in 0..n {
            if (v[i] > 0.0) != (v[i + 1] > 0.0) {
                out.push((bisect(at(i), at(i + 1)), part));
            }
            let same =
                i > 0 && (v[i - 1] > 0.0) == (v[i] > 0.0) && (v[i] > 0.0) == (v[i + 1] > 0.0);
            if same && v[i].abs() <= v[i - 1].abs() && v[i].abs() <= v[i + 1].abs() {
                let (mut lo, mut hi, s) = (at(i - 1), at(i + 1), v[i].signum());
                for _ in 0..200 {
                    let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                    if s * g(m1) < s * g(m2) {
                        hi = m2
                    } else {
                        lo = m1
                    }
                }
                let tm = 0.5 * (lo + hi);
                if (g(tm) > 0.0) != (v[i] > 0.0) {
                    out.push((bisect(at(i - 1), tm), part));
                    out.push((bisect(tm, at(i + 1)), part));
                }
            }
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

#[derive(Default, Debug)]
struct Tally {
    rays: usize,
    matched: usize,
    optional: usize,
    excused: usize,
    normals: usize,
    first: usize,
    parity: usize,
}

#[test]
fn crossings_match_sampled_implicit_functions() {
    let mut rng = Rng::new(0x5eed_c0de);
    let mut tally = Tally::default();
    const N: usize = 256;
    for s in solids(&mut rng) {
        let (hi, (parts, closed)) = (s.bounds().1, parts(&s));
        let sz = hi.max_element();
        for _ in 0..1000 {
            let (o, d) = ray(&mut rng, &s);
            let Some(span) = extent(o, d, 3.0 * hi) else {
                continue;
            };
            let (tmin, tmax) = match rng.below(3) {
                0 | 1 => (f64::NEG_INFINITY, f64::INFINITY),
                _ => {
                    let a = span.0 + (span.1 - span.0) * rng.f();
                    (a, a + (span.1 - a) * rng.f())
                }
            };
            let tol_t = 1e-9 * (span.1 - span.0);
            let near = |t: f64| (t - tmin).abs() <= tol_t || (t - tmax).abs() <= tol_t;
            let mut buf = [super::NO_CROSSING; 4];
            let n = s.crossings(o, d, tmin, tmax, &mut buf);
            let got = &buf[..n];
            tally.rays += 1;
            let mut used = [false; 4];
            let mut clean = true;
            let mut refs = Vec::new();
            for (t, part) in reference(&parts, o, d, span, N) {
                let p = o + t * d;
                let out_by = part.outside(p);
                if !(tmin - tol_t < t && t < tmax + tol_t) || out_by > 1e-7 * sz {
                    continue;
                }
                let optional = out_by > -1e-7 * sz || near(t);
                let hit = (0..got.len())
                    .filter(|&i| !used[i] && (got[i].t - t).abs() <= tol_t)
                    .min_by(|&i, &j| (got[i].t - t).abs().total_cmp(&(got[j].t - t).abs()));
                match hit {
                    Some(i) => {
                        used[i] = true;
                        tally.matched += 1;
                        let n = part.normal(p);
                        // At a rim or edge either part's normal may come; the apex has none.
                        let apex = (p - DVec3::Y * hi.y).length() < 1e-6 * sz;
                        let apex = apex && matches!(part, Part::Mantle(..));
                        if !optional && !apex {
                            let err = (got[i].normal - n).length();
                            assert!(
                                err < 1e-9,
                                "{s:?} o {o} d {d}: normal {} vs {n}",
                                got[i].normal
                            );
                            tally.normals += 1;
                        }
                    }
                    None => assert!(
                        optional,
                        "{s:?} o {o} d {d} ({tmin}, {tmax}): missed {t} on {part:?}; got {got:?}"
                    ),
                }
                clean &= !optional;
                tally.optional += optional as usize;
                refs.push((t, part.normal(p)));
            }
            // Unmatched crossings: at a rim/edge/apex, at tmin/tmax, or a near-tangent pair
            // closer than the sampling step.
            let step = 2.0 * (span.1 - span.0) / N as f64;
            for (i, c) in got.iter().enumerate().filter(|&(i, _)| !used[i]) {
                let pair = got
                    .iter()
                    .enumerate()
                    .any(|(j, e)| j != i && !used[j] && (e.t - c.t).abs() < step);
                let ok = edge_distance(&s, o + c.t * d) < 1e-7 * sz || near(c.t) || pair;
                assert!(
                    ok,
                    "{s:?} o {o} d {d} ({tmin}, {tmax}): extra {c:?}; got {got:?}"
                );
                assert!((c.normal.length() - 1.0).abs() < 1e-12);
                tally.excused += 1;
                clean = false;
            }
            if clean {
                // first_crossing and blocks against the reference alone.
                let first = s.first_crossing(o, d, tmin, tmax, false);
                let front = s.first_crossing(o, d, tmin, tmax, true);
                let want_front = refs.iter().find(|r| d.dot(r.1) < 0.0);
                assert_eq!(first.is_some(), !refs.is_empty());
                if let (Some(c), Some(r)) = (first, refs.first()) {
                    assert!((c.t - r.0).abs() <= tol_t);
                }
                assert_eq!(front.is_some(), want_front.is_some(), "{s:?} o {o} d {d}");
                if let (Some(c), Some(r)) = (front, want_front) {
                    assert!((c.t - r.0).abs() <= tol_t && d.dot(c.normal) < 0.0);
                }
                assert_eq!(s.blocks(o, d, tmin, tmax), !refs.is_empty());
                tally.first += 1;
            }
            if closed {
                // Over the whole line: entry, exit, never one without the other.
                let mut out = [super::NO_CROSSING; 4];
                let n = s.crossings(o, d, f64::NEG_INFINITY, f64::INFINITY, &mut out);
                assert!(n % 2 == 0, "{s:?} o {o} d {d}: {:?}", &out[..n]);
                for (i, c) in out[..n].iter().enumerate() {
                    let cos = d.normalize().dot(c.normal);
                    assert!(
                        cos.abs() < 1e-6 || (cos < 0.0) == (i % 2 == 0),
                        "{s:?} o {o} d {d}: {:?}",
                        &out[..n]
                    );
                }
                tally.parity += 1;
            }
        }
    }
    println!("crossings: {tally:?}");
    assert!(tally.matched > 20_000 && tally.first > 40_000 && tally.parity > 10_000);
}

#[test]
fn degenerate_and_non_finite_input_gives_nothing() {
    let (nan, inf) = (f64::NAN, f64::INFINITY);
    let (o, d) = (DVec3::new(0.1, -3.0, 0.2), DVec3::Y);
    let (t3, t2) = ([true; 3], [true; 2]);
    let bad = [
        Solid::Cuboid {
            half: DVec3::new(1.0, 0.0, 1.0),
        },
        Solid::Cuboid {
            half: DVec3::splat(nan),
        },
        cyl(0.0, 1.0, t3),
        cyl(1.0, 0.0, t3),
        cyl(-1.0, 1.0, t3),
        cone(1.0, 0.0, t2),
        cone(0.0, 1.0, t2),
        cone(inf, 1.0, t2),
        cone(1e-300, 1e300, t2),
    ];
    let mut out = [super::NO_CROSSING; 4];
    for s in bad {
        assert_eq!(s.crossings(o, d, -inf, inf, &mut out), 0, "{s:?}");
    }
    let s = cone(1.0, 1.0, t2);
    for (o, d, a, b) in [
        (o, DVec3::ZERO, -inf, inf),
        (o, DVec3::splat(nan), -inf, inf),
        (DVec3::splat(inf), d, -inf, inf),
        (o, d, nan, nan),
    ] {
        assert_eq!(s.crossings(o, d, a, b, &mut out), 0);
        assert!(triangle_hit(&[DVec3::ZERO, DVec3::X, DVec3::Z], o, d, a, b).is_none());
    }
    assert_eq!(s.crossings(o, d, -inf, inf, &mut out), 2);
}

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

/// A shadow caster owned by the test.
#[derive(Clone, Copy, Debug)]
enum Caster {
    S(Solid),
    T([DVec3; 3]),
}

impl Caster {
    fn shape(&self) -> Shape<'_> {
        match self {
            Caster::S(s) => Shape::Solid(s),
            Caster::T(p) => Shape::Triangle(p),
        }
    }
    fn hi(&self) -> DVec3 {
        match self {
            Caster::S(s) => s.bounds().1,
            Caster::T(p) => p[0].abs().max(p[1].abs()).max(p[2].abs()),
        }
    }
    fn kind(&self) -> usize {
        match self {
            Caster::S(Solid::Cuboid { .. }) => 0,
            Caster::S(Solid::Cylinder { .. }) => 1,
            Caster::S(Solid::Cone { .. }) => 2,
            Caster::T(_) => 3,
        }
    }
}

const KINDS: [&str; 4] = ["cuboid", "cylinder", "cone", "triangle"];

fn casters(rng: &mut Rng) -> Vec<Caster> {
    let mut v = Vec::new();
    for scale in [1e-3, 1.0, 1e3] {
        let mut len = || scale * rng.log10(-0.5, 0.5);
        v.push(Caster::S(Solid::Cuboid {
            half: DVec3::new(len(), len(), len()),
        }));
        for parts in [
            [true; 3],
            [false, true, false],
            [true, false, false],
            [false, true, true],
        ] {
            v.push(Caster::S(cyl(len(), len(), parts)));
        }
        for parts in [[true; 2], [true, false], [false, true]] {
            v.push(Caster::S(cone(len(), len(), parts)));
        }
        v.push(Caster::T([(); 3].map(|_| cube(rng) * scale)));
    }
    v
}

/// A light: random, along an axis (the cylinder seen end-on), or (point lights) inside the
/// infinite cylinder or cone.
fn light(rng: &mut Rng, c: &Caster, directional: bool) -> ShadowLight {
    let hi = c.hi();
    let special = rng.below(4) == 0;
    if directional {
        let w = if special {
            DVec3::AXES[rng.below(3)] * rng.log10(-1.0, 1.0)
        } else {
            dir(rng)
        };
        return ShadowLight::Directional { to_light: w };
    }
    let mut p = cube(rng) * 4.0 * hi;
    if special {
        (p.x, p.z) = (rng.range(-0.7, 0.7) * hi.x, rng.range(-0.7, 0.7) * hi.z);
    }
    ShadowLight::Point { position: p }
}

/// A point on a silhouette curve of the curved side (where the normal is across the light
/// ray), found by scanning the angle and bisecting, or `None`.
fn silhouette(rng: &mut Rng, c: &Caster, light: &ShadowLight) -> Option<DVec3> {
    let hi = c.hi();
    let (r, h, f) = (hi.x, hi.y, rng.f());
    // Point and (unnormalised) normal at angle phi, at height fraction f.
    let at = |phi: f64| {
        let (sn, cs) = phi.sin_cos();
        match c {
            Caster::S(Solid::Cylinder { .. }) => Some((
                DVec3::new(r * cs, h * (2.0 * f - 1.0), r * sn),
                DVec3::new(cs, 0.0, sn),
            )),
            Caster::S(Solid::Cone { .. }) => Some((
                DVec3::new(r * f * cs, h - 2.0 * h * f, r * f * sn),
                DVec3::new(cs, r / (2.0 * h), sn),
            )),
            _ => None,
        }
    };
    let across = |phi: f64| {
        let (p, n) = at(phi).unwrap();
        n.dot(match *light {
            ShadowLight::Directional { to_light } => to_light,
            ShadowLight::Point { position } => position - p,
        }) > 0.0
    };
    at(0.0)?;
    let k0 = rng.below(64);
    for k in (0..64).map(|k| (k + k0) % 64) {
        let (mut lo, mut hi) = (TAU * k as f64 / 64.0, TAU * (k + 1) as f64 / 64.0);
        if across(lo) != across(hi) {
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if across(mid) == across(lo) {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            return at(lo).map(|a| a.0);
        }
    }
    None
}

/// A camera ray: anywhere, or through the shadow of a rim/edge/vertex, silhouette or surface
/// point; sometimes parallel to coordinate planes. With its span in a box around the caster.
fn camera(rng: &mut Rng, c: &Caster, light: &ShadowLight) -> Option<(DVec3, DVec3, (f64, f64))> {
    let hi = c.hi();
    let b = match (c, rng.below(4)) {
        (_, 0) => None,
        (Caster::S(s), 1) => Some(boundary_point(rng, s)),
        (Caster::S(s), 2) => silhouette(rng, c, light).or_else(|| Some(surface_point(rng, s))),
        (Caster::S(s), _) => Some(surface_point(rng, s)),
        (Caster::T(p), k) => Some(match k {
            1 => p[0] + rng.f() * (p[1] - p[0]),
            2 => p[rng.below(3)],
            _ => p[0] + rng.f() * (p[1] - p[0]) + rng.f() * (p[2] - p[1]),
        }),
    };
    let q = match (b, *light) {
        (None, _) => cube(rng) * 3.0 * hi,
        (Some(b), ShadowLight::Directional { to_light: w }) => {
            b - w * (rng.range(0.0, 2.0) * hi.length() / w.length())
        }
        (Some(b), ShadowLight::Point { position: l }) => l + (b - l) * rng.range(1.0, 2.0),
    };
    let mut d = dir(rng);
    // (Not for aimed rays: one through a silhouette point's shadow, parallel to an axis, may
    // lie in a tangent plane, on the shadow boundary all along.)
    if b.is_none() && rng.below(2) == 0 {
        d[rng.below(3)] = 0.0;
    }
    let span = extent(q, d, 4.0 * hi)?;
    Some((q, d, span))
}

/// Samples `shadowed` at `n` points of the span; returns (transitions, transitions with no
/// candidate in between).
fn check_breaks(
    c: &Caster,
    light: &ShadowLight,
    o: DVec3,
    d: DVec3,
    span: (f64, f64),
    classes: u8,
    n: usize,
) -> (usize, usize) {
    let shape = c.shape();
    let mut cand = Vec::new();
    breaks(&shape, o, d, light, span, classes, &mut cand);
    assert!(cand.iter().all(|&t| span.0 < t && t < span.1));
    cand.sort_by(f64::total_cmp);
    let tol = 1e-9 * (span.1 - span.0);
    let at = |i: usize| span.0 + (span.1 - span.0) * (i as f64 + 0.5) / n as f64;
    let (mut transitions, mut misses) = (0, 0);
    let mut prev = shadowed(&shape, o + at(0) * d, light);
    for i in 1..n {
        let now = shadowed(&shape, o + at(i) * d, light);
        if now != prev {
            transitions += 1;
            let k = cand.partition_point(|&t| t < at(i - 1) - tol);
            if !(k < cand.len() && cand[k] <= at(i) + tol) {
                misses += 1;
            }
        }
        prev = now;
    }
    (transitions, misses)
}

#[test]
fn shadow_breaks_bracket_every_transition() {
    let mut rng = Rng::new(0x5ad0);
    let mut counts = [[0usize; 2]; 4];
    for c in casters(&mut rng) {
        for directional in [true, false] {
            for _ in 0..150 {
                let l = light(&mut rng, &c, directional);
                let Some((o, d, span)) = camera(&mut rng, &c, &l) else {
                    continue;
                };
                let (n, miss) = check_breaks(&c, &l, o, d, span, ALL, 20_000);
                assert_eq!(miss, 0, "{c:?} {l:?} o {o} d {d} {span:?}");
                counts[c.kind()][directional as usize] += n;
            }
        }
    }
    for (k, [point, directional]) in counts.iter().enumerate() {
        println!(
            "shadow breaks, {}: {directional} transitions (directional), {point} (point)",
            KINDS[k]
        );
        assert!(*point > 400 && *directional > 400);
    }
}

#[test]
fn shadow_breaks_check_can_fail() {
    // Leaving out one class of candidates must miss transitions: each class is needed, and
    // the sampling test above would notice a missing candidate.
    let mut rng = Rng::new(0xfa11);
    let mut misses = [[[0usize; 3]; 2]; 4];
    for c in casters(&mut rng) {
        for directional in [true, false] {
            for _ in 0..40 {
                let l = light(&mut rng, &c, directional);
                let Some((o, d, span)) = camera(&mut rng, &c, &l) else {
                    continue;
                };
                for (i, class) in [SURFACE, TANGENT, BOUNDARY].into_iter().enumerate() {
                    misses[c.kind()][directional as usize][i] +=
                        check_breaks(&c, &l, o, d, span, ALL & !class, 2000).1;
                }
            }
        }
    }
    println!(
        "misses without [surface, tangent, boundary] candidates, [point, directional]: {misses:?}"
    );
    for (k, m) in misses.iter().enumerate() {
        for by_light in m {
            let curved = k == 1 || k == 2;
            assert!(
                by_light[0] > 0 && by_light[2] > 0 && (by_light[1] > 0) == curved,
                "{}: {m:?}",
                KINDS[k]
            );
        }
    }
}

#[test]
fn shadow_breaks_in_degenerate_views() {
    // A cylinder seen end-on: no tangent planes; its shadow is bounded by the infinite
    // cylinder and the cap planes (class SURFACE alone suffices; the rims alone do not, as
    // they miss the cap planes). A point light inside the infinite cylinder: no tangents.
    let mut rng = Rng::new(0xe0d);
    let s = Caster::S(cyl(0.7, 0.4, [true; 3]));
    let (mut n, mut rims_only) = (0, 0);
    for i in 0..300 {
        let (x, y, z) = (
            rng.range(-0.4, 0.4),
            rng.range(-3.0, 3.0),
            rng.range(-0.4, 0.4),
        );
        let l = match i % 4 {
            0 => ShadowLight::Directional {
                to_light: DVec3::Y * 2.0,
            },
            2 => ShadowLight::Directional {
                to_light: DVec3::Y * -0.5,
            },
            _ => ShadowLight::Point {
                position: DVec3::new(x, y, z),
            },
        };
        let Some((o, d, span)) = camera(&mut rng, &s, &l) else {
            continue;
        };
        let classes = [SURFACE, SURFACE | BOUNDARY][i % 2];
        let (t, miss) = check_breaks(&s, &l, o, d, span, classes, 5000);
        assert_eq!(miss, 0, "{l:?} o {o} d {d}");
        n += t;
        if i % 2 == 0 {
            rims_only += check_breaks(&s, &l, o, d, span, BOUNDARY, 5000).1;
        }
    }
    println!("degenerate views: {n} transitions; {rims_only} missed by rims alone");
    assert!(n > 300 && rims_only > 0);
}
