//! Radial density profiles of gas spheres (docs/model.md section 6) and their optical depth along
//! a ray in closed form.
//!
//! A profiled gas sphere of centre `c` and radius `r` has extinction `sigma0 f(u)`,
//! `u = |x - c| / r`, inside and 0 outside ([`Profile::f`]); [`sigma0`] keeps `transparency`
//! the transmittance along a full diameter. Along a ray `x(t) = o + t w` (`|w| = 1`) whose
//! closest approach to `c` is at `t_c`, with `beta = |x(t_c) - c| / r` and `v = (t - t_c) / r`,
//! `u^2 = beta^2 + v^2` and the optical depth of `[t0, t1]` is
//! `tau = sigma0 r J(beta, v0, v1)`, `J = integral_v0^v1 f(sqrt(beta^2 + v^2)) dv`
//! ([`Profile::line_integral`]; [`Profile::ray_integral`] takes the ray itself).
//!
//! # Accuracy
//!
//! `J` is computed to a few units of `eps = 2^-53` relative to the exact integral for the
//! given f64 `beta, v0, v1`, for grazing rays, for chords through the centre, for pieces a
//! few ulps from a chord end and for pieces of 1e-12 of the radius, so `tau = sigma0 r J`
//! keeps that relative precision at any optical depth. Measured against 160-digit values
//! (mpmath) on 8000 such cases per profile: worst 3e-16 (constant), 2.7e-15 (linear),
//! 6e-16 (quadratic), 9e-16 (gaussian, widths 0.05 to 1); src/render/tests/profile_chords.rs holds
//! it to 2e-14 against independent quadrature. The antiderivatives of docs/model.md section 6
//! cancel in all of those cases, so each profile is rearranged:
//!
//! - Everything that vanishes at the chord end is derived from `g = 1 - u^2 = h^2 - v^2`
//!   (`h = sqrt(1 - beta^2)`, the half chord), which is formed from the exact products
//!   `beta^2` and `v^2` and an error-free sum (`one_minus_sq`): relative error
//!   `~eps + eps^2 / g`, so the distance to the chord end `h - v = g / (h + v)` is exact to
//!   rounding even a few ulps from the end, and `h` is not the difference `1 - beta` of two
//!   nearly equal numbers.
//! - Differences `F(v1) - F(v0)` are written as integrals of differences (`v1 - v0` times a
//!   sum of positive terms, or `asinh` and `sinh` differences by their addition formulas), so
//!   a piece of 1e-12 of the radius loses nothing.
//!
//! The per-profile details are in the comments of `Chord::linear`, `Chord::quadratic` and
//! `Chord::gaussian` below. The error function is computed in `erf.rs` (`erf`, `erfcx`:
//! W. J. Cody's rational approximations), as the library depends on no crate that provides it.

use glam::DVec3;

use crate::geom::eft::{two_prod, two_square, two_sum};

pub use crate::scene::profile::Profile;

/// The switch between the two forms of the linear profile: the near-surface form is used
/// where `f = 1 - u <= LINEAR_SURFACE` on the whole piece. Rounding errors are amplified at
/// most 8 times on the bulk side (`1 / (1 - X)`, below) and about 5 times (measured) on the
/// near-surface side, whose subtracted term grows with `f`.
const LINEAR_SURFACE: f64 = 0.25;

impl Profile {
    /// The density shape `f(u)` for `u` in `[0, 1]`; 0 outside (NaN for NaN).
    pub fn f(&self, u: f64) -> f64 {
        if u.is_nan() {
            return f64::NAN;
        }
        if !(0.0..=1.0).contains(&u) {
            return 0.0;
        }
        match *self {
            Profile::Constant => 1.0,
            Profile::Linear => 1.0 - u,
            // Factored: exact to rounding near u = 1, where 1 - u is exact (Sterbenz).
            Profile::Quadratic => (1.0 - u) * (1.0 + u),
            Profile::Gaussian { width } => {
                let q = u / width;
                (-0.5 * q * q).exp()
            }
        }
    }

