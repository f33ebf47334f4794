//! The approximations of ambient occlusion that real-time and interactive tools compute, each
//! named after the tool it models, so that a render by one can be judged against the exact
//! answer (`gtsphere compare`; docs/ao-methods.md).
//!
//! - [`mc`]: random rays within the reach (OSPRay, Tachyon, Blender);
//! - [`directions`]: a fixed set of directions over the whole sphere (ChimeraX's multishadow
//!   lighting);
//! - [`sum`]: each sphere's own form factor, summed and clamped (analytic sphere occlusion in
//!   shaders);
//! - [`voxel`]: three cones traced through a voxel density grid (MegaMol's MDAO).
//!
//! Each answers the question the exact method answers (`super::unoccluded_to`): the unoccluded
//! fraction at a point on an opaque sphere, the sphere itself left out, within the reach.
//! `exact` is the default, and none of these is ever chosen silently.

pub mod directions;
pub mod mc;
pub mod sum;
pub mod voxel;

use glam::DVec3;

use super::{AoSettings, Weighting};
use crate::render::sampler::Rng;
use crate::render::{Counters, Integrator, Prepared, View};

/// The most rays `mc` traces per shading point (as many as samples per pixel may be).
pub const MAX_SAMPLES: u32 = 1 << 20;

/// The most directions `directions` may use.
pub const MAX_DIRECTIONS: u32 = 1 << 16;

/// How the unoccluded fraction is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum AoMethod {
    /// Exactly, the measure of the union of the caps the spheres block (the default).
    #[default]
    Exact,
    /// `samples` random directions per shading point, each traced within the reach ([`mc`]).
    Mc {
        /// Rays per shading point, from 1 to [`MAX_SAMPLES`].
        samples: u32,
    },
    /// `count` fixed directions spread over the whole sphere, those above the horizon traced
    /// within the reach ([`directions`]).
    Directions {
        /// Directions over the sphere, from 1 to [`MAX_DIRECTIONS`].
        count: u32,
    },
    /// The spheres' single-cap form factors summed and clamped at 1 ([`sum`]).
    Sum,
    /// Three cones traced through a voxel density grid of the spheres ([`voxel`]).
    Voxel(voxel::VoxelSettings),
}

impl AoMethod {
    /// `mc` with its default of 16 rays per shading point.
    pub const MC: AoMethod = AoMethod::Mc { samples: 16 };
    /// `directions` with its default of 64 directions, ChimeraX's in its soft and full
    /// lighting.
    pub const DIRECTIONS: AoMethod = AoMethod::Directions { count: 64 };
    /// `voxel` with MegaMol's defaults.
    pub const VOXEL: AoMethod = AoMethod::Voxel(voxel::VoxelSettings::MEGAMOL);

    /// Whether its answer is random: then its error estimate is a standard error, and the
    /// estimates of a pixel's samples are independent.
    pub fn is_random(&self) -> bool {
        matches!(self, AoMethod::Mc { .. })
    }

    /// Its name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            AoMethod::Exact => "exact",
            AoMethod::Mc { .. } => "mc",
            AoMethod::Directions { .. } => "directions",
            AoMethod::Sum => "sum",
            AoMethod::Voxel(_) => "voxel",
        }
    }
}

/// Reusable buffers of one worker for the approximations.
#[derive(Default)]
pub struct MethodScratch {
    /// The BVH walk's stack (`sum`).
    stack: Vec<u32>,
    /// The set of `directions`, for the count it was made for.
    directions: Vec<DVec3>,
}

