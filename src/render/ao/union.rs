//! The measure of a union of caps within a hemisphere, exactly (docs/model.md section 11),
//! and of a union of regions that are intersections of caps (what triangles and Boxes block,
//! `super::polygon`).
//!
//! Both measures are boundary integrals. By Nusselt's analogue, the cosine-weighted measure of
//! a region `R` of the hemisphere about `n` is the area of its orthographic projection onto
//! the plane normal to `n`, which by Green's theorem in that plane is `(1/2)` times the line
//! integral of `n . (x × dx)` around the boundary of `R`, traversed with `R` on the left. Its
//! solid angle is, by Stokes' theorem, the line integral of `(1 - z) dψ` (`z = n . x`, `ψ` the
//! azimuth about `n`), a form whose derivative is the area element everywhere but at `-n`.
//!
//! The boundary of the union of caps within the hemisphere is made of arcs of circles: arcs
//! of the caps' boundary circles above the horizon and outside every other cap, and arcs of
//! the horizon inside some cap. Along an arc of a circle both integrals have closed forms, so
//! the measure is a finite sum:
//! - every circle is cut at its crossings with the other circles (the roots of
//!   `A cos φ + B sin φ = C` in its own angle `φ`);
//! - each piece between two crossings lies wholly inside or outside each other cap, so its
//!   midpoint decides whether it is part of the boundary;
//! - the pieces that are add their closed forms.
//!
//! Whether two circles cross, touch or nest is decided from their angular radii and the angle
//! between their axes, the same way for both, so that the two agree near a tangency.
//!
//! The work is quadratic in the number of caps that reach above the horizon, with a test per
//! piece against the caps that cross its circle.
//!
//! With regions ([`covered_fraction_of_regions`]) a circle's arc is part of the boundary
//! where it is inside its own region's other caps and outside every other region; circles
//! that coincide (a mesh's shared edges) are decided by their orientation, and the pieces by
//! the arcs between crossings rather than by testing a point (see there). Scenes of spheres
//! keep [`covered_fraction`], unchanged.

use glam::DVec3;

use super::cap::Cap;

/// One circle of the arrangement: a cap's boundary, or the horizon (a cap of angular radius
/// 90 degrees about the normal).
#[derive(Clone, Copy, Debug)]
struct Circle {
    axis: DVec3,
    cos: f64,
    sin: f64,
    /// The angular radius.
    angle: f64,
    /// `e1 × e2 = axis`: the circle is `cos axis + sin (cos φ e1 + sin φ e2)`, and `φ`
    /// increasing goes round it with its cap on the left.
    e1: DVec3,
    e2: DVec3,
}

impl Circle {
    fn new(axis: DVec3, cos: f64) -> Circle {
        let e1 = axis.any_orthonormal_vector();
        let sin = ((1.0 - cos) * (1.0 + cos)).max(0.0).sqrt();
        Circle {
            axis,
            cos,
            sin,
            angle: sin.atan2(cos),
            e1,
            e2: axis.cross(e1),
        }
    }

    fn at(&self, phi: f64) -> DVec3 {
        self.axis * self.cos + (self.e1 * phi.cos() + self.e2 * phi.sin()) * self.sin
    }

    /// The boundary integral of the chosen weighting along the circle from `φ0` to `φ1`
    /// (`φ0 <= φ1 <= φ0 + 2π`): its part of the covered measure, times `π` (cosine) or `2π`
    /// (uniform).
    fn integral(&self, w: Weighting, n: DVec3, phi0: f64, phi1: f64) -> f64 {
        match w {
            Weighting::Cosine => 0.5 * self.projected(n, phi0, phi1),
            Weighting::Uniform => self.solid(n, phi0, phi1),
        }
    }

    /// `∫ n . (x × dx)`, twice the projected area's part: with `x(φ)` as in [`Circle::at`],
    /// `x × dx = (sin² axis - cos sin (cos φ e1 + sin φ e2)) dφ`.
    fn projected(&self, n: DVec3, phi0: f64, phi1: f64) -> f64 {
        let (s0, c0) = phi0.sin_cos();
        let (s1, c1) = phi1.sin_cos();
        self.sin * self.sin * n.dot(self.axis) * (phi1 - phi0)
            - self.cos * self.sin * (n.dot(self.e1) * (s1 - s0) + n.dot(self.e2) * (c0 - c1))
    }