    /// `I_f`, the integral of `f` over `[0, 1]`: 1, 1/2, 2/3, `s sqrt(pi/2) erf(1 / (s sqrt 2))`.
    pub fn integral(&self) -> f64 {
        match *self {
            Profile::Constant => 1.0,
            Profile::Linear => 0.5,
            Profile::Quadratic => 2.0 / 3.0,
            Profile::Gaussian { width } => {
                width * SQRT_PI_OVER_2 * erf(std::f64::consts::FRAC_1_SQRT_2 / width)
            }
        }
    }

    /// The dimensionless integral `J = integral_v0^v1 f(sqrt(beta^2 + v^2)) dv` along a line
    /// at distance `beta` (in radii, `[0, 1]`) from the centre, `v` measured from the closest
    /// approach in radii; the optical depth is `sigma0 r J`.
    ///
    /// `v0, v1` are clipped to the chord `|v| <= sqrt(1 - beta^2)`; the result is 0 if
    /// `v1 <= v0` after clipping or `beta >= 1`. `beta` is taken as `|beta|`. NaN in, NaN out.
    /// Accurate to a few ulps relative (module documentation).
    pub fn line_integral(&self, beta: f64, v0: f64, v1: f64) -> f64 {
        if beta.is_nan() || v0.is_nan() || v1.is_nan() {
            return f64::NAN;
        }
        let b = beta.abs();
        if b >= 1.0 {
            return 0.0;
        }
        let h2 = one_minus_sq(b, 0.0);
        let h = h2.sqrt();
        let (lo, hi) = (v0.max(-h), v1.min(h));
        if lo >= hi {
            return 0.0;
        }
        let chord = Chord { b, h, h2 };
        // Fold by the symmetry v -> -v. A clipped end stands for the exact chord end, whose
        // position h is irrational: what is measured from it comes from g, not from h.
        let piece = if lo >= 0.0 {
            Piece::Side(lo, hi, v1 >= h)
        } else if hi <= 0.0 {
            Piece::Side(-hi, -lo, v0 <= -h)
        } else {
            Piece::Across(lo, hi)
        };
        match *self {
            Profile::Constant => match piece {
                Piece::Side(v0, v1, end) => chord.length(v0, v1, end),
                Piece::Across(v0, v1) => v1 - v0,
            },
            Profile::Linear => chord.linear(piece),
            Profile::Quadratic => chord.quadratic(piece),
            Profile::Gaussian { width } => chord.gaussian(width, piece),
        }
    }

    /// `integral_t0^t1 f(|o + t w - c| / r) dt` in world length for the ray `o + t w` (`w` a
    /// unit vector) through the sphere of centre `c` and radius `r > 0`, so that the optical
    /// depth of `[t0, t1]` is `sigma0` times this; for the constant profile it is the length of
    /// `[t0, t1]` inside the sphere. Infinite `t0, t1` are allowed.
    ///
    /// The closest approach is found in plain f64: `beta` and `v` are off by about
    /// `eps |o - c| / r`, the conditioning of the ray itself (src/render/tests/profile_chords.rs
    /// measures ~4e-13 for origins within 10 radii at `beta <= 0.99`); the rest is
    /// [`Profile::line_integral`].
    pub fn ray_integral(&self, o: DVec3, w: DVec3, t0: f64, t1: f64, c: DVec3, r: f64) -> f64 {
        let f = o - c;
        let tc = -f.dot(w);
        let p = f + tc * w;
        r * self.line_integral(p.length() / r, (t0 - tc) / r, (t1 - tc) / r)
    }
}

/// The extinction scale `sigma0 = -ln(transparency) / (2 r I_f)`, so that the transmittance
/// along a full diameter, `exp(-sigma0 2 r I_f)`, is `transparency` (docs/model.md section 6). For
/// the constant profile it is `Material::sigma`'s `-ln(transparency) / (2 r)`, bit for bit.
pub fn sigma0(transparency: f64, radius: f64, profile: Profile) -> f64 {
    -transparency.ln() / (2.0 * radius * profile.integral())
}

/// `sqrt(pi / 2)`.
const SQRT_PI_OVER_2: f64 = 1.253_314_137_315_500_3;

/// The chord of a line at distance `b` from the centre of the unit ball: `h2 = 1 - b^2`
/// (accurate to rounding, [`one_minus_sq`]) and `h = sqrt(h2)`, the half chord.
struct Chord {
    b: f64,
    h: f64,
    h2: f64,
}

