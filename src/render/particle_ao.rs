//! The mean unoccluded fraction over each sphere's surface (the quantity OVITO's ambient
//! occlusion modifier and QuteMol give one value per particle for), integrated to a
//! tolerance from the exact AO at surface points ([`super::ao`], docs/model.md section 11).
//!
//! A sphere's surface is mapped to the rectangle `u = cos θ ∈ [-1, 1]`, `φ ∈ [0, 2π)`,
//! where area is `r² du dφ`, so the mean is the rectangle's average. The average is
//! integrated by global adaptive cubature: on each cell, a 3 x 3 Gauss-Legendre rule on the
//! whole cell and on its four quarters; their difference is the cell's error estimate, and
//! the cell with the largest estimate is split until the estimates sum to at most `tol`.
//! The integrand is continuous where neighbours only shade the sphere, with kinks where a
//! cap meets the horizon, and jumps to 0 where a neighbour buries the surface; the estimate
//! is the usual heuristic of embedded rules, not a bound.

use std::collections::BinaryHeap;

use glam::DVec3;

use rayon::prelude::*;

use super::ao::{unoccluded_to, unsupported, AoScratch, Weighting};
use super::visibility::Opaque;
use super::{Prepared, Progress};
use crate::Error;

/// One sphere's mean unoccluded fraction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParticleAo {
    /// The mean over its surface, in `[0, 1]`.
    pub mean: f64,
    /// The estimated absolute error of `mean`.
    pub error: f64,
    /// Points of the surface where AO was computed.
    pub points: u64,
}

/// The most points one sphere's integral may take before it stops with the error it has.
pub const MAX_POINTS: u64 = 1 << 20;

/// Gauss-Legendre nodes and weights on [-1, 1], 3 points.
const GL3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// A cell of the `(u, φ)` rectangle with its integral over the whole cell and over each
/// quarter (the part of the mean it holds).
struct Cell {
    lo: (f64, f64),
    hi: (f64, f64),
    quarters: [f64; 4],
    error: f64,
}

impl PartialEq for Cell {
    fn eq(&self, o: &Self) -> bool {
        self.error == o.error
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cell {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.error.total_cmp(&o.error)
    }
}

/// AO over one sphere's surface, as a function of `(u, φ)`.
struct Surface<'a> {
    prep: &'a Prepared,
    centre: DVec3,
    radius: f64,
    own: Option<u32>,
    reach: (f64, Weighting),
    s: &'a mut AoScratch,
    points: u64,
    /// The tolerance of each point's value where Cylinders or Cones occlude, and the largest
    /// bound of a point's error so far: the mean's error is within it plus the cells'.
    point_tol: f64,
    point_error: f64,
}

impl Surface<'_> {
    fn ao(&mut self, u: f64, phi: f64) -> f64 {
        self.points += 1;
        let sin = ((1.0 - u) * (1.0 + u)).max(0.0).sqrt();
        let n = DVec3::new(sin * phi.cos(), sin * phi.sin(), u);
        let (v, error) = unoccluded_to(
            self.prep,
            self.centre + self.radius * n,
            n,
            self.own.map(Opaque::Sphere),
            self.reach,
            self.point_tol,
            self.s,
        );
        self.point_error = self.point_error.max(error);
        v
    }

    /// The integral of AO over a cell, divided by the rectangle's area 4π.
    fn rule(&mut self, lo: (f64, f64), hi: (f64, f64)) -> f64 {
        let (hu, hp) = (0.5 * (hi.0 - lo.0), 0.5 * (hi.1 - lo.1));
        let (mu, mp) = (0.5 * (hi.0 + lo.0), 0.5 * (hi.1 + lo.1));
        let mut sum = 0.0;
        for &(a, wa) in &GL3 {
            for &(b, wb) in &GL3 {
                sum += wa * wb * self.ao(mu + hu * a, mp + hp * b);
            }
        }
        sum * hu * hp / (4.0 * std::f64::consts::PI)
    }

    /// A cell whose rule over the whole is `whole`, with its quarters' rules.
    fn cell(&mut self, lo: (f64, f64), hi: (f64, f64), whole: f64) -> Cell {
        let mid = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
        let quarters = [
            self.rule(lo, mid),
            self.rule((mid.0, lo.1), (hi.0, mid.1)),
            self.rule((lo.0, mid.1), (mid.0, hi.1)),
            self.rule(mid, hi),
        ];
        let error = (quarters.iter().sum::<f64>() - whole).abs();
        Cell {
            lo,
            hi,
            quarters,
            error,
        }
    }
}

/// The four quarters of the cell `lo..hi`.
fn quarters(lo: (f64, f64), hi: (f64, f64)) -> [((f64, f64), (f64, f64)); 4] {
    let mid = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
    [
        (lo, mid),
        ((mid.0, lo.1), (hi.0, mid.1)),
        ((lo.0, mid.1), (mid.0, hi.1)),
        (mid, hi),
    ]
}

