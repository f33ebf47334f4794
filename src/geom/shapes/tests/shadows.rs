//! Shadow breaks against `shadowed` sampled on a dense grid.

use super::*;

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
