//! Line/sphere roots in f64 that stay accurate for tiny spheres far away and for grazing rays.
//!
//! The formulation follows Haines, Günther and Akenine-Möller, "Precision Improvements for
//! Ray/Sphere Intersection" (Ray Tracing Gems, 2019, ch. 7), as pbrt-v4 `Sphere::BasicIntersect`
//! does: the discriminant is `r^2 - |v|^2` with `v` the offset from the centre to the line's
//! closest point, and the roots use the stable `q` form. On top of that, `o - c` is kept exactly
//! (TwoSum), `v` is formed with exact products (Dekker), the closest-point parameter is refined
//! once, and the constant term `|o - c|^2 - r^2` is summed without cancellation error. The
//! result: hit or miss is decided correctly whenever the exact closest-approach distance differs
//! from `r` by more than about `1e-15 r`, whatever the distance to the sphere (src/geom/tests/).

use glam::DVec3;

use super::eft::{two_sum, Dekker, ExactProducts, Fused};

/// Parameters `t0 <= t1` where the line `o + t d` meets the sphere `|x - c| = r`, or `None` if
/// it misses.
///
/// - `d` need not be unit length; `t` is in units of `d` (world length is `t * |d|`).
/// - A tangent line gives `Some((t, t))`; a line through the centre of a sphere of radius 0
///   likewise.
/// - `None` for `d == 0`, for `r < 0` and for non-finite input. Never NaN for finite input. A
///   root beyond the f64 range saturates to `±inf` (possible only when `|d|` is below about
///   `|o - c| / f64::MAX`).
/// - Accuracy (src/geom/tests/): each root within ~4 eps `(|t| + r^2 / (|d| h))` of the
///   exact root of the given f64 inputs (`eps = 2^-53`, `h` the world half chord): a few ulps,
///   plus the sensitivity of near-tangent rays to one ulp of the closest-approach distance.
///   The root nearer 0 is also within ~10 eps of itself, so a ray leaving a surface gets a
///   tiny root of the right sign. Inputs whose magnitudes span more than ~2^1000 lose their
///   smallest parts (see `scale_down`).
#[inline]
pub fn sphere_roots(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    // Most calls (BVH leaf candidates) miss by far: decide those first. The test is false
    // for NaN or infinite input, which the checks below then refuse.
    if certainly_misses(o, d, c, r) {
        return None;
    }
    careful_roots(o, d, c, r)
}

/// [`sphere_roots`] once a certain miss is ruled out. Compiled again for FMA and chosen at
/// run time: the exact products are then one fused multiply-add each instead of Dekker's
/// splits (the same values, see [`ExactProducts`]).
#[multiversion::multiversion(targets("x86_64+avx+avx2+fma+bmi1+bmi2+lzcnt+popcnt"))]
fn careful_roots(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    // Chosen when each clone is compiled, not at run time.
    multiversion::target::match_target! {
        "x86_64+fma" => careful_roots_with::<Fused>(o, d, c, r),
        _ => careful_roots_with::<Dekker>(o, d, c, r),
    }
}

/// [`careful_roots`] with the exact products of `P`.
#[inline(always)]
fn careful_roots_with<P: ExactProducts>(
    o: DVec3,
    d: DVec3,
    c: DVec3,
    r: f64,
) -> Option<(f64, f64)> {
    if !(o.is_finite() && d.is_finite() && c.is_finite() && r.is_finite()) || r < 0.0 {
        return None;
    }
    let dmax = d.abs().max_element();
    if dmax == 0.0 {
        return None;
    }
    let big = o.abs().max_element().max(c.abs().max_element()).max(r);
    if (SAFE_LO..=SAFE_HI).contains(&big) && (SAFE_LO..=SAFE_HI).contains(&dmax) {
        // Every intermediate stays far inside the f64 range (|t| < 2^203, |q| < 2^406, the
        // largest squares above 2^-200, and every split operand below 2^995), so the inputs
        // need no scaling. Scaling by powers of two is exact, so this computes the same
        // sums and products as the scaled path, up to the rounding of the two square roots.
        return unit_scale_roots::<P>(o, d, c, r);
    }
    // The problem is invariant under o, c, r -> 2^-k (o, c, r) and d -> 2^-m d, with
    // t -> 2^(m-k) t. Powers of two scale exactly, so bring every input to about 1 and no
    // product below can overflow or underflow (even for d ~ 1e-300 or r ~ 1e300).
    let k = exponent(o.abs().max_element().max(c.abs().max_element()).max(r));
    let m = exponent(dmax);
    let (t0, t1) = unit_scale_roots::<P>(
        scale_down(o, k),
        scale_down(d, m),
        scale_down(c, k),
        scalbn(r, -k),
    )?;
    Some((scalbn(t0, k - m), scalbn(t1, k - m)))
}