/// A piece of the chord `[-h, h]`, folded by the symmetry `v -> -v` of every integrand.
#[derive(Clone, Copy)]
enum Piece {
    /// `0 <= v0 < v1 <= h`, on one side of the closest approach; `true` if `v1` is the chord
    /// end.
    Side(f64, f64, bool),
    /// `v0 < 0 < v1`. (Whether they are chord ends matters only at second order here: every
    /// form is used away from the ends or where `f` vanishes there.)
    Across(f64, f64),
}

impl Chord {
    /// `g(v) = 1 - b^2 - v^2 = h^2 - v^2 >= 0` (the quadratic profile's `f`), accurate to
    /// rounding; 0 beyond the chord (a clipped end may lie an ulp past it).
    fn g(&self, v: f64) -> f64 {
        one_minus_sq(self.b, v).max(0.0)
    }

    /// `u = sqrt(b^2 + v^2)`, to an ulp.
    fn u(&self, v: f64) -> f64 {
        (self.b * self.b + v * v).sqrt()
    }

    /// `h - v` for `0 <= v <= h`, the distance to the chord end, as `g / (h + v)`: exact to
    /// rounding however close to the end (`h - v` would carry h's rounding, an ulp of `h`).
    fn to_end(&self, v: f64) -> f64 {
        self.g(v) / (self.h + v)
    }

    /// The length of a one-sided piece `[v0, v1]`, [`Chord::to_end`] if `v1` is the end.
    fn length(&self, v0: f64, v1: f64, end: bool) -> f64 {
        if end {
            self.to_end(v0)
        } else {
            v1 - v0
        }
    }

    /// Quadratic profile, `f = g = h^2 - v^2`: `J = L mean(g)`, `L = v1 - v0`, the mean being
    /// `h^2 - (v0^2 + v0 v1 + v1^2) / 3`.
    ///
    /// - Across the closest approach that sum is at most `max(v0^2, v1^2) <= h^2`, so the mean
    ///   is at least `2 h^2 / 3`: no cancellation.
    /// - On one side (`0 <= v0 < v1`) the mean cancels near the chord end. In the distances
    ///   to the end `a = h - v` ([`Chord::to_end`], exact to rounding) the mean is
    ///   `h (a0 + a1) - (a0^2 + a0 a1 + a1^2) / 3`, and as `a <= h` the subtracted part is at
    ///   most 2/3 of the first: rounding errors are amplified at most 3 times.
    fn quadratic(&self, piece: Piece) -> f64 {
        match piece {
            Piece::Across(v0, v1) => (v1 - v0) * (self.h2 - (v0 * v0 + v0 * v1 + v1 * v1) / 3.0),
            Piece::Side(v0, v1, end) => {
                let a0 = self.to_end(v0);
                let a1 = if end { 0.0 } else { self.to_end(v1) };
                let l = if end { a0 } else { v1 - v0 };
                l * (self.h * (a0 + a1) - (a0 * a0 + a0 * a1 + a1 * a1) / 3.0)
            }
        }
    }

    /// Linear profile, `f = 1 - u`: two closed forms, chosen by whether `f` exceeds
    /// [`LINEAR_SURFACE`] somewhere on the piece.
    ///
    /// **Bulk** ([`Chord::linear_bulk`]): docs/model.md's antiderivative as `J = L (1 - X)`,
    /// `L = v1 - v0`, with `X` the mean of `u` over the piece, written without differences.
    /// Since `f` is concave, its mean is at least half its maximum, so `1 - X >= 1/8` here.
    ///
    /// **Near the surface** ([`Chord::linear_surface`]), `f` small everywhere and `1 - X`
    /// would cancel: a hyperbolic variable measured from the chord end does not.
    fn linear(&self, piece: Piece) -> f64 {
        match piece {
            Piece::Side(v0, v1, end) if 1.0 - self.u(v0) <= LINEAR_SURFACE => {
                self.linear_surface(v0, v1, end)
            }
            // Both halves near the surface: a grazing ray.
            // (A whole chord, as a light ray from outside has, is symmetric: one half, twice.)
            Piece::Across(v0, v1) if 1.0 - self.b <= LINEAR_SURFACE && v0 == -v1 => {
                2.0 * self.linear_surface(0.0, v1, false)
            }
            Piece::Across(v0, v1) if 1.0 - self.b <= LINEAR_SURFACE => {
                self.linear_surface(0.0, -v0, false) + self.linear_surface(0.0, v1, false)
            }
            Piece::Side(v0, v1, _) | Piece::Across(v0, v1) => self.linear_bulk(v0, v1),
        }
    }

