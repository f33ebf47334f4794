//! Exact oracle for line/sphere questions on f64 inputs, independent of the geometry it checks.
//!
//! Every finite f64 is a dyadic rational `m * 2^e`. Sums and products of dyadics are dyadics,
//! so with arbitrary-size integers (a minimal sign-magnitude bigint below) the discriminant,
//! the sign of `|o + t d - c|^2 - r^2` at any f64 `t`, and comparisons against the vertex are
//! computed exactly. Roots are irrational in general; the oracle returns the pair of adjacent
//! f64 values that brackets each one, found by bisection on exact signs (no sqrt, no division).

use std::cmp::Ordering;

use glam::DVec3;

/// Sign-magnitude integer, little-endian u32 limbs without trailing zeros; zero is empty.
#[derive(Clone, Debug, Default)]
struct Big {
    neg: bool,
    mag: Vec<u32>,
}

fn trim(mut v: Vec<u32>) -> Vec<u32> {
    while v.last() == Some(&0) {
        v.pop();
    }
    v
}

fn cmp_mag(a: &[u32], b: &[u32]) -> Ordering {
    a.len()
        .cmp(&b.len())
        .then_with(|| a.iter().rev().cmp(b.iter().rev()))
}

fn add_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
    let (a, b) = if a.len() >= b.len() { (a, b) } else { (b, a) };
    let mut out = Vec::with_capacity(a.len() + 1);
    let mut carry = 0u64;
    for (i, &x) in a.iter().enumerate() {
        let s = x as u64 + *b.get(i).unwrap_or(&0) as u64 + carry;
        out.push(s as u32);
        carry = s >> 32;
    }
    out.push(carry as u32);
    trim(out)
}

/// `a - b` for `a >= b`.
fn sub_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(a.len());
    let mut borrow = 0i64;
    for (i, &x) in a.iter().enumerate() {
        let mut s = x as i64 - *b.get(i).unwrap_or(&0) as i64 - borrow;
        borrow = i64::from(s < 0);
        if s < 0 {
            s += 1 << 32;
        }
        out.push(s as u32);
    }
    assert_eq!(borrow, 0, "sub_mag needs a >= b");
    trim(out)
}

fn mul_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0u32; a.len() + b.len()];
    for (i, &x) in a.iter().enumerate() {
        let mut carry = 0u64;
        for (j, &y) in b.iter().enumerate() {
            let s = x as u64 * y as u64 + out[i + j] as u64 + carry;
            out[i + j] = s as u32;
            carry = s >> 32;
        }
        out[i + b.len()] = carry as u32;
    }
    trim(out)
}

fn shl_mag(a: &[u32], bits: u32) -> Vec<u32> {
    if a.is_empty() {
        return Vec::new();
    }
    let (limbs, rem) = ((bits / 32) as usize, bits % 32);
    let mut out = vec![0u32; limbs];
    let mut carry = 0u32;
    for &x in a {
        out.push((x << rem) | carry);
        carry = if rem == 0 { 0 } else { x >> (32 - rem) };
    }
    out.push(carry);
    trim(out)
}

fn bit_len(a: &[u32]) -> u32 {
    match a.last() {
        None => 0,
        Some(&top) => 32 * (a.len() as u32 - 1) + (32 - top.leading_zeros()),
    }
}

/// The top 64 bits of `a` (truncated) and the shift that was dropped: `a ~ top * 2^shift`.
fn top64(a: &[u32]) -> (u64, i32) {
    let len = bit_len(a);
    let shift = len.saturating_sub(64);
    let mut top = 0u64;
    for k in 0..len.min(64) {
        let bit = shift + k;
        if (a[(bit / 32) as usize] >> (bit % 32)) & 1 == 1 {
            top |= 1 << k;
        }
    }
    (top, shift as i32)
}

/// Exact dyadic rational `m * 2^e`.
#[derive(Clone, Debug, Default)]
pub struct Dy {
    m: Big,
    e: i32,
}

impl Dy {
    pub fn from_f64(x: f64) -> Dy {
        assert!(x.is_finite());
        if x == 0.0 {
            return Dy::default();
        }
        let bits = x.to_bits();
        let biased = ((bits >> 52) & 0x7ff) as i32;
        let frac = bits & ((1 << 52) - 1);
        let (mant, e) = if biased == 0 {
            (frac, -1074)
        } else {
            (frac | (1 << 52), biased - 1075)
        };
        let mag = trim(vec![mant as u32, (mant >> 32) as u32]);
        Dy {
            m: Big { neg: x < 0.0, mag },
            e,
        }
    }

