//! The f64 geometry against independent answers: an exact big-integer oracle (`exact.rs`)
//! for spheres, brute-force root finding and finite differences for ellipsoids, sampling for
//! chords. Deterministic pseudo-random inputs (SplitMix64), swept over scales.

mod exact;

use exact::{bracket_error, bracket_ulps, Exact};
use glam::{DAffine3, DMat3, DQuat, DVec3};

use crate::geom::sphere::segment_chord;
use crate::geom::{ellipsoid_normal, ellipsoid_roots, enters_between, sphere_roots};
use crate::testing::Rng;

mod ellipsoids_and_chords;
mod sphere_through;

/// Unit roundoff, 2^-53.
const U: f64 = f64::EPSILON / 2.0;

impl Rng {
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.range(lo.ln(), hi.ln()).exp()
    }
    fn sign(&mut self) -> f64 {
        if self.u64() & 1 == 0 {
            1.0
        } else {
            -1.0
        }
    }
    /// Uniform random unit vector (rejection from the cube).
    fn dir(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l2 = v.length_squared();
            if l2 > 1e-4 && l2 <= 1.0 {
                return v / l2.sqrt();
            }
        }
    }
    /// Random unit vector perpendicular to the unit vector `u`.
    fn perp(&mut self, u: DVec3) -> DVec3 {
        loop {
            let v = self.dir();
            let p = v - v.dot(u) * u;
            if p.length() > 0.1 {
                return p.normalize();
            }
        }
    }
}

/// The textbook quadratic, `b^2 - 4ac` in f64: what the tests must be able to tell apart.
fn naive_roots(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    let f = o - c;
    let (a, b, cc) = (d.dot(d), 2.0 * f.dot(d), f.dot(f) - r * r);
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some(((-b - s) / (2.0 * a), (-b + s) / (2.0 * a)))
}

/// The Haines et al. discriminant in plain f64 (rounded `o - c`, no fused multiply-add, no
/// refinement): good, but not good enough at 1e-10 of tangency, which is why `geom` does more.
fn plain_haines_hits(o: DVec3, d: DVec3, c: DVec3, r: f64) -> bool {
    let f = o - c;
    let v = f - (f.dot(d) / d.dot(d)) * d;
    r * r - v.dot(v) >= 0.0
}

/// A ray from a camera `o` (coordinates up to 1e3, so `o - c` rounds) to a sphere whose centre
/// is `dist` away, aimed `rho` to the side of the centre; `d` unit or of length ~`dist`. The
/// radius is then set from the oracle's distance of the centre to the actual f64 line, so that
/// the exact margin `(r - distance) / r` is `mu` within a few eps (absolute).
fn grazing_ray(rng: &mut Rng, dist: f64, rho: f64, mu: f64) -> (DVec3, DVec3, DVec3, f64) {
    let o = DVec3::new(
        rng.range(-1e3, 1e3),
        rng.range(-1e3, 1e3),
        rng.range(-1e3, 1e3),
    );
    let u = rng.dir();
    let c = o + dist * u;
    let mut d = c + rho * rng.perp(u) - o;
    if rng.u64() & 1 == 0 {
        d = d.normalize();
    }
    let line_distance = Exact::new(o, d, c, 1.0).distance();
    (o, d, c, line_distance / (1.0 - mu))
}

struct Band {
    lo: f64,
    hi: f64,
    rays: usize,
    wrong: usize,
    naive_wrong: usize,
    plain_wrong: usize,
    max_root_ulps: i64,
}

