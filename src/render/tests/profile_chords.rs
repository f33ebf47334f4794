//! The closed-form optical depth of radial density profiles (`render::profile`, docs/model.md
//! section 6) against answers computed here independently: adaptive Gauss-Kronrod quadrature
//! of `f(|x - c| / r)` along the ray, closed values at `beta = 0`, the midpoint rule on tiny
//! pieces, `2 I_f` on the diameter.
//!
//! Two references:
//! - `along_ray`: the profile's own `f` at `|o + t w - c| / r`, integrated over `t` with
//!   breakpoints at the chord ends and the closest approach (the linear profile's kink). Its
//!   integrand is off by a few eps (|o - c| + |t|) / r in `u`, so it serves for lines with
//!   `beta <= 0.99`.
//! - `reference`: in the dimensionless chord variables, integrated in the distance
//!   `a = h - |v|` from the nearer chord end, with `g = 1 - u^2 = a (2h - a)` formed exactly
//!   (fused products and a compensated sum), the gaussian in `v` kept as a double-double:
//!   well conditioned however grazing the line and however close to the end the piece, so
//!   the closed form is held to rounding there too.
//!
//! The dimensionless comparisons hold the closed form to 2e-14 relative (it measures ~3e-15 at
//! worst; docs/model.md asks for exact to rounding), the world-ray one to 1e-12 (it measures
//! ~4e-13, the rounding of the ray's own geometry). The worst relative errors are printed
//! (`cargo test -p gtsphere --lib profile_chords -- --nocapture`).

use crate::render::profile::{sigma0, Profile};
use crate::scene::{ProfileError, DEFAULT_WIDTH};
use glam::DVec3;

use crate::testing::Rng;

mod special_chords;

/// The dimensionless comparisons' relative tolerance.
const TOL: f64 = 2e-14;

const PROFILES: [Profile; 6] = [
    Profile::Constant,
    Profile::Linear,
    Profile::Quadratic,
    Profile::Gaussian { width: 0.05 },
    Profile::Gaussian { width: 1.0 / 3.0 },
    Profile::Gaussian { width: 1.0 },
];

fn label(p: Profile) -> String {
    match p {
        Profile::Gaussian { width } => format!("gaussian {width:.3}"),
        _ => p.name().to_string(),
    }
}

fn rel(got: f64, want: f64) -> f64 {
    if got == want {
        0.0
    } else {
        ((got - want) / want).abs()
    }
}

// ---- Adaptive Gauss-Kronrod (7-point Gauss, 15-point Kronrod), bisecting until |K - G| of
// every piece is below its share of the tolerance, and summing the Kronrod values.

/// Kronrod abscissae on [0, 1] (descending; the Gauss ones are the odd-indexed and 0), their
/// weights, and the Gauss weights (QUADPACK `qk15`).
const XK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// `(K15, |K15 - G7|, K15 of |f|)` on `[a, b]`.
fn gk15(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64, f64) {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    let fc = f(mid);
    let (mut k, mut g, mut abs) = (WK[7] * fc, WG[3] * fc, WK[7] * fc.abs());
    for j in 0..7 {
        let (f0, f1) = (f(mid - half * XK[j]), f(mid + half * XK[j]));
        k += WK[j] * (f0 + f1);
        abs += WK[j] * (f0.abs() + f1.abs());
        if j % 2 == 1 {
            g += WG[j / 2] * (f0 + f1);
        }
    }
    (k * half, ((k - g) * half).abs(), abs * half)
}