    pub fn sign(&self) -> i32 {
        if self.m.mag.is_empty() {
            0
        } else if self.m.neg {
            -1
        } else {
            1
        }
    }

    pub fn neg(&self) -> Dy {
        let mut out = self.clone();
        out.m.neg = !out.m.neg && !out.m.mag.is_empty();
        out
    }

    pub fn add(&self, other: &Dy) -> Dy {
        if self.sign() == 0 {
            return other.clone();
        }
        if other.sign() == 0 {
            return self.clone();
        }
        let e = self.e.min(other.e);
        let a = shl_mag(&self.m.mag, (self.e - e) as u32);
        let b = shl_mag(&other.m.mag, (other.e - e) as u32);
        let m = if self.m.neg == other.m.neg {
            Big {
                neg: self.m.neg,
                mag: add_mag(&a, &b),
            }
        } else {
            match cmp_mag(&a, &b) {
                Ordering::Equal => Big::default(),
                Ordering::Greater => Big {
                    neg: self.m.neg,
                    mag: sub_mag(&a, &b),
                },
                Ordering::Less => Big {
                    neg: other.m.neg,
                    mag: sub_mag(&b, &a),
                },
            }
        };
        Dy { m, e }
    }

    pub fn sub(&self, other: &Dy) -> Dy {
        self.add(&other.neg())
    }

    pub fn mul(&self, other: &Dy) -> Dy {
        let mag = mul_mag(&self.m.mag, &other.m.mag);
        let neg = self.m.neg != other.m.neg && !mag.is_empty();
        Dy {
            m: Big { neg, mag },
            e: self.e + other.e,
        }
    }

    /// `self / other` as an f64 (within ~2 ulps), with no overflow of either on its own.
    pub fn ratio(&self, other: &Dy) -> f64 {
        assert!(other.sign() != 0);
        if self.sign() == 0 {
            return 0.0;
        }
        let ((ta, sa), (tb, sb)) = (top64(&self.m.mag), top64(&other.m.mag));
        let q = ta as f64 / tb as f64 * pow2(self.e + sa - other.e - sb);
        if self.m.neg != other.m.neg {
            -q
        } else {
            q
        }
    }

    /// Nearest-ish f64 (truncate to 64 bits, then round): within 1 ulp, enough for estimates.
    pub fn to_f64(&self) -> f64 {
        if self.sign() == 0 {
            return 0.0;
        }
        let (top, shift) = top64(&self.m.mag);
        let x = top as f64 * pow2(self.e + shift);
        if self.m.neg {
            -x
        } else {
            x
        }
    }
}

/// 2^n for any n (0 or inf beyond the range), by exact steps.
fn pow2(mut n: i32) -> f64 {
    let mut x = 1.0;
    while n > 1000 {
        x *= 2f64.powi(1000);
        n -= 1000;
    }
    while n < -1000 {
        x *= 2f64.powi(-1000);
        n += 1000;
    }
    x * 2f64.powi(n)
}