    /// The linear profile where `f = 1 - u` is not small, on a piece on one side
    /// (`0 <= v0 < v1`) or across the closest approach (`v0 < 0 < v1`).
    ///
    /// docs/model.md's `F(v) = v - v u / 2 - (b^2 / 2) asinh(v / b)` gives
    /// `J = L - (v1 u1 - v0 u0) / 2 - (b^2 / 2) (asinh(v1 / b) - asinh(v0 / b))`. With
    /// `u1 - u0 = L (v0 + v1) / (u0 + u1)` (from `u1^2 - u0^2 = v1^2 - v0^2`),
    /// `v1 u1 - v0 u0 = L ((u0 + u1) / 2 + (v0 + v1)^2 / (2 (u0 + u1)))`, a sum of positive
    /// terms. The `asinh` difference is, by `asinh(a) - asinh(b) = asinh(a sqrt(1 + b^2) -
    /// b sqrt(1 + a^2))`, `asinh(L (v0 + v1) / (v1 u0 + v0 u1))` on one side (no
    /// cancellation, and nothing divided by `b`), or across the closest approach the sum
    /// `asinh(v1 / b) + asinh(-v0 / b)` of positive terms. The term is dropped where `b^2` is
    /// 0 in f64 (it is below `b^2 ln(2 / b)`, under 1e-300).
    fn linear_bulk(&self, v0: f64, v1: f64) -> f64 {
        let b = self.b;
        let l = v1 - v0;
        let (u0, u1) = (self.u(v0), self.u(v1));
        let su = u0 + u1;
        let sv = v0 + v1;
        let mut x = 0.5 * (0.5 * su + sv * sv / (2.0 * su));
        let b2 = b * b;
        if b2 > 0.0 {
            let dphi = if v0 >= 0.0 {
                asinh(l * sv / (v1 * u0 + v0 * u1))
            } else if v0 == -v1 {
                2.0 * asinh(v1 / b)
            } else {
                asinh(v1 / b) + asinh(-v0 / b)
            };
            x += b2 * dphi / (2.0 * l);
        }
        l * (1.0 - x)
    }

    /// The linear profile near the surface, `0 <= v0 < v1 <= h` (`end`: `v1` is the end).
    ///
    /// With `v = b sinh(phi)` the chord end is `phi_e`, `b cosh(phi_e) = 1`,
    /// `b sinh(phi_e) = h`. In `chi = phi_e - phi` (0 at the end),
    /// `u = cosh(chi) - h sinh(chi)` and `dv = -u dchi`, so `J = G(chi0) - G(chi1)` with
    /// `G(chi) = integral_0^chi (u - u^2) = h T(chi) + A(chi) - (1 + h^2) A(2 chi) / 4`,
    /// `T(chi) = (cosh(2 chi) - 1) / 2 - (cosh(chi) - 1)` and `A(x) = sinh(x) - x`. The
    /// differences are taken in `m = (chi0 + chi1) / 2`, `d = (chi0 - chi1) / 2`:
    ///
    /// - `T(chi0) - T(chi1) = 2 sinh(m) sinh(d) (2 cosh(m) cosh(d) - 1)`, a product of
    ///   positive factors;
    /// - `A(k chi0) - A(k chi1) = 4 sinh^2(k m / 2) sinh(k d) + 2 A(k d)`, a sum of positive
    ///   terms ([`sinh_minus_x`] for `A` of a small argument).
    ///
    /// `h T` leads (`J ~ h chi^2 / 2` at the end); the subtracted `A` term is of higher order
    /// and, with `f <= 1/4`, amplifies rounding at most ~5 times (measured). The ends come from
    /// `chi = asinh((h u - v) / b^2) = asinh(g / (h u + v))` (the `asinh` difference formula
    /// with `u = 1` at the end; `g` exact to rounding) and `2 d = asinh(L (v0 + v1) /
    /// (v1 u0 + v0 u1))`, so neither cancels, and `b` may be 0 (`chi = ln(1 / v)`). At the end
    /// `chi1 = 0`, so `m = d = chi0 / 2`.
    fn linear_surface(&self, v0: f64, v1: f64, end: bool) -> f64 {
        let h = self.h;
        let u0 = self.u(v0);
        let chi0 = asinh(self.g(v0) / (h * u0 + v0));
        let (m, d) = if end {
            (0.5 * chi0, 0.5 * chi0)
        } else {
            let u1 = self.u(v1);
            let chi1 = asinh(self.g(v1) / (h * u1 + v1));
            let d = 0.5 * asinh((v1 - v0) * (v0 + v1) / (v1 * u0 + v0 * u1));
            (0.5 * (chi0 + chi1), d)
        };
        // sinh and cosh of m / 2, m, d and 2 d from two expm1 (`sinh_cosh`) and the doubling
        // formulas, all of positive terms.
        let (sm2, cm2) = sinh_cosh(0.5 * m);
        let (sm, cm) = (2.0 * sm2 * cm2, 1.0 + 2.0 * sm2 * sm2);
        let (sd, cd) = sinh_cosh(d);
        let s2d = 2.0 * sd * cd;
        let dt = 2.0 * sm * sd * (2.0 * cm * cd - 1.0);
        let da1 = 4.0 * sm2 * sm2 * sd + 2.0 * sinh_minus_x(d);
        let da2 = 4.0 * sm * sm * s2d + 2.0 * sinh_minus_x(2.0 * d);
        h * dt + da1 - (1.0 + self.h2) * da2 * 0.25
    }

