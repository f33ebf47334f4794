//! The measure of a union of regions that are intersections of caps (what triangles, Boxes
//! and the polyhedra about Cylinders and Cones block), exactly: [`covered_fraction_of_regions`]
//! (the boundary integrals, and how the boundary is found, are in `super`'s comment).

use glam::DVec3;

use super::{drop_held, held_by_far, meets, Circle, Meets, Regions, Weighting};
use crate::render::ao::cap::Cap;

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
    /// The caps not held by a larger one.
    caps: Vec<Circle>,
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
    // A cap or a region that a larger cap holds by far changes neither the union nor how
    // any other circle's pieces lie (whatever is inside it is inside that cap, whose circle
    // cuts where it would): left out first, at one dot product per pair. (On the Jmol
    // ball-and-stick export with no reach, 8 x 8 pixels in 2.3 s rather than 15.4 s.)
    s.caps.clear();
    s.caps.extend(
        caps.iter()
            .filter(|c| !below_horizon(n, c))
            .map(|c| Circle::new(c.axis, c.cos)),
    );
    drop_held(&mut s.caps, 0);
    for &c in &s.caps {
        s.starts.push(s.circles.len() as u32);
        s.cones.push((c.axis, c.cos, c.sin, c.angle));
        s.circles.push(c);
        s.corners.push(None);
    }
    for k in 0..regions.len() {
        let own = regions.region(k);
        if own.iter().any(|c| below_horizon(n, c)) {
            continue;
        }
        let b = regions.bound(k);
        let (sin, cos) = b.angle.sin_cos();
        if held_by_far(&s.caps, (b.axis, cos, sin, b.angle)) {
            continue;
        }
        s.starts.push(s.circles.len() as u32);
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
