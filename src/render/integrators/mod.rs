//! Integrators, one per file, each answering `radiance(ray) -> Estimate`. The set is closed and
//! chosen by name (an enum, not trait objects in the hot loop).

pub mod surface;

use glam::DVec3;

/// What one camera ray returns.
#[derive(Clone, Copy, Debug, Default)]
pub struct Estimate {
    /// Radiance (linear RGB).
    pub value: DVec3,
    /// Estimated absolute error of `value` (0 where the answer is exact up to rounding).
    pub error: f64,
    /// Whether the ray hit geometry (pixel coverage, alpha).
    pub covered: bool,
}