    /// Gaussian profile of width `s`: `f = exp(-(b^2 + v^2) / (2 s^2))`, and with
    /// `x = v / (s sqrt 2)`, `J = s sqrt(pi/2) exp(-b^2 / (2 s^2)) (erf(x1) - erf(x0))`.
    ///
    /// Exponents `Y = u^2 / (2 s^2)` are formed in double-double ([`exp_neg_y`]).
    ///
    /// - Across the closest approach, `erf(x1) + erf(-x0)`: positive terms.
    /// - On one side (`0 <= x0 < x1`), in `m = (x0 + x1) / 2`, `d = (x1 - x0) / 2`:
    ///   - a short piece (`2 m d <= 0.35`, `d <= 0.25`):
    ///     `integral e^(-x^2) = e^(-m^2) integral_-d^d e^(-2 m t - t^2) dt`, expanded in
    ///     Hermite polynomials ([`hermite_mean`]): `J = L exp(-Y(v_mid)) S`, where `S`, the mean
    ///     of `e^(-2 m t - t^2)`, is within 3 % of 1. Tiny pieces are exact to rounding.
    ///   - otherwise, for `x0 >= 0.5`, `erfc(x0) - erfc(x1)` as
    ///     `exp(-Y0) erfcx(x0) - exp(-Y1) erfcx(x1)` (`Y = u^2 / (2 s^2)`), where the second
    ///     term is at most `e^(-4 m d) < 1/2` of the first;
    ///   - or, for `x0 < 0.5`, `erf(x1) - erf(x0)`, the second at most 0.72 of the first.
    fn gaussian(&self, s: f64, piece: Piece) -> f64 {
        let k = std::f64::consts::FRAC_1_SQRT_2 / s;
        match piece {
            Piece::Across(v0, v1) => {
                // erf is odd exactly, so a whole (symmetric) chord takes one erf, same bits.
                let erfs = if v0 == -v1 {
                    2.0 * erf(v1 * k)
                } else {
                    erf(v1 * k) + erf(-v0 * k)
                };
                s * SQRT_PI_OVER_2 * exp_neg_y(u_sq(self.b, 0.0, 0.0), s) * erfs
            }
            Piece::Side(v0, v1, end) => {
                let l = self.length(v0, v1, end);
                let (m, d) = (0.5 * (v0 + v1) * k, 0.5 * l * k);
                if 2.0 * m * d <= 0.35 && d <= 0.25 {
                    self.gaussian_short(s, v0, v1, l, end)
                } else if v0 * k >= 0.5 {
                    self.gaussian_erfc(s, v0, v1, end)
                } else {
                    self.gaussian_erf(s, v0, v1)
                }
            }
        }
    }

