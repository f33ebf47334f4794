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

use hashbrown::HashMap;
use rayon::prelude::*;

use super::ao::{unoccluded, unsupported, AoScratch, Weighting};
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
}

impl Surface<'_> {
    fn ao(&mut self, u: f64, phi: f64) -> f64 {
        self.points += 1;
        let sin = ((1.0 - u) * (1.0 + u)).max(0.0).sqrt();
        let n = DVec3::new(sin * phi.cos(), sin * phi.sin(), u);
        unoccluded(
            self.prep,
            self.centre + self.radius * n,
            n,
            self.own,
            self.reach,
            self.s,
        )
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
    (centre, radius): (DVec3, f64),
    own: Option<u32>,
    (reach, w): (f64, Weighting),
    tol: f64,
    s: &mut AoScratch,
) -> ParticleAo {
    let mut f = Surface {
        prep,
        centre,
        radius,
        own,
        reach: (reach, w),
        s,
        points: 0,
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
            let whole = f.rule(lo, hi);
            heap.push(f.cell(lo, hi, whole));
        }
    }
    let mut error: f64 = heap.iter().map(|c: &Cell| c.error).sum();
    while error > tol && f.points < MAX_POINTS {
        let Some(worst) = heap.pop() else { break };
        error -= worst.error;
        for (k, (lo, hi)) in quarters(worst.lo, worst.hi).into_iter().enumerate() {
            let c = f.cell(lo, hi, worst.quarters[k]);
            error += c.error;
            heap.push(c);
        }
    }
    // (Summed afresh: the running sum drifts by rounding as cells come and go.)
    let error: f64 = heap.iter().map(|c| c.error).sum();
    let mean: f64 = heap.iter().map(|c| c.quarters.iter().sum::<f64>()).sum();
    ParticleAo {
        mean: mean.clamp(0.0, 1.0),
        error,
        points: f.points,
    }
}

/// The key of a sphere's exact centre and radius.
fn key(c: DVec3, r: f64) -> [u64; 4] {
    [c.x.to_bits(), c.y.to_bits(), c.z.to_bits(), r.to_bits()]
}

/// [`sphere_ao`] of each of `spheres` (centre and radius, in world units, as the scene
/// [`prep`](Prepared) was made from lists them, in its order), on the threads of the current
/// rayon pool; `progress` counts spheres as [`crate::render::render`] counts tiles, and may
/// cancel. A sphere dropped by `prepare` as a copy of another takes that one's surface (it
/// is drawn as that one).
pub fn particles_ao(
    prep: &Prepared,
    spheres: &[(DVec3, f64)],
    (reach, w): (f64, Weighting),
    tol: f64,
    progress: &dyn Progress,
) -> Result<Vec<ParticleAo>, Error> {
    if let Some(why) = unsupported(prep) {
        return Err(Error::Invalid(why));
    }
    if !(tol > 0.0 && tol.is_finite()) {
        return Err(Error::Invalid(format!(
            "tol = {tol}: the tolerance must be positive and finite"
        )));
    }
    super::ao::check_reach(reach).map_err(Error::Invalid)?;
    let prims: HashMap<[u64; 4], u32> = (0..prep.bvh.len() as u32)
        .map(|i| {
            let p = prep.bvh.prim(i);
            (key(p.center, p.radius), i)
        })
        .collect();
    progress.start(spheres.len() as u64);
    let out: Vec<Option<ParticleAo>> = spheres
        .par_iter()
        .map_init(AoScratch::default, |s, &(c, r)| {
            if progress.cancelled() {
                return None;
            }
            let own = prims.get(&key(c, r)).copied();
            let a = sphere_ao(prep, (c, r), own, (reach, w), tol, s);
            progress.tile_done();
            Some(a)
        })
        .collect();
    let out: Option<Vec<ParticleAo>> = out.into_iter().collect();
    let out = out.ok_or(Error::Cancelled)?;
    progress.finish();
    Ok(out)
}