    /// `∫ (1 - z) dψ`, the solid angle's part, with `z = n . x` and `ψ` the azimuth about `n`
    /// (the form whose derivative is the area element everywhere but at `-n`, which no arc
    /// of the hemisphere reaches). Along the circle, `z = A + B cos u` with `u = φ - φ_n`
    /// (`A = cos (n . axis)`, `B = sin |n's part across the axis|`) and `(1 - z) dψ =
    /// n . (x × dx) / (1 + z) = (-cos + K / (a + B cos u)) du` with `K = n . axis + cos`,
    /// `a = 1 + A`. The last term's integral is `(2 / √(a² - B²))` times the angle the vector
    /// `(cos(u/2), k sin(u/2))`, `k = √((a - B) / (a + B))`, turns through, taken in one
    /// `atan2` so that it keeps its digits where the circle passes near `-n`.
    fn solid(&self, n: DVec3, phi0: f64, phi1: f64) -> f64 {
        let (n1, n2, na) = (n.dot(self.e1), n.dot(self.e2), n.dot(self.axis));
        let across = n1.hypot(n2);
        let phi_n = if across > 0.0 { n2.atan2(n1) } else { 0.0 };
        let (big_a, big_b) = (self.cos * na, self.sin * across);
        let a = 1.0 + big_a;
        let (lo, hi) = (a - big_b, a + big_b);
        let k = (lo / hi).sqrt();
        let (v0, v1) = (0.5 * (phi0 - phi_n), 0.5 * (phi1 - phi_n));
        let (s0, c0) = v0.sin_cos();
        let (s1, c1) = v1.sin_cos();
        // The half-angle swept from φ0 itself (not v1 - v0), so that its sine is not below 0
        // by rounding: the whole circle turns through π, not -π.
        let turn = (k * (0.5 * (phi1 - phi0)).sin()).atan2(c0 * c1 + k * k * s0 * s1);
        -self.cos * (phi1 - phi0) + (na + self.cos) * 2.0 * turn / (lo * hi).sqrt()
    }

    /// [`Circle::integral`] for circles of any kind, great circles through the normal too:
    /// the uniform weighting by [`Circle::solid_any`].
    fn integral_any(&self, w: Weighting, n: DVec3, phi0: f64, phi1: f64) -> f64 {
        match w {
            Weighting::Cosine => 0.5 * self.projected(n, phi0, phi1),
            Weighting::Uniform => self.solid_any(n, phi0, phi1),
        }
    }

    /// [`Circle::solid`] written so that it holds for every circle of the hemisphere, also
    /// one through `-n` (a great circle through the normal, as a triangle's edge may span):
    /// with `|n| = 1`, `a² - B² = K²` exactly, so that `√(a² - B²) = |K|` and
    /// `k = |K| / (a + B)`, and the last term is `sign(K) 2 turn`, which tends to 0 with `K`
    /// (the arc then runs along a meridian, where `dψ = 0`).
    fn solid_any(&self, n: DVec3, phi0: f64, phi1: f64) -> f64 {
        let (n1, n2, na) = (n.dot(self.e1), n.dot(self.e2), n.dot(self.axis));
        let across = n1.hypot(n2);
        let phi_n = if across > 0.0 { n2.atan2(n1) } else { 0.0 };
        let hi = 1.0 + self.cos * na + self.sin * across;
        let big_k = na + self.cos;
        let k = big_k.abs() / hi;
        let (v0, v1) = (0.5 * (phi0 - phi_n), 0.5 * (phi1 - phi_n));
        let (s0, c0) = v0.sin_cos();
        let (s1, c1) = v1.sin_cos();
        let turn = (k * (0.5 * (phi1 - phi0)).sin()).atan2(c0 * c1 + k * k * s0 * s1);
        -self.cos * (phi1 - phi0) + big_k.signum() * 2.0 * turn
    }

    /// Whether `x` is strictly inside this circle's cap.
    #[inline]
    fn holds(&self, x: DVec3) -> bool {
        self.axis.dot(x) > self.cos
    }
}

/// How circle `j` lies with respect to circle `i`.
enum Meets {
    /// They cross, at these two angles of circle `i`.
    Crosses(f64, f64),
    /// Circle `i` lies wholly inside cap `j`.
    Inside,
    /// Circle `i` lies wholly outside cap `j`.
    Outside,
    /// The same circle.
    Same,
    /// The same circle with the caps on either side (two great circles): the one a neighbour
    /// across a shared edge has.
    Opposite,
}

/// Two circles whose angular distances differ from a tangency by less than this (radians)
/// are taken as tangent, and circles closer than this as the same. The decision depends on
/// the pair alone, not on which of the two is cut, so that the two circles agree on it;
/// circles that do cross that near a tangency enclose a sliver of area below `1e-18`.
const TANGENT: f64 = 1e-13;