    /// [`Chord::gaussian`] on a short piece of length `l` on one side:
    /// `l exp(-Y(v_mid)) S(m, d)`, with `v_mid` exact as a double-double: `(v0 + v1) / 2`, or
    /// `v0 + l / 2` if `v1` is the chord end (then `v1` is the rounded `h`, and an ulp of the
    /// midpoint moves `Y` by `1e-14` at `s = 0.05`).
    fn gaussian_short(&self, s: f64, v0: f64, v1: f64, l: f64, end: bool) -> f64 {
        let k = std::f64::consts::FRAC_1_SQRT_2 / s;
        let (m, d) = (0.5 * (v0 + v1) * k, 0.5 * l * k);
        let (vh, vl) = if end {
            two_sum(v0, 0.5 * l)
        } else {
            let (sum, err) = two_sum(v0, v1);
            (0.5 * sum, 0.5 * err)
        };
        l * exp_neg_y(u_sq(self.b, vh, vl), s) * hermite_mean(m, d)
    }

    /// [`Chord::gaussian`] on one side, away from the centre: the `erfcx` difference. At the
    /// chord end (`end`) `u^2` is exactly 1, not `b^2 + h^2` of the rounded `h`.
    fn gaussian_erfc(&self, s: f64, v0: f64, v1: f64, end: bool) -> f64 {
        let k = std::f64::consts::FRAC_1_SQRT_2 / s;
        let u1 = if end {
            (1.0, 0.0)
        } else {
            u_sq(self.b, v1, 0.0)
        };
        s * SQRT_PI_OVER_2
            * (exp_neg_y(u_sq(self.b, v0, 0.0), s) * erfcx(v0 * k)
                - exp_neg_y(u1, s) * erfcx(v1 * k))
    }

    /// [`Chord::gaussian`] on one side, from near the centre: the `erf` difference.
    fn gaussian_erf(&self, s: f64, v0: f64, v1: f64) -> f64 {
        let k = std::f64::consts::FRAC_1_SQRT_2 / s;
        s * SQRT_PI_OVER_2 * exp_neg_y(u_sq(self.b, 0.0, 0.0), s) * (erf(v1 * k) - erf(v0 * k))
    }
}

/// `1 - b^2 - v^2`, with relative error about `eps + eps^2 / |result|` (so also where it
/// cancels to nearly 0, at a chord end): the squares are split exactly into two f64s
/// (Dekker) and the five parts summed so that every large cancellation happens between exact
/// values (`1 - b^2` is exact for `b^2 >= 1/2` by Sterbenz, and TwoSum keeps the rest).
fn one_minus_sq(b: f64, v: f64) -> f64 {
    let (pb, eb) = two_square(b);
    let (pv, ev) = two_square(v);
    let (s, e1) = two_sum(1.0, -pb);
    let (s, e2) = two_sum(s, -pv);
    // eb is ~eps: folding it into s exactly leaves a tail of parts ~eps^2 (a plain
    // s + (e1 + e2 - eb - ev) would round eb's sum with eps * eps, 1e-13 of a g of 4e-20).
    let (s, e3) = two_sum(s, -eb);
    s + ((e1 + e2) + (e3 - ev))
}

/// `u^2 = b^2 + (vh + vl)^2` as a double-double `(high, low)`: the squares exactly, their
/// sum with TwoSum, the tails added (`vl` a small tail of `vh`, `|vl| <= ulp(vh)`).
fn u_sq(b: f64, vh: f64, vl: f64) -> (f64, f64) {
    let (pb, eb) = two_square(b);
    let (pv, ev) = two_square(vh);
    let (nh, e) = two_sum(pb, pv);
    (nh, e + eb + ev + 2.0 * vh * vl)
}