/// The integral of `f` over `[a, b]` to about 1e-14 relative: pieces are bisected until
/// `|K - G|` is below their share of `1e-13 |I|` (K15 is then far more accurate than that),
/// or at the level of the integrand's own error: `noise = (absolute, relative)`, times the
/// piece's length or its `integral |f|` (relative at least `1e3 eps`). Panics on NaN or if
/// that takes more than a million evaluations.
fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64, noise: (f64, f64)) -> f64 {
    struct Run<'a> {
        f: &'a dyn Fn(f64) -> f64,
        noise: (f64, f64),
        calls: u32,
    }
    fn go(run: &mut Run, a: f64, b: f64, tol: f64) -> f64 {
        run.calls += 1;
        assert!(
            run.calls < 70_000,
            "quadrature did not converge on [{a}, {b}]"
        );
        let (k, e, abs) = gk15(run.f, a, b);
        assert!(!k.is_nan(), "NaN integrand on [{a}, {b}]");
        let (absolute, relative) = run.noise;
        let floor = (absolute * (b - a)).max(relative.max(1e3 * f64::EPSILON) * abs);
        if e <= tol.max(floor) {
            return k;
        }
        let m = 0.5 * (a + b);
        go(run, a, m, 0.5 * tol) + go(run, m, b, 0.5 * tol)
    }
    if b <= a {
        return 0.0;
    }
    let (rough, _, _) = gk15(f, a, b);
    let mut run = Run { f, noise, calls: 0 };
    go(&mut run, a, b, 1e-13 * rough.abs())
}

// ---- Reference 1: f along the ray, in world units.

/// `integral_t0^t1 f(|o + t w - c| / r) dt` by quadrature, split at the chord ends and at the
/// closest approach (found here with the plain quadratic formula).
fn along_ray(p: Profile, o: DVec3, w: DVec3, (t0, t1): (f64, f64), c: DVec3, r: f64) -> f64 {
    let tc = (c - o).dot(w);
    let d2 = (o + tc * w - c).length_squared();
    if d2 >= r * r {
        return 0.0;
    }
    let half = (r * r - d2).sqrt();
    let (a, b) = (t0.max(tc - half), t1.min(tc + half));
    if a >= b {
        return 0.0;
    }
    let f = |t: f64| p.f((o + t * w - c).length() / r);
    // u is off by du, a few eps (|o - c| + |t|) / r, so f by |f'| du: absolutely for the
    // linear and quadratic profiles (|f'| <= 2), relatively for the gaussian
    // (|f' / f| = u / s^2). The quadrature refines no further than that.
    let du = 4.0 * f64::EPSILON * ((o - c).length() + a.abs().max(b.abs())) / r;
    let noise = match p {
        Profile::Constant => (0.0, 0.0),
        Profile::Linear | Profile::Quadratic => (2.0 * du, 0.0),
        Profile::Gaussian { width } => (0.0, du / (width * width)),
    };
    if a < tc && tc < b {
        integrate(&f, a, tc, noise) + integrate(&f, tc, b, noise)
    } else {
        integrate(&f, a, b, noise)
    }
}

// ---- Reference 2: dimensionless, in the distance from the chord end.

/// TwoSum: `a + b = s + e` exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// The sum of `x` to about `eps + 1e-48 * cond` relative (Ogita, Rump and Oishi's SumK with
/// K = 3: two error-free passes over the terms, then a plain sum).
fn sum3(mut x: Vec<f64>) -> f64 {
    for _ in 0..2 {
        for i in 1..x.len() {
            let (s, e) = two_sum(x[i], x[i - 1]);
            x[i] = s;
            x[i - 1] = e;
        }
    }
    x.iter().sum()
}

/// `g = 1 - b^2 - v^2` to rounding: the squares are split exactly with fused multiply-adds.
fn one_minus_u2(b: f64, v: f64) -> f64 {
    let (pb, pv) = (b * b, v * v);
    sum3(vec![-b.mul_add(b, -pb), -v.mul_add(v, -pv), -pv, -pb, 1.0])
}

/// The profile's `f` at the point of the line at distance `b` and parameter `v`, where
/// `g = 1 - u^2` is known accurately (written from the table of docs/model.md section 6).
fn shape(p: Profile, b: f64, v: f64, g: f64) -> f64 {
    match p {
        Profile::Constant => 1.0,
        // 1 - u = g / (1 + u).
        Profile::Linear => g / (1.0 + (b * b + v * v).sqrt()),
        Profile::Quadratic => g,
        Profile::Gaussian { width } => gaussian(b, (v, 0.0), width),
    }
}