/// Checks AO settings: a positive reach, and the method's parameters in their ranges. `sum`
/// and `voxel` are cosine-weighted by construction (a form factor; cones about the normal),
/// so they refuse the uniform weighting.
pub fn check(ao: &AoSettings) -> Result<(), String> {
    super::check_reach(ao.reach)?;
    match ao.method {
        AoMethod::Exact => {}
        AoMethod::Mc { samples } => {
            if !(1..=MAX_SAMPLES).contains(&samples) {
                return Err(format!(
                    "the mc AO method's samples = {samples}: from 1 to {MAX_SAMPLES} rays per \
                     shading point"
                ));
            }
        }
        AoMethod::Directions { count } => {
            if !(1..=MAX_DIRECTIONS).contains(&count) {
                return Err(format!(
                    "the directions AO method's count = {count}: from 1 to {MAX_DIRECTIONS} \
                     directions"
                ));
            }
        }
        AoMethod::Sum => {}
        AoMethod::Voxel(v) => v.check()?,
    }
    if ao.weighting == Weighting::Uniform && matches!(ao.method, AoMethod::Sum | AoMethod::Voxel(_))
    {
        return Err(format!(
            "the {} AO method is cosine-weighted by construction: it has no uniform weighting",
            ao.method.name()
        ));
    }
    Ok(())
}

/// What a view of `prep` needs for `integrator`: with AO, a scene that AO supports
/// (`ao::unsupported`; the approximations, spheres only), and with the voxel method its
/// density grid, built here once for the render ([`voxel::Grid::build`]).
pub fn prepare_view(
    prep: &Prepared,
    integrator: &Integrator,
) -> Result<Option<voxel::Grid>, String> {
    let Integrator::Ao(ao) = integrator else {
        return Ok(None);
    };
    if let Some(why) = super::unsupported(prep) {
        return Err(why);
    }
    if ao.method != AoMethod::Exact && prep.gas_spheres > 0 {
        return Err(format!(
            "the {} AO method models a sphere renderer's approximation and knows opaque \
             spheres only, and this scene has {} gas spheres; --ao-method exact takes them",
            ao.method.name(),
            prep.gas_spheres
        ));
    }
    if ao.method != AoMethod::Exact && !prep.surfaces.is_empty() {
        return Err(format!(
            "the {} AO method models a sphere renderer's approximation and knows spheres only, \
             and this scene has {} surfaces other than spheres (triangles and boxes); \
             --ao-method exact takes them",
            ao.method.name(),
            prep.surfaces.items.len()
        ));
    }
    Ok(match ao.method {
        AoMethod::Voxel(v) => Some(voxel::Grid::build(
            prep.bvh.packed().iter().map(|q| (q.center, q.radius)),
            prep.bvh.bounds(),
            v.resolution,
        )),
        _ => None,
    })
}

/// The unoccluded fraction at `x` (unit normal `n`, on the BVH's primitive `own`) by
/// `ao.method`, other than exact, and its estimated error: the standard error for `mc`, 0 for
/// the deterministic methods, whose error is not estimated. The rays traced are counted as
/// shadow rays.
pub fn unoccluded(
    view: &View,
    ao: &AoSettings,
    (x, n, own): (DVec3, DVec3, Option<u32>),
    rng: &mut Rng,
    s: &mut MethodScratch,
    counters: &mut Counters,
) -> (f64, f64) {
    let range = (ao.reach, ao.weighting);
    match ao.method {
        AoMethod::Exact => unreachable!("the exact method is the caller's"),
        AoMethod::Mc { samples } => {
            counters.shadow_rays += u64::from(samples);
            mc::unoccluded(&view.bvh, (x, n, own), range, samples, rng)
        }
        AoMethod::Directions { count } => {
            if s.directions.len() != count as usize {
                directions::spiral(count, &mut s.directions);
            }
            let (v, rays) = directions::unoccluded(&view.bvh, (x, n, own), range, &s.directions);
            counters.shadow_rays += rays;
            (v, 0.0)
        }
        AoMethod::Sum => (
            sum::unoccluded(&view.bvh, (x, n, own), ao.reach, &mut s.stack),
            0.0,
        ),
        AoMethod::Voxel(v) => {
            let grid = view
                .ao_grid
                .as_ref()
                .expect("Prepared::view builds the grid of the voxel method");
            (voxel::unoccluded(grid, &v, ao.reach, (x, n)), 0.0)
        }
    }
}

#[cfg(test)]
mod tests;