/// Bounds of the magnitudes (largest of `|o|, |c|, r`, and largest `|d_i|`) for which
/// [`careful_roots`] skips the scaling: 2^-100 and 2^100.
const SAFE_LO: f64 = 7.888609052210118e-31;
const SAFE_HI: f64 = 1.2676506002282294e30;

/// The line's closest approach to the centre in plain f64, the cheap estimates below start
/// from: `f = o - c`, `a = d.d`, `tc = -(f.d)/a` and `v = f + tc d`, with `size = |f|_1 + r`
/// and `e_v = 64 u size` (`u = 2^-53`).
///
/// `|v|` has an absolute error below `16 u (|f| + r)`: `f` is off by at most `u |f|` per
/// component, `tc` by `~8 u |f| / |d|` (which moves `v` along `d` and changes `|v|` by at most
/// that times `|d|`), and forming `v` and its length adds `~6 u |f|` (`|tc d| <= |f|`). `e_v`
/// is 4x that bound (`|f|` bounded by its 1-norm, so the margin only grows).
struct Approach {
    a: f64,
    tc: f64,
    v: DVec3,
    size: f64,
    e_v: f64,
}

impl Approach {
    /// `None` where the magnitudes leave the range in which no square overflows or
    /// underflows (then the bounds do not hold).
    #[inline(always)]
    fn of(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<Approach> {
        let f = o - c;
        let a = d.dot(d);
        let ff = f.dot(f);
        if !(a > 1e-280 && a < 1e280 && ff > 1e-280 && ff < 1e280 && r < 1e139) {
            return None;
        }
        let tc = -f.dot(d) / a;
        let v = f + tc * d;
        let size = f.abs().element_sum() + r;
        Some(Approach {
            a,
            tc,
            v,
            size,
            e_v: 64.0 * (0.5 * f64::EPSILON) * size,
        })
    }

    /// A cheap, certain rejection of lines that pass well clear of the sphere (most candidate
    /// tests in a BVH leaf), before the careful path: the computed distance exceeds `r` by
    /// `e_v`. No square roots: `|v| > m` is tested as `v.v > m^2`, whose roundings move the
    /// comparison by ~2 eps `(|f| + r)`, well inside the 4x margin.
    #[inline(always)]
    fn misses(&self, r: f64) -> bool {
        let m = r + self.e_v;
        self.v.dot(self.v) > m * m
    }

    /// [`enters_between`] from the estimate of the entry `tc - h`, when its margin allows:
    /// `None` when the line passes outside `0.999 r` of the centre (or may), when the entry
    /// lies within the margin of 0 or `dist`, or when `r` is tiny (then the careful roots
    /// decide).
    ///
    /// Bounds, in units of `u`: with `|v|` within `e_v / 4` of exact, the half chord
    /// `sqrt(r^2 - |v|^2)` is at least `0.044 r` once `|v| + e_v <= 0.999 r`, and moves by at
    /// most `3 r e_v / (2 * 0.044 r) < 35 e_v` for an error `e_v` in `|v|`; `tc` is within
    /// `8 |f| / |d|`; roundings of the square roots, the division and the difference add a
    /// few `u` of `|tc| + h`.
    #[inline(always)]
    fn clearly_enters_between(&self, r: f64, dist: f64) -> Option<bool> {
        // (`r` is not NaN: `Approach::of` refused it.)
        if r <= 1e-139 {
            return None;
        }
        let len = self.v.length();
        if len + self.e_v > 0.999 * r {
            return None;
        }
        let norm = self.a.sqrt();
        let h = (r - len).sqrt() * (r + len).sqrt() / norm;
        let t0 = self.tc - h;
        let margin = 1e-10 * (self.size / norm + self.tc.abs() + h);
        if t0 > margin && t0 < dist - margin {
            Some(true)
        } else if t0 < -margin || t0 > dist + margin {
            Some(false)
        } else {
            None
        }
    }
}

/// [`Approach::misses`], for a line not yet estimated.
#[inline]
fn certainly_misses(o: DVec3, d: DVec3, c: DVec3, r: f64) -> bool {
    Approach::of(o, d, c, r).is_some_and(|p| p.misses(r))
}

/// Whether the line `o + t d` enters the sphere `|x - c| = r` strictly between `t = 0` and
/// `t = dist` (`dist` may be infinite): exactly
/// `matches!(sphere_roots(o, d, c, r), Some((t0, _)) if t0 > 0.0 && t0 < dist)`, the test a
/// shadow ray makes of an opaque sphere, with the careful roots computed only when a plain
/// f64 estimate of the entry is too close to 0 or `dist`, or the line too close to tangent,
/// to call.
///
/// The estimate (see `Approach::clearly_enters_between`) is off from the exact entry by at
/// most `~2200 u ((|f|_1 + r) / |d|) + 4 u |t0|` (`u = 2^-53`, `f = o - c`) on lines that
/// pass within `0.999 r` of the centre, and [`sphere_roots`]' entry by at most
/// `~4 u (|t0| + 23 r / |d|)` there (its half chord is at least `0.04 r`). The margin
/// asked for is `1e-10` times those scales, over a hundred times their sum: wherever the
/// estimate decides, the careful roots decide the same. The closest approach is computed
/// once for the certain miss and the estimate.
#[inline(always)]
pub fn enters_between(o: DVec3, d: DVec3, c: DVec3, r: f64, dist: f64) -> bool {
    let approach = Approach::of(o, d, c, r);
    if approach.as_ref().is_some_and(|p| p.misses(r)) {
        return false;
    }
    match approach.and_then(|p| p.clearly_enters_between(r, dist)) {
        Some(enters) => enters,
        None => matches!(careful_roots(o, d, c, r), Some((t0, _)) if t0 > 0.0 && t0 < dist),
    }
}

/// The overlap, in units of the ray parameter `t`, of the segment `t in [ta, tb]` of the line
/// `o + t d` with the sphere `|x - c| = r`: `max(0, min(t1, tb) - max(t0, ta))` with `t0, t1`
/// from [`sphere_roots`]; 0 if the line misses or `tb <= ta`.
///
/// The world length of the chord is this times `|d|` (for a unit `d`, it is the world length).
/// `ta = -inf` or `tb = +inf` are allowed (a ray to infinity).
#[cfg(test)]
pub fn segment_chord(o: DVec3, d: DVec3, c: DVec3, r: f64, ta: f64, tb: f64) -> f64 {
    match sphere_roots(o, d, c, r) {
        Some((t0, t1)) => {
            let (lo, hi) = (t0.max(ta), t1.min(tb));
            if hi > lo {
                hi - lo
            } else {
                0.0
            }
        }
        None => 0.0,
    }
}

/// [`sphere_roots`] for scaled inputs: `|o|, |c|, r < 2` (max of them in [1, 2) or all 0) and
/// `max |d_i|` in [1, 2), so `a = d.d` is in [1, 12) and nothing below overflows; or for
/// unscaled inputs within [`SAFE_LO`]..[`SAFE_HI`], where nothing overflows either.
///
/// Exact products by `P` ([`ExactProducts`]): Dekker's splitting unless compiled for FMA.
#[inline(always)]
fn unit_scale_roots<P: ExactProducts>(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Option<(f64, f64)> {
    // f = o - c = fh + fl exactly (TwoSum). Rounding f would move the line sideways by
    // eps |f|, which is 1e-9 r for a sphere of radius 1e-3 at distance 1e4.
    let (fh, fl) = two_sum3(o, -c);
    let a = d.dot(d);

    // tc + tl: parameter of the point closest to the centre, -(f.d)/(d.d), as an unevaluated
    // sum. An error dt in it moves v = f + t d along d only, changing |v|^2 by dt^2 a (second
    // order); but tc alone is off by up to an ulp, eps |f| along d, which still biases |v| by
    // ~(eps |f| / r)^2 / 2 (1e-9 for |f| / r = 3e11). One Newton step (v.d = 0 at the exact
    // parameter) gives the correction tl, kept apart from tc so it is not rounded away.
    let tc = -(fh.dot(d) + fl.dot(d)) / a;
    let v1 = closest_offset::<P>(fh, fl, tc, d);
    let tl = -v1.dot(d) / a;
    // tl d is the small correction (~eps |f|), so rounding the product first costs
    // ~eps^2 |f|, below v's own error.
    let v = v1 + tl * d;

    // Discriminant as r^2 - |v|^2 (Haines et al.) rather than b^2 - ac: both b^2 and ac are
    // ~|f|^2 |d|^2 and their difference drowns in their rounding for small or distant spheres.
    // v is accurate to ~eps |v| + eps^2 |f|, so the sign is right unless |v| = r (1 +- ~4 eps).
    let len = v.length();
    if len > r {
        return None;
    }
    // Half chord w = sqrt(r^2 - |v|^2) as sqrt(r - len) sqrt(r + len): r - len is exact near
    // tangency (Sterbenz) and the split avoids underflow of the product.
    let w = (r - len).sqrt() * (r + len).sqrt();
    let h = w / a.sqrt(); // half chord in units of t

    // Stable roots (half-b form, b = f.d = -a (tc + tl)): q = -(b + sign(b) sqrt(b^2 - ac)),
    // t = q/a and c/q. q/a = tc + tl + sign(tc) h adds numbers of one sign (|tl| << |tc| unless
    // both are ~0), so it has no cancellation; the root nearer 0 comes from Vieta
    // (t0 t1 = c/a) instead of the cancelling tc - sign(tc) h. Small terms are summed first.
    let t_far = tc + (tl + h.copysign(tc + tl));
    let q = a * t_far;
    let t_near = if q != 0.0 {
        // |t_near| <= |t_far| holds exactly; clamping enforces it when q is tiny (a ray
        // nearly tangent at its origin), where rounding in c could make c/q huge.
        let lim = t_far.abs();
        (dist2_minus_r2::<P>(fh, fl, r) / q).clamp(-lim, lim)
    } else {
        // q == 0: tc + tl == 0 and h == 0, a double root at the origin.
        t_far
    };
    Some(if t_near <= t_far {
        (t_near, t_far)
    } else {
        (t_far, t_near)
    })
}

/// `f + tc d` with `f = fh + fl`: `tc d` is formed exactly as `p + e` (it is ~|f| and nearly
/// cancels `fh`), then `p + fh` rounds once relative to the small result (it is exact when
/// they cancel, by Sterbenz) and the small tails are added. As accurate as a fused
/// multiply-add `fma(tc, d, fh) + fl`.
#[inline(always)]
fn closest_offset<P: ExactProducts>(fh: DVec3, fl: DVec3, tc: f64, d: DVec3) -> DVec3 {
    let one = |dk: f64, fk: f64, lk: f64| {
        let (p, e) = P::prod(tc, dk);
        (p + fk) + (e + lk)
    };
    DVec3::new(
        one(d.x, fh.x, fl.x),
        one(d.y, fh.y, fl.y),
        one(d.z, fh.z, fl.z),
    )
}

/// `|fh + fl|^2 - r^2` (the quadratic's constant term `c`), accurate to ~eps |c| even when it
/// cancels to nearly 0 (origin on the sphere): every square is split exactly into two f64s
/// (TwoProduct) and the large parts are summed with TwoSum (Ogita, Rump, Oishi "Sum2").
#[inline(always)]
fn dist2_minus_r2<P: ExactProducts>(fh: DVec3, fl: DVec3, r: f64) -> f64 {
    let (px, ex) = P::square(fh.x);
    let (py, ey) = P::square(fh.y);
    let (pz, ez) = P::square(fh.z);
    let (pr, er) = P::square(r);
    let (s, e1) = two_sum(px, py);
    let (s, e2) = two_sum(s, pz);
    let (s, e3) = two_sum(s, -pr);
    // The tail is ~eps |f|^2; rounding it costs ~eps^2 |f|^2. fl.fl is ~eps^2 |f|^2 itself.
    let tail = (e1 + e2 + e3) + (ex + ey + ez - er) + 2.0 * fh.dot(fl) + fl.dot(fl);
    s + tail
}

#[inline(always)]
fn two_sum3(a: DVec3, b: DVec3) -> (DVec3, DVec3) {
    let (x, ex) = two_sum(a.x, b.x);
    let (y, ey) = two_sum(a.y, b.y);
    let (z, ez) = two_sum(a.z, b.z);
    (DVec3::new(x, y, z), DVec3::new(ex, ey, ez))
}

/// `floor(log2 |x|)` for finite non-zero `x` (subnormals included); 0 for 0.
pub(super) fn exponent(x: f64) -> i32 {
    if x == 0.0 {
        return 0;
    }
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i32;
    if biased == 0 {
        // Subnormal: 2^64 x is normal and the scaling is exact.
        exponent(x * f64::from_bits(0x43f0_0000_0000_0000)) - 64
    } else {
        biased - 1023
    }
}

/// `x * 2^n` for any `n`, rounded once (musl's `scalbn`): the factor is applied in steps that
/// stay representable, and the last underflowing step is the only one that can round.
pub(super) fn scalbn(mut x: f64, mut n: i32) -> f64 {
    const P1023: f64 = f64::from_bits(0x7fe0_0000_0000_0000); // 2^1023
    const PM969: f64 = f64::from_bits(0x0360_0000_0000_0000); // 2^-969 = 2^-1022 * 2^53
    if n > 1023 {
        x *= P1023;
        n -= 1023;
        if n > 1023 {
            x *= P1023;
            n = (n - 1023).min(1023);
        }
    } else if n < -1022 {
        // Stop 53 above the subnormal range so that only the final multiply rounds.
        x *= PM969;
        n += 969;
        if n < -1022 {
            x *= PM969;
            n = (n + 969).max(-1022);
        }
    }
    x * f64::from_bits(((0x3ff + n) as u64) << 52)
}

/// `v * 2^-k` componentwise. Exact unless a component falls below 2^-1022 on the way, which
/// happens only to parts 2^1000 times smaller than the largest input, i.e. irrelevant ones.
pub(super) fn scale_down(v: DVec3, k: i32) -> DVec3 {
    DVec3::new(scalbn(v.x, -k), scalbn(v.y, -k), scalbn(v.z, -k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_and_scalbn_cover_the_whole_range() {
        for e in -1074..=1023 {
            let x = 2f64.powi(e.max(-1022)) * if e < -1022 { 2f64.powi(e + 1022) } else { 1.0 };
            assert_eq!(exponent(x), e, "2^{e}");
            assert_eq!(exponent(-1.5 * x), e + i32::from(e == -1074), "1.5 * 2^{e}");
        }
        assert_eq!(scalbn(1.0, -1074), f64::from_bits(1));
        assert_eq!(scalbn(f64::from_bits(1), 1074 + 1023), 2f64.powi(1023));
        assert_eq!(
            scalbn(f64::MAX, -2046),
            f64::MAX * 2f64.powi(-1023) * 2f64.powi(-1023)
        );
        assert_eq!(scalbn(1.0, 5000), f64::INFINITY);
        assert_eq!(scalbn(-1.0, -5000), -0.0);
        assert_eq!(scalbn(3.0, 0), 3.0);
    }

    /// The plain estimate decides most of the shadow rays that meet a sphere (the careful
    /// roots are then skipped), and decides them as the careful roots do. (Agreement at the
    /// margins is tested in src/geom/tests/.)
    #[test]
    fn clear_entries_skip_the_careful_roots() {
        let mut rng = crate::testing::Rng::new(43);
        let (mut met, mut decided) = (0, 0);
        for _ in 0..20_000 {
            // A point on a sphere of radius 1 at the origin, towards a light, past a second
            // sphere somewhere near.
            let x = DVec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize();
            let c = x * rng.range(1.0, 4.0)
                + DVec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * 2.0;
            let r = rng.range(0.2, 1.0);
            let l = (c + DVec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * 2.0 * r - x)
                .normalize();
            let dist = if rng.f() < 0.5 {
                f64::INFINITY
            } else {
                rng.range(0.1, 10.0)
            };
            let careful = careful_roots(x, l, c, r);
            if careful.is_none() {
                continue;
            }
            met += 1;
            let estimate = Approach::of(x, l, c, r).and_then(|p| p.clearly_enters_between(r, dist));
            if let Some(enters) = estimate {
                decided += 1;
                assert_eq!(enters, careful.is_some_and(|(t0, _)| t0 > 0.0 && t0 < dist));
            }
        }
        assert!(
            met > 5_000 && decided * 100 > 98 * met,
            "{decided} of {met}"
        );
    }

    /// The FMA clone's exact products give the same roots, bit for bit, as Dekker's, on
    /// hits, grazing rays, origins on and near the surface, tiny far spheres and inputs
    /// that need scaling (outside 2^-100..2^100).
    #[test]
    fn fused_products_give_the_same_roots_as_dekkers() {
        let mut rng = crate::testing::Rng::new(41);
        let unit = |rng: &mut crate::testing::Rng| {
            let v = DVec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5);
            if v.length() > 1e-3 {
                v.normalize()
            } else {
                DVec3::X
            }
        };
        let (mut hits, mut grazing) = (0, 0);
        for k in 0..40_000 {
            let scale = 10f64.powf(rng.range(-140.0, 140.0) * f64::from(k % 4 == 0));
            let r = scale * rng.log10(-6.0, 1.0);
            let c = scale * 100.0 * DVec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5);
            let d = unit(&mut rng) * rng.log10(-3.0, 3.0);
            // The origin: anywhere, on the sphere, or placed so the line passes at a chosen
            // distance from the centre (about r, for grazing rays).
            let o = match k % 3 {
                0 => c + scale * 1e3 * unit(&mut rng),
                1 => c + r * unit(&mut rng),
                _ => {
                    let side = unit(&mut rng).cross(d).normalize_or(DVec3::Y);
                    let miss = r * (1.0 + rng.range(-1e-12, 1e-12) * f64::from(k % 2 == 0));
                    c + miss * side - d * rng.range(-1e3, 1e3) * scale
                }
            };
            let fused = careful_roots_with::<Fused>(o, d, c, r);
            let dekker = careful_roots_with::<Dekker>(o, d, c, r);
            let bits = |x: Option<(f64, f64)>| x.map(|(a, b)| (a.to_bits(), b.to_bits()));
            assert_eq!(bits(fused), bits(dekker), "{o:?} {d:?} {c:?} {r:e}");
            hits += usize::from(dekker.is_some());
            grazing += usize::from(
                dekker.is_some_and(|(a, b)| (b - a).abs() < 1e-5 * (a.abs() + b.abs())),
            );
        }
        // The cases above are not all misses, and some are nearly tangent.
        assert!(
            hits > 15_000 && grazing > 5_000,
            "{hits} hits, {grazing} grazing"
        );
    }

    #[test]
    fn axis_ray_through_unit_sphere_has_exact_roots() {
        let roots = |d| sphere_roots(DVec3::new(0.0, 0.0, -5.0), d, DVec3::ZERO, 1.0);
        assert_eq!(roots(DVec3::Z), Some((4.0, 6.0)));
        assert_eq!(roots(2.0 * DVec3::Z), Some((2.0, 3.0)));
        assert_eq!(roots(-DVec3::Z), Some((-6.0, -4.0)));
        assert_eq!(roots(DVec3::X), None);
    }

    #[test]
    fn degenerate_inputs_give_none_or_a_double_root() {
        let (o, c) = (DVec3::new(1.0, 0.0, 0.0), DVec3::ZERO);
        assert_eq!(sphere_roots(o, DVec3::ZERO, c, 1.0), None);
        assert_eq!(sphere_roots(o, DVec3::Y, c, -1.0), None);
        assert_eq!(sphere_roots(o, DVec3::Y, c, f64::NAN), None);
        assert_eq!(
            sphere_roots(o, DVec3::new(f64::INFINITY, 0.0, 0.0), c, 1.0),
            None
        );
        // Tangent at the origin: b = 0 and w = 0, so q = 0.
        assert_eq!(sphere_roots(o, DVec3::Y, c, 1.0), Some((0.0, 0.0)));
        // Radius 0: only a line through the centre touches it.
        assert_eq!(sphere_roots(o, -DVec3::X, c, 0.0), Some((1.0, 1.0)));
        assert_eq!(sphere_roots(o, DVec3::Y, c, 0.0), None);
        // Everything zero: the origin is the (point) sphere.
        assert_eq!(sphere_roots(c, DVec3::X, c, 0.0), Some((0.0, 0.0)));
    }

    #[test]
    fn segment_chord_clips_to_the_segment() {
        let (o, d, c) = (DVec3::new(0.0, 0.0, -5.0), DVec3::Z, DVec3::ZERO);
        assert_eq!(segment_chord(o, d, c, 1.0, 0.0, f64::INFINITY), 2.0);
        assert_eq!(segment_chord(o, d, c, 1.0, 5.0, 5.5), 0.5);
        assert_eq!(segment_chord(o, d, c, 1.0, 0.0, 4.5), 0.5);
        assert_eq!(segment_chord(o, d, c, 1.0, 6.5, 9.0), 0.0);
        assert_eq!(segment_chord(o, d, c, 1.0, 5.5, 5.0), 0.0);
        assert_eq!(segment_chord(o, DVec3::X, c, 1.0, 0.0, 9.0), 0.0);
        assert_eq!(
            segment_chord(o, d, c, 1.0, f64::NEG_INFINITY, f64::INFINITY),
            2.0
        );
    }
}