/// Rays within 1e-9 of tangency to a sphere of radius 1e-3 at distance 1e4
/// from the camera must hit or miss as the exact answer says, with no NaN; here also the
/// decades below. Returns one row per band of |margin|, [1e-(k+1), 1e-k] for k in `ks`.
fn grazing_bands(ks: std::ops::RangeInclusive<i32>) -> Vec<Band> {
    let mut rng = Rng(0x5eed_0001);
    let mut bands = Vec::new();
    for k in ks {
        let (lo, hi) = (10f64.powi(-k - 1), 10f64.powi(-k));
        let mut band = Band {
            lo,
            hi,
            rays: 0,
            wrong: 0,
            naive_wrong: 0,
            plain_wrong: 0,
            max_root_ulps: 0,
        };
        for i in 0..600 {
            let mu = rng.log_uniform(lo, hi) * if i % 2 == 0 { 1.0 } else { -1.0 };
            let (o, d, c, r) = grazing_ray(&mut rng, 1e4, 1e-3, mu);
            let exact = Exact::new(o, d, c, r);
            let m = exact.margin();
            // The construction puts m within a few u of mu (absolute); the truth is exact.
            assert!((m - mu).abs() <= 8.0 * U, "margin {m} for {mu}");
            band.rays += 1;
            let got = sphere_roots(o, d, c, r);
            if let Some((t0, t1)) = got {
                assert!(!t0.is_nan() && !t1.is_nan() && t0 <= t1);
            }
            band.wrong += usize::from(got.is_some() != exact.hits());
            band.naive_wrong += usize::from(naive_roots(o, d, c, r).is_some() != exact.hits());
            band.plain_wrong += usize::from(plain_haines_hits(o, d, c, r) != exact.hits());
            if let (Some((t0, t1)), Some([b0, b1])) = (got, exact.roots()) {
                let ulps = bracket_ulps(t0, b0).max(bracket_ulps(t1, b1));
                band.max_root_ulps = band.max_root_ulps.max(ulps);
            }
        }
        bands.push(band);
    }
    for b in &bands {
        eprintln!(
            "|margin| in [{:.0e}, {:.0e}]: {} rays, wrong: geom {}, naive {}, plain Haines {}; \
             roots within {} ulps of exact",
            b.lo, b.hi, b.rays, b.wrong, b.naive_wrong, b.plain_wrong, b.max_root_ulps
        );
    }
    bands
}

#[test]
fn grazing_rays_at_tiny_far_sphere_agree_with_exact_hit_or_miss() {
    // Asserted down to 1e-15 of tangency; below that (|v| = r (1 +- ~4 eps)) f64 may disagree.
    for b in grazing_bands(9..=15).iter().filter(|b| b.lo >= 1e-15) {
        assert_eq!(b.wrong, 0, "band [{:e}, {:e}]", b.lo, b.hi);
        assert!(b.max_root_ulps <= 8, "band [{:e}, {:e}]", b.lo, b.hi);
    }
}

#[test]
fn naive_quadratic_fails_the_grazing_test() {
    // The test has teeth: b^2 - 4ac is noise at 1e-10 of tangency (b^2/4 ~ 1e8 |d|^2 rounds
    // by ~1e-8 |d|^2, the signal a r^2 2e-10 is ~2e-16 |d|^2), so it gets about half of them
    // wrong (282 of 600). Even the Haines et al. discriminant in plain f64 gets 87 wrong:
    // rounding o - c and (f.d / d.d) d moves the line by ~eps 1e4 ~ 1e-12, i.e. 1e-9 r.
    let b = &grazing_bands(9..=9)[0];
    assert!(b.naive_wrong * 4 > b.rays, "naive: {}", b.naive_wrong);
    assert!(
        b.plain_wrong * 20 > b.rays,
        "plain Haines: {}",
        b.plain_wrong
    );
}

/// Scale of the tolerance on a root, in units of t: the root itself (for a few ulps), plus
/// `r^2 / (|d| h)` (`h` the world half chord): a near-tangent root moves by eps times this
/// when the closest-approach distance moves by one ulp.
fn root_scale(t: f64, e: &Exact, r: f64) -> f64 {
    t.abs() + r * r / (e.d_len() * e.half_chord())
}

#[derive(Default)]
struct SweepStats {
    cases: usize,
    hits: usize,
    undecided: usize,
    max_root_err: f64,
    max_surface_err: f64,
}