fn dot(a: &[Dy; 3], b: &[Dy; 3]) -> Dy {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

fn dy3(v: DVec3) -> [Dy; 3] {
    [Dy::from_f64(v.x), Dy::from_f64(v.y), Dy::from_f64(v.z)]
}

/// Total order of f64 as integers: adjacent floats have adjacent keys (+0 and -0 share 0).
pub fn key(x: f64) -> i64 {
    let b = x.to_bits() as i64;
    if b < 0 {
        -(b & i64::MAX)
    } else {
        b
    }
}

pub fn from_key(k: i64) -> f64 {
    if k < 0 {
        -f64::from_bits((-k) as u64)
    } else {
        f64::from_bits(k as u64)
    }
}

/// Adjacent `(lo, hi)` with `pred(lo)` false and `pred(hi)` true, given a monotone `pred` that
/// is false at `lo` and true at `hi` on entry.
fn bisect(mut lo: f64, mut hi: f64, pred: impl Fn(f64) -> bool) -> (f64, f64) {
    let (mut kl, mut kh) = (key(lo), key(hi));
    while (kh as i128) - (kl as i128) > 1 {
        let mid = from_key(((kl as i128 + kh as i128) / 2) as i64);
        if pred(mid) {
            (kh, hi) = (key(mid), mid);
        } else {
            (kl, lo) = (key(mid), mid);
        }
    }
    (lo, hi)
}

/// The line `o + t d` and the sphere `|x - c| = r`, in exact arithmetic.
pub struct Exact {
    f: [Dy; 3], // o - c, exact
    d: [Dy; 3],
    r2: Dy,
    a: Dy,      // d.d
    b: Dy,      // f.d
    cross2: Dy, // |f x d|^2
    /// `a r^2 - |f x d|^2`: a times (r^2 - squared distance from c to the line). By Lagrange's
    /// identity it equals `b^2 - a (f.f - r^2)`, the quadratic's quarter discriminant.
    disc: Dy,
}

impl Exact {
    pub fn new(o: DVec3, d: DVec3, c: DVec3, r: f64) -> Exact {
        let (o, c) = (dy3(o), dy3(c));
        let f = [o[0].sub(&c[0]), o[1].sub(&c[1]), o[2].sub(&c[2])];
        let d = dy3(d);
        let rr = Dy::from_f64(r);
        let r2 = rr.mul(&rr);
        let a = dot(&d, &d);
        let b = dot(&f, &d);
        let cross = [
            f[1].mul(&d[2]).sub(&f[2].mul(&d[1])),
            f[2].mul(&d[0]).sub(&f[0].mul(&d[2])),
            f[0].mul(&d[1]).sub(&f[1].mul(&d[0])),
        ];
        let cross2 = dot(&cross, &cross);
        let disc = a.mul(&r2).sub(&cross2);
        Exact {
            f,
            d,
            r2,
            a,
            b,
            cross2,
            disc,
        }
    }

    /// Whether the line meets the sphere (tangency counts as a hit).
    pub fn hits(&self) -> bool {
        self.disc.sign() >= 0
    }

    /// `(r - dist) / r` with `dist` the distance from the centre to the line: positive for a
    /// hit, to ~1e-16 relative (of itself).
    pub fn margin(&self) -> f64 {
        // x = disc / (a r^2) = 1 - dist^2/r^2 exactly; 1 - sqrt(1 - x) = x / (1 + sqrt(1 - x)).
        if self.r2.sign() == 0 {
            // A point sphere: on the line or not at all.
            return if self.hits() { 0.0 } else { f64::NEG_INFINITY };
        }
        let x = self.disc.ratio(&self.a.mul(&self.r2));
        x / (1.0 + (1.0 - x).max(0.0).sqrt())
    }

    /// Distance from the centre to the line (to ~1e-16 relative).
    pub fn distance(&self) -> f64 {
        self.cross2.ratio(&self.a).sqrt()
    }

    /// Half the chord in world length: `sqrt(disc / a)` (0 for a miss).
    pub fn half_chord(&self) -> f64 {
        self.disc.ratio(&self.a).max(0.0).sqrt()
    }

    /// `|d|`.
    pub fn d_len(&self) -> f64 {
        // sqrt(a) = sqrt(a / 2^2k) 2^k with 2^2k ~ a, so that a ~ 1e600 does not overflow.
        let k = (self.a.e + bit_len(&self.a.m.mag) as i32) / 2;
        let p = Dy {
            m: Big {
                neg: false,
                mag: vec![1],
            },
            e: 2 * k,
        };
        self.a.ratio(&p).sqrt() * pow2(k)
    }

    /// `|f + t d|^2 - r^2`, exact.
    pub fn g(&self, t: f64) -> Dy {
        let t = Dy::from_f64(t);
        let p = [
            self.f[0].add(&t.mul(&self.d[0])),
            self.f[1].add(&t.mul(&self.d[1])),
            self.f[2].add(&t.mul(&self.d[2])),
        ];
        dot(&p, &p).sub(&self.r2)
    }

    /// `|o + t d - c| - r`, the signed distance of the point at `t` from the surface (~1e-16
    /// relative), from the exact `g` as `g / (|f + t d| + r)` (no cancellation).
    pub fn surface_offset(&self, t: f64) -> f64 {
        let g = self.g(t).to_f64();
        let r2 = self.r2.to_f64();
        g / ((g + r2).max(0.0).sqrt() + r2.sqrt())
    }

    /// `t >= -b / a`: at or past the vertex (the closest point to the centre).
    fn past_vertex(&self, t: f64) -> bool {
        Dy::from_f64(t).mul(&self.a).add(&self.b).sign() >= 0
    }

    /// For each root (ascending), adjacent f64 `(lo, hi)` with `lo <= root <= hi`, or `(t, t)`
    /// when the root is exactly the f64 `t`. `None` for a miss.
    pub fn roots(&self) -> Option<[(f64, f64); 2]> {
        if !self.hits() {
            return None;
        }
        let inside = |t: f64| self.g(t).sign() <= 0;
        let (vl, vh) = bisect(-f64::MAX, f64::MAX, |t| self.past_vertex(t));
        let mid = if inside(vl) {
            vl
        } else if inside(vh) {
            vh
        } else {
            // The whole chord lies strictly between two adjacent floats.
            return Some([(vl, vh), (vl, vh)]);
        };
        let exact = |(lo, hi): (f64, f64), at: f64| {
            if self.g(at).sign() == 0 {
                (at, at)
            } else {
                (lo, hi)
            }
        };
        // g is decreasing before the vertex and increasing after it.
        let r0 = bisect(-f64::MAX, mid, inside);
        let r1 = bisect(mid, f64::MAX, |t| !inside(t));
        Some([exact(r0, r0.1), exact(r1, r1.0)])
    }
}

/// How far `t` lies outside the bracket `(lo, hi)`, in units of t (0 inside).
pub fn bracket_error(t: f64, (lo, hi): (f64, f64)) -> f64 {
    if t < lo {
        lo - t
    } else if t > hi {
        t - hi
    } else {
        0.0
    }
}

/// How many f64 steps `t` lies outside the bracket `(lo, hi)` (0 inside).
pub fn bracket_ulps(t: f64, (lo, hi): (f64, f64)) -> i64 {
    let (lo, hi, t) = (key(lo) as i128, key(hi) as i128, key(t) as i128);
    (lo - t).max(t - hi).clamp(0, i64::MAX as i128) as i64
}

/// Sanity checks of the oracle itself against closed forms.
#[test]
fn oracle_matches_closed_forms() {
    // Unit sphere, ray along z at x = 0.5: roots 10 -+ sqrt(0.75) = 10 -+ sqrt(3)/2.
    let o = DVec3::new(0.5, 0.0, -10.0);
    let e = Exact::new(o, DVec3::Z, DVec3::ZERO, 1.0);
    let [r0, r1] = e.roots().unwrap();
    let h = 3f64.sqrt() / 2.0; // correctly rounded sqrt, then exact halving
    assert!(bracket_ulps(10.0 - h, r0) <= 1 && bracket_ulps(10.0 + h, r1) <= 1);
    assert_eq!(r0.1, from_key(key(r0.0) + 1));
    assert!((e.margin() - 0.5).abs() < 1e-16 && (e.distance() - 0.5).abs() < 1e-16);
    // Exact roots are returned as points: 4 and 6.
    let e = Exact::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z, DVec3::ZERO, 1.0);
    assert_eq!(e.roots(), Some([(4.0, 4.0), (6.0, 6.0)]));
    // Tangent: a double root at t = 5, margin exactly 0.
    let e = Exact::new(DVec3::new(1.0, 0.0, -5.0), DVec3::Z, DVec3::ZERO, 1.0);
    assert_eq!(e.roots(), Some([(5.0, 5.0), (5.0, 5.0)]));
    assert_eq!(e.margin(), 0.0);
    // Just outside by 2^-52: a miss; just inside: a hit with margin 2^-60.
    let x = 1.0 + 2f64.powi(-52);
    assert!(!Exact::new(DVec3::new(x, 0.0, -5.0), DVec3::Z, DVec3::ZERO, 1.0).hits());
    let e = Exact::new(DVec3::new(1.0, 0.0, -5.0), DVec3::Z, DVec3::ZERO, x);
    assert!(e.hits() && (e.margin() / 2f64.powi(-52) - 1.0).abs() < 1e-12);
    // Bigint arithmetic far from 1: (2^600 + 1)^2 - 2^1200 - 2^601 = 1.
    let big = Dy::from_f64(2f64.powi(600));
    let one = Dy::from_f64(1.0);
    let s = big.add(&one);
    let v = s.mul(&s).sub(&big.mul(&big)).sub(&big.add(&big));
    assert_eq!(v.to_f64(), 1.0);
    assert_eq!(Dy::from_f64(f64::from_bits(1)).to_f64(), f64::from_bits(1));
    assert_eq!(Dy::from_f64(-f64::MAX).to_f64(), -f64::MAX);
}
