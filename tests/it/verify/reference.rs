//! The independent reference: the radiance along one camera ray by brute force over every
//! primitive, written from docs/model.md alone.
//!
//! - Opaque hits: the textbook ray/sphere roots and `surface_reference` for the other
//!   surfaces; the nearest front face (a triangle from either side) is seen.
//! - Surfaces: the VRML97 lighting equation with shadows (docs/model.md section 2).
//! - Gas: the camera-ray integral of docs/model.md section 3, on pieces between sphere events (and
//!   a linear profile's closest approach). Inside a piece every light's *state signature*
//!   (in its radius or not, which side of its attenuation corner, and for every primitive
//!   whether the light ray meets it) is sampled on a grid of [`GRID`] points and every change
//!   bisected to [`BISECT`] relative, so each sub-piece is smooth; there the integrand
//!   `T(0,t) [sum sigma_j C_j + p sum sigma_j a_j sum_i E_i]` is integrated by adaptive
//!   Gauss-Kronrod to [`REL`] relative. Transmittances are `exp(-tau)` with tau from chord
//!   lengths (constant gas) or adaptive quadrature of the density (profiled gas, to
//!   [`CHORD_REL`]).
//!
//! Stated accuracy: each pixel to its reported `err` (the sum of the quadrature's
//! |Kronrod - Gauss| estimates, an over-estimate for smooth pieces) plus ~1e-12 relative
//! from the chords and rounding; `reference_matches_closed_forms` checks this.

use glam::DVec3;

use super::quad;
use super::scenes::{Profile, Rgb};
use super::world::{Gas, LightKind, Line, Prim, Solid, World};
use crate::surface_reference::{blocks_from, first_hit, RefShape};

mod breakpoints;
pub mod gas_depth;

/// Grid points per gas piece at which the light states are sampled.
pub const GRID: usize = 64;
/// Points sampled inside each interval where a light's line meets a primitive's bounding
/// sphere (where a shadow narrower than the grid's step can lie).
pub const EXTRA: usize = 8;
/// Ratio of successive cuts towards a breakpoint where a light's line grazes a gas sphere
/// ([`World::graded`]).
pub const GRADE: f64 = 4.0;
/// Relative resolution to which a light-state change along the ray is bisected.
pub const BISECT: f64 = 1e-14;
/// Relative tolerance of the camera-ray quadrature.
pub const REL: f64 = 1e-10;
/// Relative tolerance of a profiled chord's optical depth.
pub const CHORD_REL: f64 = 1e-12;
/// The isotropic phase function.
const P: f64 = 1.0 / (4.0 * std::f64::consts::PI);

/// The reference value of one camera ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct RayRef {
    pub value: Rgb,
    /// The single-scattering part of `value` (what Monte Carlo samples).
    pub scatter: Rgb,
    /// Bound on the quadrature's error (absolute, any channel).
    pub err: f64,
    /// `1 - T` of the gas in front of the first opaque hit (or of all the gas).
    pub opacity: f64,
    /// The length of the ray inside gas (up to the first opaque hit).
    pub gas_length: f64,
}

/// Ray/sphere roots `t0 <= t1` of `o + t w` (`w` unit), from the distance of the centre to
/// the line (no cancellation near tangency).
pub fn sphere_roots(c: DVec3, r: f64, o: DVec3, w: DVec3) -> Option<(f64, f64)> {
    let tc = (c - o).dot(w);
    let d2 = (o + tc * w - c).length_squared();
    let h2 = r * r - d2;
    if h2 < 0.0 {
        return None;
    }
    let h = h2.sqrt();
    Some((tc - h, tc + h))
}

/// An opaque hit seen by a camera ray: its parameter, the primitive (index in
/// `World::prims`) and the unit normal on the side the ray came from.
pub struct Hit {
    pub t: f64,
    pub k: usize,
    pub n: DVec3,
}

/// What a light is at a point: unit direction to it, distance (infinite for directional),
/// whether it reaches (radius), attenuation, colour times intensity, ambient intensity.
struct AtPoint {
    l: DVec3,
    dist: f64,
    reach: bool,
    corner: bool,
    att: f64,
    ci: Rgb,
    ambient: f64,
    color: Rgb,
}

