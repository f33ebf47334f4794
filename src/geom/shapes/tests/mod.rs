//! Tests against independent references: each part's implicit function sampled densely along
//! the ray with bisection (crossings), Cramer's rule (triangles), and `shadowed` sampled on a
//! dense grid (shadow breaks). Counts go to stdout (`--nocapture`).

mod shadows;
mod triangles;

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