impl SweepStats {
    /// Checks one line against the oracle; `undecided` counts exact margins too close to 0 for
    /// f64 to be required to agree: |margin| <= 1e-14 + 8 u^2 |o - c| / r, the second term
    /// being the rounding of the closest-point offset (~u^2 |o - c|), which matters only for
    /// |o - c| / r past ~1e15.
    fn check(&mut self, o: DVec3, d: DVec3, c: DVec3, r: f64) {
        let got = sphere_roots(o, d, c, r);
        let e = Exact::new(o, d, c, r);
        self.cases += 1;
        if let Some((t0, t1)) = got {
            assert!(!t0.is_nan() && !t1.is_nan() && t0 <= t1, "{o} {d} {c} {r}");
        }
        if e.margin().abs() <= 1e-14 + 8.0 * U * U * (o - c).length() / r {
            self.undecided += 1;
        } else {
            assert_eq!(
                got.is_some(),
                e.hits(),
                "o {o:?} d {d:?} c {c:?} r {r:e} margin {:e}",
                e.margin()
            );
        }
        if let (Some((t0, t1)), Some(brackets)) = (got, e.roots()) {
            self.hits += 1;
            for (t, b) in [(t0, brackets[0]), (t1, brackets[1])] {
                let err = bracket_error(t, b) / (U * root_scale(b.0, &e, r));
                self.max_root_err = self.max_root_err.max(err);
                // The point at the root lies on the sphere as closely as an f64 t allows.
                let off = e.surface_offset(t).abs() / (U * (r + t.abs() * e.d_len()));
                self.max_surface_err = self.max_surface_err.max(off);
            }
        }
    }
}

#[test]
fn roots_match_exact_oracle_across_scales() {
    // pbrt-v4 shapes_test style: radii 1e-4..1e4, centres up to 1e6 from the ray origin, ray
    // directions of any length and sign, origins outside, inside and near the surface; a third
    // of the lines are made near-tangent (margin 2e-14..1e-6) by setting r from the oracle.
    let mut rng = Rng(0x5eed_0002);
    let mut s = SweepStats::default();
    for i in 0..6000 {
        let mut r = rng.log_uniform(1e-4, 1e4);
        let o = rng.dir() * rng.log_uniform(1e-3, 1e6);
        let c = o + rng.dir() * rng.log_uniform(1e-3 * r, 1e6);
        let u = (c - o).normalize_or(DVec3::X);
        let aim = c + rng.perp(u) * r * rng.range(0.0, 1.3);
        let d = (aim - o) * rng.log_uniform(1e-3, 1e3) * rng.sign();
        if d == DVec3::ZERO {
            continue;
        }
        if i % 3 == 0 {
            let mu = rng.log_uniform(2e-14, 1e-6) * rng.sign();
            r = Exact::new(o, d, c, 1.0).distance() / (1.0 - mu);
        }
        s.check(o, d, c, r);
    }
    eprintln!(
        "{} lines, {} hits, {} within 1e-14 of tangency; root error <= {:.2} u * (|t| + r^2/(|d| h)), \
         surface offset <= {:.2} u * (r + |t d|)",
        s.cases, s.hits, s.undecided, s.max_root_err, s.max_surface_err
    );
    assert!(s.hits > 1500 && s.undecided < 10);
    assert!(s.max_root_err <= 8.0, "{}", s.max_root_err);
    assert!(s.max_surface_err <= 8.0, "{}", s.max_surface_err);
}

#[test]
fn special_origins_and_extreme_directions() {
    let mut rng = Rng(0x5eed_0003);
    let mut s = SweepStats::default();
    for _ in 0..500 {
        let r = rng.log_uniform(1e-4, 1e4);
        let c = rng.dir() * rng.log_uniform(1e-3, 1e6);
        // Directions from 1e-300 to 1e300 long: roots scale inversely, nothing overflows.
        let d = rng.dir() * rng.log_uniform(1e-300, 1e300);
        // Origin at the centre: roots -+ r / |d|.
        s.check(c, d, c, r);
        // Origin exactly on the sphere ((2, 3, 6) has length 7; r is a multiple of 7 times a
        // power of two so the sum is exact): one root is exactly 0.
        let r7 = 7.0 * 2f64.powi(rng.range(-14.0, 14.0) as i32);
        let c = DVec3::new(0.5, -1.5, 2.25) * 2f64.powi(rng.range(-10.0, 10.0) as i32);
        let o = c + DVec3::new(2.0, 3.0, 6.0) * (r7 / 7.0);
        assert_eq!(Exact::new(o, d, c, r7).g(0.0).sign(), 0);
        let (t0, t1) = sphere_roots(o, d, c, r7).unwrap();
        assert!(t0 == 0.0 || t1 == 0.0, "{t0} {t1}");
        s.check(o, d, c, r7);
        // Tangent at the origin.
        let d = rng.perp(DVec3::new(2.0, 3.0, 6.0) / 7.0);
        s.check(o, d, c, r7);
    }
    assert!(s.max_root_err <= 8.0, "{}", s.max_root_err);
}