/// `exp(-(b^2 + v^2) / (2 s^2))` at `v = vh + vl` (`|vl| <= ulp(vh)`), with the exponent `y`
/// good to ~eps absolutely: it reaches 200 for s = 0.05, and exp turns its absolute error
/// into a relative one, so even a node's position must be kept beyond f64 (an ulp of `v` is
/// 3e-14 of `f` there). The squares' rounding errors come from fused multiply-adds, then the
/// quotient is corrected once.
fn gaussian(b: f64, (vh, vl): (f64, f64), s: f64) -> f64 {
    let (pb, pv, ps) = (b * b, vh * vh, 2.0 * s * s);
    let (num, e) = two_sum(pb, pv);
    let num_lo = e + b.mul_add(b, -pb) + vh.mul_add(vh, -pv) + 2.0 * vh * vl;
    let ps_lo = 2.0 * s.mul_add(s, -s * s);
    let y = num / ps;
    let y_lo = ((-y).mul_add(ps, num) + num_lo - y * ps_lo) / ps;
    (-y).exp() * (1.0 - y_lo)
}

/// The half chord `h = sqrt(1 - b^2)`.
fn half_chord(b: f64) -> f64 {
    one_minus_u2(b, 0.0).max(0.0).sqrt()
}

/// `integral_v0^v1 f(sqrt(b^2 + v^2)) dv` over the chord, the ends clipped to the exact chord
/// end. Each half `[p, q]`, `0 <= p < q <= h`, is integrated in `a = h - v`, from the exact
/// `a(q) = g(q) / (h + q)` over the exact length `q - p` (or `a(p)` when `q` is the end), so
/// neither the nodes nor the piece carry the rounding of `h`; the gaussian in `v` itself.
fn reference(p: Profile, b: f64, v0: f64, v1: f64) -> f64 {
    let h = half_chord(b);
    let (lo, hi) = (v0.max(-h), v1.min(h));
    if lo >= hi {
        return 0.0;
    }
    let (lo_end, hi_end) = (v0 <= -h, v1 >= h);
    let halves = if lo >= 0.0 {
        vec![(lo, hi, hi_end)]
    } else if hi <= 0.0 {
        vec![(-hi, -lo, lo_end)]
    } else {
        vec![(0.0, -lo, lo_end), (0.0, hi, hi_end)]
    };
    let to_end = |v: f64| one_minus_u2(b, v).max(0.0) / (h + v);
    halves
        .into_iter()
        .map(|(p0, q, end)| {
            let (a_q, len) = if end {
                (0.0, to_end(p0))
            } else {
                (to_end(q), q - p0)
            };
            // In tau = a - a(q), so that the piece's length is len exactly. The gaussian,
            // which does not vanish at the end but is steep, in v = p0 + tau as a
            // double-double instead.
            let f = |tau: f64| match p {
                Profile::Gaussian { width } => gaussian(b, two_sum(p0, tau), width),
                _ => {
                    let a = a_q + tau;
                    shape(p, b, h - a, a * (2.0 * h - a))
                }
            };
            integrate(&f, 0.0, len, (0.0, 0.0))
        })
        .sum()
}

/// Worst relative error per case, printed at the end of a test.
#[derive(Default)]
struct Worst(Vec<(String, f64, String)>);

impl Worst {
    fn add(&mut self, case: &str, err: f64, what: impl FnOnce() -> String) {
        match self.0.iter_mut().find(|(c, _, _)| c == case) {
            Some(e) if err > e.1 => {
                e.1 = err;
                e.2 = what();
            }
            Some(_) => {}
            None => self.0.push((case.to_string(), err, what())),
        }
    }

    fn check(self, tol: f64) {
        let mut failed = Vec::new();
        for (case, err, what) in &self.0 {
            eprintln!("{case:<34} worst relative error {err:.2e}  ({what})");
            if err.is_nan() || *err > tol {
                failed.push(case.clone());
            }
        }
        assert!(failed.is_empty(), "above {tol:e}: {failed:?}");
    }
}