impl World {
    fn light_at(&self, kind: &LightKind, x: DVec3) -> Option<AtPoint> {
        match *kind {
            LightKind::Point(p) => {
                if !p.on {
                    return None;
                }
                let v = p.location - x;
                let d = v.length();
                let q = p.attenuation.x + p.attenuation.y * d + p.attenuation.z * d * d;
                Some(AtPoint {
                    l: v / d,
                    dist: d,
                    reach: d <= p.radius,
                    corner: q > 1.0,
                    att: 1.0 / q.max(1.0),
                    ci: p.color.map(|c| c * p.intensity),
                    ambient: p.ambient,
                    color: p.color,
                })
            }
            LightKind::Directional(dl) => {
                if !dl.on {
                    return None;
                }
                Some(AtPoint {
                    l: -dl.direction,
                    dist: f64::INFINITY,
                    reach: true,
                    corner: false,
                    att: 1.0,
                    ci: dl.color.map(|c| c * dl.intensity),
                    ambient: dl.ambient,
                    color: dl.color,
                })
            }
            LightKind::Head => Some(AtPoint {
                l: -self.eye.forward,
                dist: f64::INFINITY,
                reach: true,
                corner: false,
                att: 1.0,
                ci: [1.0; 3],
                ambient: 0.0,
                color: [1.0; 3],
            }),
        }
    }

    /// Whether the segment `x + s l`, `0 < s < dist`, is blocked by opaque primitive `k`;
    /// `on_surface`: `x` is a surface's shading point, and crossings within 1e-9 of it are
    /// its own rounding (a gas point has no such room: one just in front of a surface is
    /// shadowed by it, not lit through a sliver at the camera ray's hit).
    fn blocked_by(&self, k: usize, x: DVec3, l: DVec3, dist: f64, on_surface: bool) -> bool {
        // A light exactly on a surface: its tangent plane, decided with room for rounding.
        let end = if dist.is_finite() {
            dist * (1.0 - 1e-9)
        } else {
            f64::INFINITY
        };
        match self.prims[k].solid {
            // A shadow ray is blocked by a sphere it enters between the point and the light.
            Solid::Sphere { c, r } => {
                // A point light on the sphere (to within the rounding of its coordinates):
                // the tangent plane there decides, not the entry root, whose rounding near
                // the plane (~ulp(r^2) / h, the half-chord h -> 0) outgrows the 1e-9 room and
                // shadowed a wedge beside the plane (seed 238).
                if dist.is_finite() && on_sphere(x + dist * l, c, r) {
                    let n = x + dist * l - c;
                    return (x - c).length_squared() > r * r && (x - c).dot(n) < n.dot(n);
                }
                sphere_roots(c, r, x, l).is_some_and(|(t0, _)| t0 > 0.0 && t0 < end)
            }
            Solid::Surface { shape, to_world } => {
                let smin = if on_surface { 1e-9 } else { 0.0 };
                blocks_from(&shape, &to_world, x, l, smin, end)
            }
        }
    }

    /// The part of `x + s l`, `0 <= s <= dist`, inside gas sphere `g`.
    fn chord(g: &Gas, x: DVec3, l: DVec3, dist: f64) -> Option<(f64, f64)> {
        let (t0, t1) = sphere_roots(g.c, g.r, x, l)?;
        let (a, b) = (t0.max(0.0), t1.min(dist));
        (b > a).then_some((a, b))
    }

    /// Optical depth of gas `g` along `x + s l`, `s` in [a, b] (inside the sphere).
    pub fn depth(g: &Gas, x: DVec3, l: DVec3, a: f64, b: f64) -> f64 {
        if g.m.profile == Profile::Constant {
            return g.sigma0 * (b - a);
        }
        // Split at the closest approach to the centre (the linear profile's kink).
        let line = g.line(x, l);
        let sc = line.sc;
        let f = |s: f64| g.sigma_on(&line, s);
        if sc > a && sc < b {
            quad::scalar(f, a, sc, CHORD_REL) + quad::scalar(f, sc, b, CHORD_REL)
        } else {
            quad::scalar(f, a, b, CHORD_REL)
        }
    }

    /// V: 0 behind an opaque primitive, else the transmittance of the gas on the way.
    fn visibility(&self, x: DVec3, l: DVec3, dist: f64, skip: Option<usize>) -> f64 {
        let mut tau = 0.0;
        for (k, p) in self.prims.iter().enumerate() {
            if Some(k) == skip {
                continue;
            }
            match p.gas() {
                Some(g) => {
                    if let Some((a, b)) = Self::chord(&g, x, l, dist) {
                        tau += Self::depth(&g, x, l, a, b);
                    }
                }
                None => {
                    if self.blocked_by(k, x, l, dist, skip.is_some()) {
                        return 0.0;
                    }
                }
            }
        }
        (-tau).exp()
    }