fn meets(i: &Circle, j: &Circle) -> Meets {
    // Far from every tangency, the cosine of the angle between the axes decides at once:
    // below cos(α_i + α_j) by a margin, the circles are apart; above cos(α_i - α_j), nested.
    let dot = i.axis.dot(j.axis);
    let (cc, ss) = (i.cos * j.cos, i.sin * j.sin);
    if dot < cc - ss - 1e-9 {
        return Meets::Outside;
    }
    if dot > cc + ss + 1e-9 {
        return if i.angle < j.angle {
            Meets::Inside
        } else {
            Meets::Outside
        };
    }
    let gap = i.axis.cross(j.axis).length().atan2(i.axis.dot(j.axis));
    let apart = (i.angle - j.angle).abs();
    if gap <= TANGENT && apart <= TANGENT {
        return Meets::Same;
    }
    if gap >= i.angle + j.angle - TANGENT {
        // Opposite axes and radii adding to π: the same circle, the caps on either side.
        let opposite = std::f64::consts::PI - gap <= TANGENT
            && (std::f64::consts::PI - i.angle - j.angle).abs() <= TANGENT;
        return if opposite {
            Meets::Opposite
        } else {
            Meets::Outside
        };
    }
    if gap <= apart + TANGENT {
        return if i.angle < j.angle {
            Meets::Inside
        } else {
            Meets::Outside
        };
    }
    // Along circle i, axis_j . x - cos_j = A cos φ + B sin φ - C.
    let a = i.sin * j.axis.dot(i.e1);
    let b = i.sin * j.axis.dot(i.e2);
    let c = j.cos - i.cos * j.axis.dot(i.axis);
    let mid = b.atan2(a);
    let half = (c / (a * a + b * b).sqrt()).clamp(-1.0, 1.0).acos();
    Meets::Crosses(mid - half, mid + half)
}

/// [`meets`] of circles `i` and `j` of `circles`, with the crossings of two circles
/// computed once for the pair: on the one of lower index, by [`meets`], and on the other as
/// the angles of those same points. Where two circles cross at a small angle `δ` their
/// crossings move by `ε / δ` with the rounding `ε` of their axes; the same points for both
/// keep the two arcs that end there meeting, so that what is lost is the area between them,
/// of order `ε`, not an arc of length `ε / δ`.
///
/// Two polygons' edges with a corner in common (the same vector) cross exactly there and
/// opposite it, whatever the rounding of their planes: many circles may pass through a
/// corner of a mesh, and all of them are cut at the same point. Two great circles more than
/// `1e-6` apart (most pairs of edges) cross at `± axis_lo × axis_hi`, found without
/// [`meets`]'s decisions of tangency, which only closer ones need.
fn meets_in(circles: &[Circle], corners: &[Option<[DVec3; 2]>], i: usize, j: usize) -> Meets {
    let (ci, cj) = (&circles[i], &circles[j]);
    if ci.cos == 0.0 && cj.cos == 0.0 {
        // Two great circles more than 1e-6 apart cross, at ± their axes' cross product (of
        // the pair in the order of their indices, the same bits for both): one angle to
        // find, and no tangency to decide.
        let (lo, hi) = if i < j { (ci, cj) } else { (cj, ci) };
        let cross = lo.axis.cross(hi.axis);
        let w = cross.length();
        if w > 1e-6 {
            let shared = match (corners[i], corners[j]) {
                (Some(a), Some(b)) => a.into_iter().find(|v| b.contains(v)),
                _ => None,
            };
            let u = match shared {
                Some(v) => v / v.length(),
                None => cross / w,
            };
            let phi = u.dot(ci.e2).atan2(u.dot(ci.e1));
            return Meets::Crosses(phi, phi + std::f64::consts::PI);
        }
    }
    let m = meets(ci, cj);
    if let (Meets::Crosses(..), Some(a), Some(b)) = (&m, corners[i], corners[j]) {
        if let Some(v) = a.into_iter().find(|v| b.contains(v)) {
            let ci = &circles[i];
            let u = v / v.length();
            let angle = |x: DVec3| x.dot(ci.e2).atan2(x.dot(ci.e1));
            return Meets::Crosses(angle(u), angle(-u));
        }
    }
    match m {
        Meets::Crosses(..) if j < i => {
            let (ci, cj) = (&circles[i], &circles[j]);
            let Meets::Crosses(p0, p1) = meets(cj, ci) else {
                // (The decision is the pair's: it crosses both ways.)
                return m;
            };
            let angle = |x: DVec3| x.dot(ci.e2).atan2(x.dot(ci.e1));
            Meets::Crosses(angle(cj.at(p0)), angle(cj.at(p1)))
        }
        _ => m,
    }
}

/// How directions are weighted in the measure of the covered part of the hemisphere.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Weighting {
    /// By the cosine to the normal, as light from a uniform sky reaches a diffuse surface;
    /// the usual definition of ambient occlusion.
    #[default]
    Cosine,
    /// Uniformly: the fraction of the hemisphere's solid angle.
    Uniform,
}

/// Reusable buffers.
#[derive(Default)]
pub struct UnionScratch {
    circles: Vec<Circle>,
    /// Per circle, the circles that cut it (their indices), in `cutters`.
    cutters: Vec<u32>,
    angles: Vec<f64>,
}