/// A random unit vector (uniform on the sphere, by rejection from the cube).
fn unit(rng: &mut Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

/// Random rays through spheres of radii 1e-3 to 1e3 anywhere within 10 radii of the origin,
/// `beta` up to 0.99 (and misses), random pieces of and around the chord, against `f` along
/// the ray. (Grazing rays are tested below in the chord's variables: in world coordinates
/// `beta` itself is only known to `eps |o - c| / r`, which `1 - beta` magnifies.)
#[test]
fn random_rays_match_quadrature_of_f_along_the_ray() {
    let mut rng = Rng::new(0x5eed_0001);
    let mut worst = Worst::default();
    for i in 0..1500 {
        let r = rng.log10(-3.0, 3.0);
        let c = r * 10.0 * DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0);
        let w = unit(&mut rng);
        let n = w.any_orthonormal_vector();
        let beta = if i % 10 == 0 {
            rng.range(1.001, 1.5)
        } else {
            rng.range(0.0, 0.99)
        };
        let o = c + beta * r * n - rng.range(1.2, 4.0) * r * w;
        // The chord is about [1.2, 6] r from o; pieces of it and around it.
        let (mut t0, mut t1) = (rng.range(0.0, 7.0) * r, rng.range(0.0, 7.0) * r);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        match i % 7 {
            0 => t1 = f64::INFINITY,
            1 => t0 = f64::NEG_INFINITY,
            _ => {}
        }
        for p in PROFILES {
            let got = p.ray_integral(o, w, t0, t1, c, r);
            let want = along_ray(p, o, w, (t0, t1), c, r);
            if want == 0.0 {
                assert_eq!(got, 0.0, "{} ray {i}: want 0", label(p));
                continue;
            }
            worst.add(&label(p), rel(got, want), || {
                format!("ray {i}: beta {beta:.3}, r {r:.1e}")
            });
        }
    }
    worst.check(1e-12);
}

/// Random chords in the dimensionless variables, by kind of line and piece, against the
/// reference in the distance from the chord end: generic pieces, lines through (or within
/// 1e-300 to 1e-3 of) the centre, grazing lines (`1 - beta` from 1e-15 to 1e-2), pieces
/// ending a fraction 1e-14 to 1 of the half chord before the chord end, and pieces of 1e-9 to
/// 1e-6 of the half chord anywhere.
#[test]
fn random_chords_match_quadrature_in_the_distance_from_the_end() {
    let mut rng = Rng::new(0x5eed_0002);
    let mut worst = Worst::default();
    let kinds = ["generic", "centre", "grazing", "near end", "short"];
    for i in 0..1500 {
        let kind = kinds[i % kinds.len()];
        let b = match kind {
            "centre" => [0.0, 1e-300, 1e-20, 1e-8, 1e-3][rng.below(5)],
            "grazing" => 1.0 - rng.log10(-15.0, -2.0),
            "near end" if rng.f() < 0.5 => 1.0 - rng.log10(-15.0, -1.0),
            _ => rng.f(),
        };
        let h = half_chord(b);
        let (v0, v1) = match kind {
            "near end" => {
                let v0 = h - h * rng.log10(-14.0, 0.0);
                // Up to the end (clipped there) or to a point in between.
                let v1 = if rng.f() < 0.5 {
                    2.0
                } else {
                    v0 + (h - v0) * rng.f()
                };
                if rng.f() < 0.5 {
                    (-v1, -v0)
                } else {
                    (v0, v1)
                }
            }
            "short" => {
                let v0 = rng.range(-h, h);
                (v0, v0 + h * rng.log10(-9.0, -6.0))
            }
            _ => {
                let (x, y) = (rng.range(-1.2, 1.2) * h, rng.range(-1.2, 1.2) * h);
                (x.min(y), x.max(y))
            }
        };
        for p in PROFILES {
            let want = reference(p, b, v0, v1);
            let got = p.line_integral(b, v0, v1);
            if want == 0.0 {
                assert_eq!(got, 0.0, "{} {kind} {i}", label(p));
                continue;
            }
            worst.add(&format!("{} / {kind}", label(p)), rel(got, want), || {
                format!("beta {b:e}, v {v0:e} .. {v1:e}")
            });
        }
    }
    worst.check(TOL);
}