#[test]
fn near_root_keeps_relative_precision_for_origins_near_the_surface() {
    // Shadow and secondary rays start on a surface: the root near t = 0 must have the right
    // sign and full relative precision, not an absolute error of eps r / |d| (which is what
    // |o - c|^2 - r^2 without compensated summation would give: relative 1e-6 at 1e-10).
    let mut rng = Rng(0x5eed_0007);
    let mut worst = 0f64;
    for _ in 0..3000 {
        let r = rng.log_uniform(1e-4, 1e4);
        let c = rng.dir() * rng.log_uniform(1e-3, 1e4);
        let n = rng.dir();
        let o = c + n * r * (1.0 + rng.sign() * rng.log_uniform(1e-15, 1e-6));
        // Leaving or entering at an angle of at least ~17 degrees to the tangent plane.
        let mut d = rng.dir();
        if d.dot(n).abs() < 0.3 {
            d = (d + n * 0.5 * rng.sign()).normalize();
            if d.dot(n).abs() < 0.3 {
                continue;
            }
        }
        let d = d * rng.log_uniform(1e-3, 1e3);
        let e = Exact::new(o, d, c, r);
        let ([b0, b1], Some((t0, t1))) = (e.roots().expect("hit"), sphere_roots(o, d, c, r)) else {
            panic!("miss: {o} {d} {c} {r}");
        };
        let (t, b) = if b0.0.abs() < b1.0.abs() {
            (t0, b0)
        } else {
            (t1, b1)
        };
        assert!(
            t == 0.0 || b.0.signum() == t.signum() || b.0 == 0.0,
            "{t} {b:?}"
        );
        worst = worst.max(bracket_error(t, b) / (U * b.0.abs().max(b.1.abs())));
    }
    eprintln!("root nearest the origin within {worst:.2} u (relative)");
    assert!(worst <= 10.0, "{worst}");
}

#[test]
fn no_nan_for_any_finite_input() {
    /// Zero, +-f64::MAX, subnormals, or any magnitude 10^-e..10^e.
    fn any(rng: &mut Rng, e: f64) -> f64 {
        match rng.u64() % 8 {
            0 => 0.0,
            1 if e > 300.0 => f64::MAX * rng.sign(),
            2 if e > 300.0 => f64::from_bits(rng.u64() % (1 << 52)) * rng.sign(),
            _ => rng.log_uniform(10f64.powf(-e), 10f64.powf(e)) * rng.sign(),
        }
    }
    let mut rng = Rng(0x5eed_0004);
    // Up to 1e140 every input is scaled exactly, so the answers are also held to the oracle;
    // beyond, only to "no NaN, t0 <= t1, chord >= 0".
    for (e, cases) in [(308.0, 20_000), (140.0, 4000)] {
        let mut s = SweepStats::default();
        for _ in 0..cases {
            let mut v = || DVec3::new(any(&mut rng, e), any(&mut rng, e), any(&mut rng, e));
            let (o, d, c) = (v(), v(), v());
            let r = any(&mut rng, e).abs();
            // Half of the lines aimed at the centre, so that some hit.
            let d = if rng.u64() & 1 == 0 {
                (c - o) * rng.log_uniform(10f64.powf(-e), 10f64.powf(e))
            } else {
                d
            };
            if !d.is_finite() {
                continue;
            }
            if d == DVec3::ZERO {
                assert_eq!(sphere_roots(o, d, c, r), None);
            } else if e < 300.0 {
                s.check(o, d, c, r);
            } else if let Some((t0, t1)) = sphere_roots(o, d, c, r) {
                s.hits += 1;
                assert!(!t0.is_nan() && !t1.is_nan() && t0 <= t1, "{o} {d} {c} {r}");
            }
            let chord = segment_chord(o, d, c, r, f64::NEG_INFINITY, f64::INFINITY);
            assert!(chord >= 0.0, "{o} {d} {c} {r}");
        }
        eprintln!(
            "magnitudes to 1e{e}: {} hits, {} undecided; root error <= {:.2}, surface offset <= {:.2}",
            s.hits, s.undecided, s.max_root_err, s.max_surface_err
        );
        assert!(s.hits > cases / 20, "{}", s.hits);
        assert!(s.max_root_err <= 8.0 && s.max_surface_err <= 8.0);
    }
}