/// The fraction of the hemisphere about the unit normal `n` that the union of `caps` covers,
/// in `[0, 1]`, weighted by `w`: `(1/π) ∫ (n . w) dw` (cosine) or `(1/2π) ∫ dw` (uniform)
/// over the covered directions `w` of the hemisphere. Exact up to rounding.
pub fn covered_fraction(n: DVec3, caps: &[Cap], w: Weighting, s: &mut UnionScratch) -> f64 {
    s.circles.clear();
    s.circles.push(Circle::new(n, 0.0));
    for cap in caps {
        let (ca, sa) = (cap.axis.dot(n), cap.axis.cross(n).length());
        let sin = ((1.0 - cap.cos) * (1.0 + cap.cos)).max(0.0).sqrt();
        // Wholly below the horizon: the normal is outside it (θ > α) and its highest point,
        // at angle θ - α from the normal, has cos(θ - α) = cos θ cos α + sin θ sin α <= 0.
        if ca < cap.cos && ca * cap.cos + sa * sin <= 0.0 {
            continue;
        }
        s.circles.push(Circle::new(cap.axis, cap.cos));
    }
    let mut sum = 0.0;
    for i in 0..s.circles.len() {
        let ci = s.circles[i];
        s.cutters.clear();
        s.angles.clear();
        // A circle that another owns, that lies inside another cap or (a cap's) below the
        // horizon adds nothing; one that crosses the horizon is tested against it piece by
        // piece.
        let mut hidden = false;
        let mut owned = false;
        let mut crosses_horizon = false;
        for (j, cj) in s.circles.iter().enumerate() {
            if j == i {
                continue;
            }
            match meets(&ci, cj) {
                Meets::Crosses(p0, p1) => {
                    s.angles.push(p0);
                    s.angles.push(p1);
                    if j == 0 {
                        crosses_horizon = true;
                    } else {
                        s.cutters.push(j as u32);
                    }
                }
                // Inside another cap, a circle is hidden; inside the horizon's (wholly above
                // it), a cap circle is whole.
                Meets::Inside => hidden |= j > 0,
                // Outside the horizon's cap (wholly below it), a cap circle is gone. (Caps'
                // circles are opposite only when both are great circles, in which case each
                // is outside the other cap but for the circle itself.)
                Meets::Outside | Meets::Opposite => hidden |= j == 0,
                Meets::Same if i == 0 => owned = true,
                // The first of two equal circles is the boundary.
                Meets::Same => hidden |= j < i,
            }
        }
        if i == 0 && owned {
            // The horizon is the boundary of a cap that covers the hemisphere.
            return 1.0;
        }
        if hidden || (i == 0 && s.cutters.is_empty()) {
            continue;
        }
        if s.angles.is_empty() {
            // A whole cap circle above the horizon, crossing no other.
            sum += ci.integral(w, n, 0.0, std::f64::consts::TAU);
            continue;
        }
        // The pieces between crossings, in order round the circle.
        for a in s.angles.iter_mut() {
            *a = a.rem_euclid(std::f64::consts::TAU);
        }
        s.angles.sort_unstable_by(f64::total_cmp);
        let m = s.angles.len();
        for k in 0..m {
            let p0 = s.angles[k];
            let p1 = if k + 1 < m {
                s.angles[k + 1]
            } else {
                s.angles[0] + std::f64::consts::TAU
            };
            if p1 <= p0 {
                continue;
            }
            let x = ci.at(0.5 * (p0 + p1));
            let in_a_cap = s.cutters.iter().any(|&j| s.circles[j as usize].holds(x));
            let on_boundary = if i == 0 {
                in_a_cap
            } else {
                !in_a_cap && (!crosses_horizon || n.dot(x) > 0.0)
            };
            if on_boundary {
                sum += ci.integral(w, n, p0, p1);
            }
        }
    }
    let whole = match w {
        Weighting::Cosine => std::f64::consts::PI,
        Weighting::Uniform => std::f64::consts::TAU,
    };
    (sum / whole).clamp(0.0, 1.0)
}

/// Regions of directions that are intersections of caps, as a flat polygon blocks them
/// (`super::polygon`): each region's caps, region after region, and a cone that holds it.
#[derive(Clone, Debug, Default)]
pub struct Regions {
    /// The regions' caps, region after region.
    caps: Vec<Cap>,
    /// Per cap, the two corners (relative to the point) of the polygon's edge whose plane
    /// through the point bounds it, if it is an edge's.
    corners: Vec<Option<[DVec3; 2]>>,
    /// Where each region's caps end in `caps`.
    ends: Vec<u32>,
    /// Per region, a cone holding it.
    bounds: Vec<Cone>,
}

