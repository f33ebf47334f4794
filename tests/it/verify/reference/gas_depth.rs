//! The optical depth of a gas sphere along a line in closed form, for the AO reference
//! (`super::super::ao`): each profile's integral of the density, written apart from the
//! library's and from `World::depth`'s quadrature, which the self-tests hold it to.

use glam::DVec3;

use super::super::scenes::Profile;
use super::super::world::Gas;

/// `erf(x)` from the series `2/sqrt(pi) exp(-x^2) sum_k (2 x^2)^k x / (1 3 ... (2k + 1))`,
/// whose terms are all of the sign of `x` (no cancellation); 1 in magnitude past 6, where
/// `erfc` is below 2e-17.
pub fn erf(x: f64) -> f64 {
    if x.abs() >= 6.0 {
        return x.signum();
    }
    let x2 = x * x;
    let (mut term, mut sum) = (x, x);
    let mut k = 0.0;
    while term.abs() > 1e-17 * sum.abs() {
        k += 1.0;
        term *= 2.0 * x2 / (2.0 * k + 1.0);
        sum += term;
    }
    std::f64::consts::FRAC_2_SQRT_PI * (-x2).exp() * sum
}

/// Optical depth of gas `g` along `x + s w` (`w` unit), `s` in `[a, b]` inside the sphere, in
/// closed form: with `v` the parameter from the line's closest approach to the centre (at
/// distance `d`) and `rho^2 = d^2 + v^2`, the integral over `v` of `sigma0 f(rho / r)`:
/// constant `v`; quadratic `((r^2 - d^2) v - v^3 / 3) / r^2`; linear `v - (v rho + d^2
/// asinh(v / d)) / (2 r)`; gaussian of width `s` `exp(-d^2 / (2 s^2 r^2)) s r sqrt(pi / 2)
/// erf(v / (sqrt 2 s r))`. (`World::depth` integrates the density numerically; the
/// self-test `verify_ao_gas_depth_closed_forms_match_quadrature` holds these to it.)
pub fn gas_depth(g: &Gas, x: DVec3, w: DVec3, a: f64, b: f64) -> f64 {
    let line = g.line(x, w);
    let (va, vb) = (a - line.sc, b - line.sc);
    let (r, d2) = (g.r, line.d2);
    let integral = match g.m.profile {
        Profile::Constant => vb - va,
        Profile::Quadratic => {
            ((r * r - d2) * (vb - va) - (vb.powi(3) - va.powi(3)) / 3.0) / (r * r)
        }
        Profile::Linear => {
            let d = d2.sqrt();
            let prim = |v: f64| {
                let tail = if d > 0.0 { d2 * (v / d).asinh() } else { 0.0 };
                (v * (d2 + v * v).sqrt() + tail) / 2.0
            };
            (vb - va) - (prim(vb) - prim(va)) / r
        }
        Profile::Gaussian(width) => {
            let sr = width * r;
            let k = std::f64::consts::SQRT_2 * sr;
            (-d2 / (2.0 * sr * sr)).exp()
                * sr
                * (std::f64::consts::PI / 2.0).sqrt()
                * (erf(vb / k) - erf(va / k))
        }
    };
    g.sigma0 * integral.max(0.0)
}