/// `exp(-Y)`, `Y = (nh + nl) / (2 s^2)`, with `Y` formed in double-double (the quotient with
/// one correction step): `Y` is good to ~eps in absolute terms, so `exp(-Y)` is good to a few
/// ulps however large `Y` is (`exp` turns an absolute error of its argument into a relative
/// one, and `Y` reaches 200 at the surface for `s = 0.05`).
fn exp_neg_y((nh, nl): (f64, f64), s: f64) -> f64 {
    let (dh, dl) = two_square(s);
    let (dh, dl) = (2.0 * dh, 2.0 * dl);
    let y = nh / dh;
    if y.is_nan() || y >= 1e3 {
        // exp(-y) underflows to 0 whatever the correction (and NaN stays NaN).
        return (-y).exp();
    }
    // (nh + nl) / (dh + dl) = y + (nh - y dh + nl - y dl) / dh to second order; y dh exactly.
    let (p, pe) = two_prod(y, dh);
    let yl = (((nh - p) - pe) + nl - y * dl) / dh;
    (-y).exp() * (1.0 - yl)
}

/// `S(m, d) = (1 / 2d) integral_-d^d e^(-2 m t - t^2) dt`, the mean of `e^(-(m+t)^2 + m^2)`
/// over `|t| <= d`, for `2 m d <= 0.35`, `d <= 0.25`.
///
/// From Hermite's generating function `e^(-2 m t - t^2) = sum H_n(m) (-t)^n / n!`, the odd
/// terms integrate to 0: `S = sum_{n even} P_n / (n + 1)` with `P_n = H_n(m) d^n / n!`, by
/// the recurrence `H_{n+1} = 2 m H_n - 2 n H_{n-1}` scaled as
/// `P_{n+1} = (2 m d P_n - 2 d^2 P_{n-1}) / (n + 1)`. With `2 m d` and `d` bounded, `|P_n|`
/// falls factorially (below 1e-18 by `n` = 16) and `|P_2| <= 1/16`: no cancellation.
fn hermite_mean(m: f64, d: f64) -> f64 {
    let (a, c) = (2.0 * m * d, 2.0 * d * d);
    let (mut prev, mut cur) = (1.0, a); // P_0, P_1
    let mut sum = 1.0;
    // (An integer counter: `n % 2.0` on f64 is a call to fmod, a fifth of the cost here.)
    for n in 2..=40u32 {
        let nf = f64::from(n);
        let next = (a * cur - c * prev) / nf;
        prev = cur;
        cur = next;
        if n % 2 == 0 {
            sum += cur / (nf + 1.0);
        }
        if prev.abs() + cur.abs() <= 1e-18 * sum {
            break;
        }
    }
    sum
}

/// `(sinh x, cosh x)` for `x >= 0` from one `expm1`, to a few ulps (no cancellation:
/// `sinh = e (e + 2) / (2 (e + 1))`, `cosh = 1 + e^2 / (2 (e + 1))`, `e = expm1(x)`).
#[inline]
fn sinh_cosh(x: f64) -> (f64, f64) {
    let e = x.exp_m1();
    let q = 0.5 / (e + 1.0);
    (e * (e + 2.0) * q, 1.0 + e * e * q)
}

/// `asinh(x)` to a few ulps, as `log1p(|x| + x^2 / (1 + sqrt(1 + x^2)))` with the sign of
/// `x`: the standard library's goes through `hypot`, guarded against overflow, at twice the
/// cost; beyond 1e8 (where `x^2` could overflow) it is used as is.
#[inline]
fn asinh(x: f64) -> f64 {
    let a = x.abs();
    if a > 1e8 || a.is_nan() {
        return x.asinh();
    }
    let a2 = a * a;
    (a + a2 / (1.0 + (1.0 + a2).sqrt())).ln_1p().copysign(x)
}

/// `sinh(x) - x`, to a few ulps: the Taylor series `x^3/3! + x^5/5! + ...` for `|x| <= 2`
/// (the direct difference cancels), else the direct difference (which then loses < 2 bits).
fn sinh_minus_x(x: f64) -> f64 {
    if x.abs() > 2.0 {
        return x.sinh() - x;
    }
    let x2 = x * x;
    let mut term = x * x2 / 6.0;
    let mut sum = term;
    let mut k = 3.0;
    while term.abs() > 1e-18 * sum.abs() {
        term *= x2 / ((k + 1.0) * (k + 2.0));
        k += 2.0;
        sum += term;
    }
    sum
}

mod erf;
#[cfg(test)]
use erf::exp_neg_sq;
use erf::{erf, erfcx};

#[cfg(test)]
mod tests;