/// A cone of directions: those within `angle` (radians, up to π) of the unit `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Its axis, a unit vector.
    pub axis: DVec3,
    /// Its angular radius, in `[0, π]`.
    pub angle: f64,
}

impl Regions {
    /// No regions.
    pub fn clear(&mut self) {
        self.caps.clear();
        self.corners.clear();
        self.ends.clear();
        self.bounds.clear();
    }

    /// How many regions.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// The caps of region `k`, whose intersection it is.
    pub fn region(&self, k: usize) -> &[Cap] {
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        &self.caps[start..self.ends[k] as usize]
    }

    /// The corners of the edges of region `k`'s caps, as [`Regions::push`] took them.
    pub fn corners(&self, k: usize) -> &[Option<[DVec3; 2]>] {
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        &self.corners[start..self.ends[k] as usize]
    }

    /// Region `k`'s cone.
    pub fn bound(&self, k: usize) -> Cone {
        self.bounds[k]
    }

    /// Adds the region that is the intersection of `caps` (at least one), held by `bound`;
    /// with each cap, the corners of the polygon's edge it is the plane of, if any (two
    /// edges with a corner in common, the same vector, cross exactly there).
    pub fn push(&mut self, caps: impl IntoIterator<Item = (Cap, Option<[DVec3; 2]>)>, bound: Cone) {
        for (cap, corners) in caps {
            self.caps.push(cap);
            self.corners.push(corners);
        }
        self.ends.push(self.caps.len() as u32);
        self.bounds.push(bound);
    }

    /// Keeps the first `len` regions.
    pub fn truncate(&mut self, len: usize) {
        if len < self.ends.len() {
            let caps = if len == 0 {
                0
            } else {
                self.ends[len - 1] as usize
            };
            self.caps.truncate(caps);
            self.corners.truncate(caps);
            self.ends.truncate(len);
            self.bounds.truncate(len);
        }
    }

    /// Removes region `k`.
    pub fn remove(&mut self, k: usize) {
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        let end = self.ends[k] as usize;
        self.caps.drain(start..end);
        self.corners.drain(start..end);
        self.ends.remove(k);
        for e in &mut self.ends[k..] {
            *e -= (end - start) as u32;
        }
        self.bounds.remove(k);
    }

    /// Keeps the regions for which `keep(caps, cone)` holds, in order.
    pub fn retain(&mut self, mut keep: impl FnMut(&[Cap], Cone) -> bool) {
        let (mut caps, mut start, mut kept) = (0, 0, 0);
        for k in 0..self.ends.len() {
            let end = self.ends[k] as usize;
            if keep(&self.caps[start..end], self.bounds[k]) {
                self.caps.copy_within(start..end, caps);
                self.corners.copy_within(start..end, caps);
                caps += end - start;
                self.ends[kept] = caps as u32;
                self.bounds[kept] = self.bounds[k];
                kept += 1;
            }
            start = end;
        }
        self.caps.truncate(caps);
        self.corners.truncate(caps);
        self.ends.truncate(kept);
        self.bounds.truncate(kept);
    }
}

/// The part of circle `i` inside the cap of a circle `j` that crosses it: the arc from
/// `start` counter-clockwise (`φ` increasing) to `end`, angles of circle `i` in `[0, 2π)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Arc {
    start: f64,
    end: f64,
}

impl Arc {
    /// The arc between the crossings `q0`, `q1` of circle `ci` with circle `cj` that lies
    /// inside cap `j`: of the two arcs, the one whose middle is farther inside it. (The
    /// distance to circle `j` along circle `i` is a sinusoid whose largest value is at the
    /// middle of the arc inside, its smallest at the middle of the other: the choice keeps its
    /// digits however close the circles are, where a test of a point near a crossing would
    /// not.)
    fn inside(ci: &Circle, cj: &Circle, q0: f64, q1: f64) -> Arc {
        use std::f64::consts::TAU;
        let (q0, q1) = (q0.rem_euclid(TAU), q1.rem_euclid(TAU));
        let q1_after = if q1 < q0 { q1 + TAU } else { q1 };
        let mid = 0.5 * (q0 + q1_after);
        // At `mid` and `mid + π` the depths inside cap j are `A ± sin_i (axis_j . r)`, `r` the
        // circle's radial direction at `mid`: the sign of the second term decides.
        let (s, c) = mid.sin_cos();
        let r = ci.e1 * c + ci.e2 * s;
        if cj.axis.dot(r) >= 0.0 {
            Arc { start: q0, end: q1 }
        } else {
            Arc { start: q1, end: q0 }
        }
    }

    /// Whether the angle `phi` (in `[0, 2π)`) is on the arc.
    #[inline]
    fn holds(&self, phi: f64) -> bool {
        if self.start <= self.end {
            self.start <= phi && phi < self.end
        } else {
            phi >= self.start || phi < self.end
        }
    }
}