    /// The state of light `li` at gas point `x`: where it changes, the integrand jumps or
    /// has a kink.
    fn signature(&self, li: usize, x: DVec3, out: &mut Vec<bool>) {
        let Some(a) = self.light_at(&self.lights[li].kind, x) else {
            return;
        };
        out.push(a.reach);
        out.push(a.corner);
        if matches!(self.lights[li].kind, LightKind::Head) && self.head_viewer_carried {
            return;
        }
        for (k, p) in self.prims.iter().enumerate() {
            out.push(match p.gas() {
                Some(g) => Self::chord(&g, x, a.l, a.dist).is_some(),
                None => self.blocked_by(k, x, a.l, a.dist, false),
            });
        }
    }

    /// The (light, gas sphere) pairs whose line from `x` meets the sphere.
    fn gas_signature(&self, x: DVec3) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (li, light) in self.lights.iter().enumerate() {
            if matches!(light.kind, LightKind::Head) && self.head_viewer_carried {
                continue;
            }
            let Some(a) = self.light_at(&light.kind, x) else {
                continue;
            };
            for (k, p) in self.prims.iter().enumerate() {
                if let Some(g) = p.gas() {
                    if Self::chord(&g, x, a.l, a.dist).is_some() {
                        out.push((li, k));
                    }
                }
            }
        }
        out
    }

    /// The largest optical depth at `x` along the lines of the (light, gas sphere) `pairs`.
    fn graze_depth(&self, pairs: &[(usize, usize)], x: DVec3) -> f64 {
        let mut most = 0.0f64;
        for &(li, k) in pairs {
            let (Some(a), Some(g)) = (self.light_at(&self.lights[li].kind, x), self.prims[k].gas())
            else {
                continue;
            };
            if let Some((s0, s1)) = Self::chord(&g, x, a.l, a.dist) {
                most = most.max(Self::depth(&g, x, a.l, s0, s1));
            }
        }
        most
    }

    /// Cuts of [s0, s1] (of the camera ray `o + t w`) shrinking geometrically by [`GRADE`]
    /// towards each end where a light's line grazes gas spheres (`ends`: the pairs). There the
    /// light's transmittance is `exp(-sigma * chord)` with the chord growing as the square
    /// root of the distance from the end: in dense gas all that light arrives in a layer far
    /// thinner than the piece, which no node of a rule over the whole piece sees (the rule
    /// then converges, wrongly, on the light's absence). The cuts go on until the grazed
    /// depth at a cut is below 1 (the cut lies in the layer), and two more.
    fn graded(
        &self,
        o: DVec3,
        w: DVec3,
        s0: f64,
        s1: f64,
        ends: [&[(usize, usize)]; 2],
    ) -> Vec<f64> {
        let floor = 1e-15 * s0.abs().max(s1.abs()).max(1.0);
        let mut out = vec![s0, s1];
        for (end, pairs) in ends.into_iter().enumerate() {
            if pairs.is_empty() {
                continue;
            }
            let mut d = (s1 - s0) / GRADE;
            let mut more = 2;
            while d > floor && more > 0 {
                let t = if end == 0 { s0 + d } else { s1 - d };
                out.push(t);
                if self.graze_depth(pairs, o + t * w) <= 1.0 {
                    more -= 1;
                }
                d /= GRADE;
            }
        }
        out.retain(|&t| t >= s0 && t <= s1);
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }

    /// The nearest opaque hit of `o + t w`, `t > 0` (front faces of solids, either side of a
    /// triangle).
    pub fn first_opaque(&self, o: DVec3, w: DVec3) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for (k, p) in self.prims.iter().enumerate() {
            if p.gas().is_some() {
                continue;
            }
            let hit =
                match p.solid {
                    Solid::Sphere { c, r } => sphere_roots(c, r, o, w)
                        .filter(|&(t0, _)| t0 > 0.0)
                        .map(|(t0, _)| Hit {
                            t: t0,
                            k,
                            n: (o + t0 * w - c) / r,
                        }),
                    Solid::Surface { shape, to_world } => {
                        first_hit(&shape, &to_world, o, w).map(|h| Hit { t: h.t, k, n: h.n })
                    }
                };
            if let Some(h) = hit {
                // Of equal distances the earlier primitive (spheres come first in practice).
                if best.as_ref().is_none_or(|b| h.t < b.t) {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The VRML97 lighting equation with shadows at hit `h` of ray `o + t w`; `t_cam` is the
    /// camera ray's gas transmittance to the hit (the viewer-carried headlight's visibility).
    fn surface(&self, h: &Hit, o: DVec3, w: DVec3, t_cam: f64) -> Rgb {
        let Some(m) = self.prims[h.k].material else {
            return [1.0; 3];
        };
        let x = o + h.t * w;
        let mut out = m.emissive;
        for light in &self.lights {
            if !light.scope[h.k] {
                continue;
            }
            let Some(a) = self.light_at(&light.kind, x) else {
                continue;
            };
            if !a.reach {
                continue;
            }
            let ndl = h.n.dot(a.l);
            let mut direct = [0.0; 3];
            if ndl > 0.0 {
                let v = if matches!(light.kind, LightKind::Head) && self.head_viewer_carried {
                    t_cam
                } else {
                    self.visibility(x, a.l, a.dist, Some(h.k))
                };
                let half = (a.l - w).normalize();
                let spec = h.n.dot(half).max(0.0).powf(128.0 * m.shininess);
                for c in 0..3 {
                    direct[c] = v * (m.diffuse[c] * ndl + m.specular[c] * spec);
                }
            }
            for c in 0..3 {
                out[c] += a.att
                    * (a.color[c] * a.ambient * m.diffuse[c] * m.ambient + a.ci[c] * direct[c]);
            }
        }
        out
    }

    /// Emission and in-scattering density at gas point `x` (without the camera
    /// transmittance): `[sum sigma_j C_j, p sum sigma_j a_j sum_i E_i]`.
    fn source(&self, active: &[usize], sig: &[f64], x: DVec3, t_cam: f64) -> [f64; 6] {
        let mut out = [0.0; 6];
        for (j, &k) in active.iter().enumerate() {
            let m = self.prims[k].material.expect("gas has a material");
            for c in 0..3 {
                out[c] += sig[j] * m.emissive[c];
            }
        }
        for light in &self.lights {
            let Some(a) = self.light_at(&light.kind, x) else {
                continue;
            };
            if !a.reach || !active.iter().any(|&k| light.scope[k]) {
                continue;
            }
            let v = if matches!(light.kind, LightKind::Head) && self.head_viewer_carried {
                t_cam
            } else {
                self.visibility(x, a.l, a.dist, None)
            };
            if v == 0.0 {
                continue;
            }
            for (j, &k) in active.iter().enumerate() {
                if !light.scope[k] {
                    continue;
                }
                let m = self.prims[k].material.expect("gas has a material");
                for c in 0..3 {
                    out[3 + c] += P * sig[j] * m.diffuse[c] * a.ci[c] * a.att * v;
                }
            }
        }
        out
    }

    /// The radiance along `o + t w` (`w` unit).
    pub fn ray(&self, o: DVec3, w: DVec3) -> RayRef {
        let hit = self.first_opaque(o, w);
        let t_end = hit.as_ref().map_or(f64::INFINITY, |h| h.t);
        let gas: Vec<(usize, Gas, f64, f64)> = self
            .prims
            .iter()
            .enumerate()
            .filter_map(|(k, p)| {
                let g = p.gas()?;
                let (t0, t1) = sphere_roots(g.c, g.r, o, w)?;
                let (a, b) = (t0.max(0.0), t1.min(t_end));
                (b > a).then_some((k, g, a, b))
            })
            .collect();
        let mut events: Vec<f64> = Vec::new();
        for (_, g, a, b) in &gas {
            events.push(*a);
            events.push(*b);
            let tc = (g.c - o).dot(w);
            if g.m.profile == Profile::Linear && tc > *a && tc < *b {
                events.push(tc);
            }
        }
        events.sort_by(f64::total_cmp);
        events.dedup();
        let mut out = RayRef::default();
        let mut tau = 0.0;
        for pair in events.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let mid = 0.5 * (a + b);
            let active: Vec<usize> = gas
                .iter()
                .filter(|(_, _, ga, gb)| *ga <= mid && mid <= *gb)
                .map(|(k, ..)| *k)
                .collect();
            if active.is_empty() {
                continue;
            }
            out.gas_length += b - a;
            let gases: Vec<Gas> = active
                .iter()
                .map(|&k| self.prims[k].gas().expect("gas"))
                .collect();
            let lines: Vec<Line> = gases.iter().map(|g| g.line(o, w)).collect();
            let depth_to = |s0: f64, s1: f64| -> f64 {
                gases.iter().map(|g| World::depth(g, o, w, s0, s1)).sum()
            };
            let cuts = self.breakpoints(o, w, a, b);
            for piece in cuts.windows(2) {
                let (s0, s1) = (piece[0].0, piece[1].0);
                if s1 <= s0 {
                    continue;
                }
                let tau0 = tau + depth_to(a, s0);
                let mut f = |t: f64| {
                    let tr = (-(tau0 + depth_to(s0, t))).exp();
                    let sig: Vec<f64> = gases
                        .iter()
                        .zip(&lines)
                        .map(|(g, l)| g.sigma_on(l, t))
                        .collect();
                    let mut v = self.source(&active, &sig, o + t * w, tr);
                    for x in &mut v {
                        *x *= tr;
                    }
                    v
                };
                for sub in self
                    .graded(o, w, s0, s1, [&piece[0].1, &piece[1].1])
                    .windows(2)
                {
                    let (v, e) = quad::integrate(&mut f, sub[0], sub[1], REL, 1e-17);
                    for c in 0..3 {
                        out.value[c] += v[c] + v[3 + c];
                        out.scatter[c] += v[3 + c];
                    }
                    out.err += e;
                }
                // A breakpoint is bisected to BISECT relative: up to that much of the ray
                // beside it may hold the other side's integrand (a lit sliver of rounding
                // width at an opaque hit, say), counted in the error.
                for (end, inner) in [(0, s0), (1, s1)] {
                    if piece[end].0 != a && piece[end].0 != b {
                        let width = 2.0 * BISECT * inner.abs().max(1.0);
                        let at = if end == 0 { s0 + width } else { s1 - width };
                        let v = f(at.clamp(s0, s1));
                        out.err += width * v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    }
                }
            }
            tau += depth_to(a, b);
        }
        let tr = (-tau).exp();
        out.opacity = -(-tau).exp_m1();
        let behind = match &hit {
            Some(h) => self.surface(h, o, w, tr),
            None => self.background,
        };
        for c in 0..3 {
            out.value[c] += tr * behind[c];
        }
        out
    }

    /// The reference value of pixel (i, j) (the centre ray).
    pub fn pixel(&self, i: u32, j: u32) -> RayRef {
        let (o, w) = self.eye.ray(i, j);
        self.ray(o, w)
    }

    /// Whether a point light lies on an opaque sphere (to within the rounding of its
    /// coordinates, as [`World::blocked_by`] decides it).
    pub fn light_on_opaque_sphere(&self) -> bool {
        self.lights.iter().any(|l| match l.kind {
            LightKind::Point(p) => self.prims.iter().any(|q| match q.solid {
                Solid::Sphere { c, r } if q.gas().is_none() => on_sphere(p.location, c, r),
                _ => false,
            }),
            _ => false,
        })
    }

    /// Whether any primitive is gas (then the integrators differ).
    pub fn has_gas(&self) -> bool {
        self.prims.iter().any(|p: &Prim| p.gas().is_some())
    }

    /// The most one scattering event can send per unit of opacity in front of it: the
    /// largest albedo of any gas times every light at full strength (the largest channel of
    /// colour times intensity; the headlight is white, intensity 1; attenuation is at most 1).
    pub fn scatter_scale(&self) -> f64 {
        let albedo = self
            .prims
            .iter()
            .filter_map(|p: &Prim| p.gas())
            .map(|g| g.m.diffuse.iter().fold(0.0f64, |m, &a| m.max(a)))
            .fold(0.0f64, f64::max);
        let strongest = |color: &[f64; 3], intensity: f64| {
            color.iter().fold(0.0f64, |m, &c| m.max(c)) * intensity
        };
        let lights: f64 = self
            .lights
            .iter()
            .map(|l| match &l.kind {
                LightKind::Point(p) => strongest(&p.color, p.intensity),
                LightKind::Directional(d) => strongest(&d.color, d.intensity),
                LightKind::Head => 1.0,
            })
            .sum();
        albedo * lights
    }
}

/// Whether `p` lies on the sphere `(c, r)` to within the rounding of its coordinates.
fn on_sphere(p: DVec3, c: DVec3, r: f64) -> bool {
    ((p - c).length() - r).abs() <= 1e-12 * (r + c.length())
}