/// The mean unoccluded fraction over the surface of the sphere `(centre, radius)` whose
/// primitive is `own` (the sphere itself never occludes), to an estimated absolute error of
/// `tol` (or [`MAX_POINTS`] points), with occluders within `reach` weighted by `w`.
pub fn sphere_ao(
    prep: &Prepared,
    sphere: (DVec3, f64),
    own: Option<u32>,
    ao: (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
) -> ParticleAo {
    integrate(prep, sphere, own, ao, tol, s, &|| false).expect("never stopped")
}

/// [`sphere_ao`], or None once `stop` says so: it is asked before each cell (a few dozen
/// points), so that a sphere whose integral takes long does not hold up a cancel.
fn integrate(
    prep: &Prepared,
    (centre, radius): (DVec3, f64),
    own: Option<u32>,
    (reach, w): (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
    stop: &dyn Fn() -> bool,
) -> Option<ParticleAo> {
    let mut f = Surface {
        prep,
        centre,
        radius,
        own,
        reach: (reach, w),
        s,
        points: 0,
        point_tol: 0.25 * tol,
        point_error: 0.0,
    };
    // A first grid of 4 x 8 cells.
    let mut heap = BinaryHeap::new();
    let (nu, np) = (4, 8);
    for i in 0..nu {
        for j in 0..np {
            let lo = (
                -1.0 + 2.0 * f64::from(i) / f64::from(nu),
                std::f64::consts::TAU * f64::from(j) / f64::from(np),
            );
            let hi = (
                -1.0 + 2.0 * f64::from(i + 1) / f64::from(nu),
                std::f64::consts::TAU * f64::from(j + 1) / f64::from(np),
            );
            if stop() {
                return None;
            }
            let whole = f.rule(lo, hi);
            heap.push(f.cell(lo, hi, whole));
        }
    }
    let mut error: f64 = heap.iter().map(|c: &Cell| c.error).sum();
    while error > tol && f.points < MAX_POINTS {
        if stop() {
            return None;
        }
        let Some(worst) = heap.pop() else { break };
        error -= worst.error;
        for (k, (lo, hi)) in quarters(worst.lo, worst.hi).into_iter().enumerate() {
            let c = f.cell(lo, hi, worst.quarters[k]);
            error += c.error;
            heap.push(c);
        }
    }
    // (Summed afresh: the running sum drifts by rounding as cells come and go.)
    let error: f64 = heap.iter().map(|c| c.error).sum::<f64>() + f.point_error;
    let mean: f64 = heap.iter().map(|c| c.quarters.iter().sum::<f64>()).sum();
    Some(ParticleAo {
        mean: mean.clamp(0.0, 1.0),
        error,
        points: f.points,
    })
}

/// Checks a tolerance for [`particles_ao`]: the means lie in `[0, 1]`, so a tolerance
/// means something only between 0 and 1.
pub fn check_tol(tol: f64) -> Result<(), String> {
    if tol > 0.0 && tol < 1.0 {
        Ok(())
    } else {
        Err(format!(
            "tol = {tol}: the tolerance must be between 0 and 1"
        ))
    }
}

/// [`sphere_ao`] of each sphere of the scene `prep` was made from, in the scene's order
/// ([`Prepared::scene_spheres`] gives their centres and radii), on the threads of the
/// current rayon pool. The spheres are integrated in the BVH's order, neighbours after
/// neighbours; a sphere dropped by `prepare` as a copy of another takes that one's value,
/// since it is drawn as that one. `progress` counts the spheres integrated as
/// [`crate::render::render`] counts tiles, and may cancel (it is asked every few dozen
/// points of each sphere's integral).
pub fn particles_ao(
    prep: &Prepared,
    ao: (f64, Weighting),
    tol: f64,
    progress: &dyn Progress,
) -> Result<Vec<ParticleAo>, Error> {
    if let Some(why) = unsupported(prep) {
        return Err(Error::Invalid(why));
    }
    if prep.gas_spheres > 0 {
        return Err(Error::Invalid(format!(
            "per-particle AO knows opaque spheres, triangles, boxes and closed cylinders and \
             cones only, and this scene has {} gas spheres (AO pictures take gas as an \
             occluder)",
            prep.gas_spheres
        )));
    }
    check_tol(tol).map_err(Error::Invalid)?;
    super::ao::check_reach(ao.0).map_err(Error::Invalid)?;
    let prims = prep.bvh.packed();
    progress.start(prims.len() as u64);
    let out: Vec<Option<ParticleAo>> = (0..prims.len() as u32)
        .into_par_iter()
        .map_init(AoScratch::default, |s, i| {
            let (q, stop) = (&prims[i as usize], || progress.cancelled());
            let a = integrate(prep, (q.center, q.radius), Some(i), ao, tol, s, &stop)?;
            progress.tile_done();
            Some(a)
        })
        .collect();
    let out: Option<Vec<ParticleAo>> = out.into_iter().collect();
    let out = out.ok_or(Error::Cancelled)?;
    progress.finish();
    Ok(prep.in_scene_order(&out))
}