/// The part of a circle that its region's other caps hold.
enum Span {
    /// None of it.
    Empty,
    /// All of it, or parts that are not one arc (then all of it is looked at).
    Whole,
    /// The arc from angle `.0` counter-clockwise through `.1` radians.
    Arc(f64, f64),
}

impl Span {
    /// The intersection of `arcs` (each the part of the circle inside one cap).
    fn of(arcs: &[Arc]) -> Span {
        use std::f64::consts::TAU;
        let (mut lo, mut len) = (0.0, TAU);
        for a in arcs {
            let la = (a.end - a.start).rem_euclid(TAU);
            if len == TAU {
                (lo, len) = (a.start, la);
                continue;
            }
            // The arc as offsets from `lo`: [d, d + la], and its turn round, [d - 2π, ..].
            let d = (a.start - lo).rem_euclid(TAU);
            let first = (d < len).then(|| (d, (d + la).min(len)));
            let wrapped = (d + la > TAU).then(|| (0.0, (d + la - TAU).min(len)));
            match (first, wrapped) {
                (Some((o0, o1)), None) | (None, Some((o0, o1))) => {
                    lo = (lo + o0).rem_euclid(TAU);
                    len = o1 - o0;
                }
                (None, None) => return Span::Empty,
                (Some(_), Some(_)) => return Span::Whole,
            }
            if len <= 0.0 {
                return Span::Empty;
            }
        }
        if len >= TAU {
            Span::Whole
        } else {
            Span::Arc(lo, len)
        }
    }
}

/// How the points of circle `i` lie with respect to a cap `j` that matters to them.
#[derive(Clone, Copy, Debug, PartialEq)]
enum On {
    /// Circle `j` crosses circle `i`: inside cap `j` on this arc.
    Crossing(Arc),
    /// On the same circle with cap `j` on the same side (the left of `i`).
    Same,
    /// On the same circle with cap `j` on the other side.
    Opposite,
}

/// The buffers of [`covered_fraction_of_regions`].
#[derive(Default)]
pub struct RegionScratch {
    circles: Vec<Circle>,
    /// Per circle, the corners of the polygon's edge it holds, if any.
    corners: Vec<Option<[DVec3; 2]>>,
    /// Per region, its first circle in `circles` (and one past the last region's).
    starts: Vec<u32>,
    /// Per region, its cone: axis, cosine and sine of its radius, the radius.
    cones: Vec<(DVec3, f64, f64, f64)>,
    /// Per region, the regions whose cones meet its own, in `near[near_starts[k]..]`.
    near: Vec<u32>,
    near_starts: Vec<u32>,
    /// The regions that reach the horizon.
    low: Vec<u32>,
    /// For the circle being cut: the arcs inside its own region's other caps (and the
    /// horizon's) that cross it.
    own: Vec<Arc>,
    /// How the caps of other regions that matter lie along it, region by region, and per
    /// region `(region, end in entries)`.
    entries: Vec<On>,
    groups: Vec<(u32, u32)>,
    /// The crossing angles of a region being looked at, kept until it is known to matter.
    pending: Vec<f64>,
    angles: Vec<f64>,
}

/// Whether the cap `cap`, seen from the hemisphere about `n`, lies wholly below its horizon
/// (touching it at most at a point).
fn below_horizon(n: DVec3, cap: &Cap) -> bool {
    let (ca, sa) = (cap.axis.dot(n), cap.axis.cross(n).length());
    let sin = ((1.0 - cap.cos) * (1.0 + cap.cos)).max(0.0).sqrt();
    ca < cap.cos && ca * cap.cos + sa * sin <= 0.0
}

/// [`covered_fraction`] of the union of `caps` and `regions` (each the intersection of its
/// caps): exact up to rounding, by the same boundary integrals.
///
/// The boundary of the union within the hemisphere is made of the arcs of each region's
/// circles that lie inside the region's other caps (the horizon's among them) and outside
/// every other region, and of the arcs of the horizon inside some region. Each circle is cut
/// at its crossings with its own region's circles and with those of the regions whose cones
/// meet its region's (no other region can change what is inside its region). Each piece is
/// decided by the arcs it lies on: for each cap that crosses the circle, the arc between the
/// two crossings that is inside it (`Arc::inside`), so that the pieces and their tests agree
/// to the last digit however closely two circles run. A circle that coincides with another
/// (regions sharing an edge) is decided without a test: when the other region is on the
/// other side of the shared circle, the arc is inside the union and neither counts it; on
/// the same side, the first region owns it. A circle that coincides with the horizon is the
/// horizon's.
pub fn covered_fraction_of_regions(
    n: DVec3,
    caps: &[Cap],
    regions: &Regions,
    w: Weighting,
    s: &mut RegionScratch,
) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    s.circles.clear();
    s.corners.clear();
    s.starts.clear();
    s.cones.clear();
    s.circles.push(Circle::new(n, 0.0));
    s.corners.push(None);
    for cap in caps {
        if below_horizon(n, cap) {
            continue;
        }
        s.starts.push(s.circles.len() as u32);
        let c = Circle::new(cap.axis, cap.cos);
        s.cones.push((c.axis, c.cos, c.sin, c.angle));
        s.circles.push(c);
        s.corners.push(None);
    }
    for k in 0..regions.len() {
        let own = regions.region(k);
        if own.iter().any(|c| below_horizon(n, c)) {
            continue;
        }
        s.starts.push(s.circles.len() as u32);
        let b = regions.bound(k);
        let (sin, cos) = b.angle.sin_cos();
        s.cones.push((b.axis, cos, sin, b.angle));
        s.circles
            .extend(own.iter().map(|c| Circle::new(c.axis, c.cos)));
        s.corners.extend_from_slice(regions.corners(k));
    }
    let count = s.starts.len();
    s.starts.push(s.circles.len() as u32);
    // Which cones meet: their axes closer than their radii together (with a margin).
    s.near.clear();
    s.near_starts.clear();
    s.low.clear();
    for a in 0..count {
        s.near_starts.push(s.near.len() as u32);
        let (axis, ca, sa, angle) = s.cones[a];
        for b in 0..count {
            if b == a {
                continue;
            }
            let (bx, cb, sb, bangle) = s.cones[b];
            if angle + bangle >= PI || axis.dot(bx) >= ca * cb - sa * sb - 1e-9 {
                s.near.push(b as u32);
            }
        }
        // Reaching the horizon: the axis's angle from the normal and the radius at least 90°.
        let from_n = axis.cross(n).length().atan2(axis.dot(n));
        if from_n + angle >= FRAC_PI_2 - 1e-9 {
            s.low.push(a as u32);
        }
    }
    s.near_starts.push(s.near.len() as u32);
    let region_of = |starts: &[u32], i: usize| -> usize {
        // The last region starting at or before circle i.
        starts.partition_point(|&st| st as usize <= i) - 1
    };
    let mut sum = 0.0;
    for i in 0..s.circles.len() {
        let ci = s.circles[i];
        s.own.clear();
        s.entries.clear();
        s.groups.clear();
        s.angles.clear();
        let k = if i == 0 {
            usize::MAX
        } else {
            region_of(&s.starts, i)
        };
        // The regions whose caps decide the pieces: all that reach the horizon, for the
        // horizon; those near its own, for a region's circle.
        let others: &[u32] = if i == 0 {
            &s.low
        } else {
            // The horizon and the region's own circles bound its part of the circle.
            let mut skip = false;
            for j in std::iter::once(0).chain(s.starts[k] as usize..s.starts[k + 1] as usize) {
                if j == i {
                    continue;
                }
                match meets_in(&s.circles, &s.corners, i, j) {
                    Meets::Crosses(p0, p1) => {
                        s.angles.push(p0);
                        s.angles.push(p1);
                        s.own.push(Arc::inside(&ci, &s.circles[j], p0, p1));
                    }
                    Meets::Inside => {}
                    // Below the horizon or on it (where the horizon is the boundary), outside
                    // another of its caps, or a sliver between two opposite circles: the
                    // region has nothing along this circle.
                    Meets::Outside | Meets::Opposite => skip = true,
                    Meets::Same if j == 0 => skip = true,
                    // The same circle twice in a region: the first is the boundary.
                    Meets::Same => skip |= j < i,
                }
            }
            if skip {
                continue;
            }
            &s.near[s.near_starts[k] as usize..s.near_starts[k + 1] as usize]
        };
        // The part of the circle its own region can hold: one arc for a great circle (each
        // of its own caps holds half of it or less), and a cone about it that holds the arc.
        let span = if i == 0 || ci.cos != 0.0 {
            Span::Whole
        } else {
            Span::of(&s.own)
        };
        let (lo, len) = match span {
            Span::Empty => continue,
            Span::Whole => (0.0, TAU),
            Span::Arc(lo, len) => (lo, len),
        };
        let (centre, rho) = if len < TAU {
            (ci.at(lo + 0.5 * len), (ci.sin * 0.5 * len + 1e-9).min(PI))
        } else {
            (ci.axis, PI)
        };
        let (rho_sin, rho_cos) = rho.sin_cos();
        let mut inside_one = false;
        for &r in others {
            let r = r as usize;
            if rho < PI {
                // A region whose cone misses the arc's cannot change it.
                let (axis, cr, sr, angle) = s.cones[r];
                if rho + angle < PI && centre.dot(axis) < rho_cos * cr - rho_sin * sr - 1e-9 {
                    continue;
                }
            }
            let (from, to) = (s.starts[r] as usize, s.starts[r + 1] as usize);
            let mark = s.entries.len();
            s.pending.clear();
            let mut out = false;
            for j in from..to {
                let cj = &s.circles[j];
                if rho < FRAC_PI_2 && cj.cos == 0.0 {
                    // Two great circles that cross nowhere near the arc (their crossings,
                    // the directions of ± axis_i × axis_j, outside its cone): the arc lies on
                    // one side of circle j, which the arc's middle tells.
                    let cross = ci.axis.cross(cj.axis);
                    let w = cross.length();
                    if w > 1e-6 && centre.dot(cross).abs() < rho_cos * w {
                        let side = cj.axis.dot(centre);
                        if side > 1e-9 {
                            continue;
                        }
                        if side < -1e-9 {
                            out = true;
                            break;
                        }
                    }
                }
                match meets_in(&s.circles, &s.corners, i, j) {
                    Meets::Crosses(p0, p1) => {
                        s.pending.push(p0);
                        s.pending.push(p1);
                        s.entries.push(On::Crossing(Arc::inside(&ci, cj, p0, p1)));
                    }
                    Meets::Inside => {}
                    Meets::Same => s.entries.push(On::Same),
                    // On the horizon, a region on the other side of it holds none of it.
                    Meets::Opposite if i == 0 => {
                        out = true;
                        break;
                    }
                    Meets::Opposite => s.entries.push(On::Opposite),
                    Meets::Outside => {
                        out = true;
                        break;
                    }
                }
            }
            if out {
                s.entries.truncate(mark);
                continue;
            }
            if i != 0 && s.entries.len() == mark {
                // Wholly inside region r (where the circle is its region's).
                inside_one = true;
                break;
            }
            s.angles.extend_from_slice(&s.pending);
            s.groups.push((r as u32, s.entries.len() as u32));
        }
        if inside_one || (i == 0 && s.groups.is_empty()) {
            continue;
        }
        // The pieces between crossings within the span, in order round the circle (the whole
        // circle if nothing crosses it): as offsets from its start.
        s.angles.retain_mut(|a| {
            *a = (*a - lo).rem_euclid(TAU);
            *a < len
        });
        s.angles.sort_unstable_by(f64::total_cmp);
        let m = s.angles.len();
        let pieces = if len < TAU { m + 1 } else { m.max(1) };
        for piece in 0..pieces {
            let (o0, o1) = if len < TAU {
                (
                    if piece == 0 { 0.0 } else { s.angles[piece - 1] },
                    if piece == m { len } else { s.angles[piece] },
                )
            } else if m == 0 {
                (0.0, TAU)
            } else {
                let o0 = s.angles[piece];
                let o1 = if piece + 1 < m {
                    s.angles[piece + 1]
                } else {
                    s.angles[0] + TAU
                };
                (o0, o1)
            };
            if o1 <= o0 {
                continue;
            }
            let (p0, p1) = (lo + o0, lo + o1);
            let mid = (0.5 * (p0 + p1)).rem_euclid(TAU);
            let on_boundary = if i == 0 {
                // Inside some region (on its side of a circle it shares with the horizon).
                let mut start = 0;
                s.groups.iter().any(|&(_, end)| {
                    let group = &s.entries[start..end as usize];
                    start = end as usize;
                    group.iter().all(|on| match on {
                        On::Crossing(arc) => arc.holds(mid),
                        On::Same => true,
                        On::Opposite => false,
                    })
                })
            } else {
                s.own.iter().all(|arc| arc.holds(mid)) && {
                    let mut start = 0;
                    !s.groups.iter().any(|&(r, end)| {
                        let group = &s.entries[start..end as usize];
                        start = end as usize;
                        hides(group, mid, r as usize, k)
                    })
                }
            };
            if on_boundary {
                sum += ci.integral_any(w, n, p0, p1);
            }
        }
    }
    let whole = match w {
        Weighting::Cosine => PI,
        Weighting::Uniform => TAU,
    };
    (sum / whole).clamp(0.0, 1.0)
}

/// Whether region `r`, whose caps that matter along a circle of region `k` are `group`,
/// makes the point at angle `phi` of it no part of the boundary: the point inside it, or on
/// a circle it shares with the other region on the other side, or on the same side when `r`
/// comes first.
fn hides(group: &[On], phi: f64, r: usize, k: usize) -> bool {
    let (mut same, mut opposite) = (false, false);
    for on in group {
        match on {
            On::Crossing(arc) => {
                if !arc.holds(phi) {
                    return false;
                }
            }
            On::Same => same = true,
            On::Opposite => opposite = true,
        }
    }
    match (same, opposite) {
        (false, false) => true,
        (false, true) => true,
        (true, false) => r < k,
        // A sliver of no width.
        (true, true) => false,
    }
}
