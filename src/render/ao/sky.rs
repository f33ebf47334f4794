//! Which directions of a hemisphere are already known to be blocked: a grid of cells over
//! the hemisphere, each marked when one cap holds it whole. An occluder whose directions all
//! fall in marked cells lies within the union of caps already found, so leaving it out does
//! not change the union: culling by the sky is exact.
//!
//! Cells are 32 bands of polar angle by 64 sectors of azimuth about the normal; a band is a
//! 64-bit mask. Each cell is bounded by a cap about its centre (its radius computed once per
//! band, with a margin that makes it an upper bound), so that "a cap holds the cell" and "a
//! cone may touch the cell" are both tests on the angle between two directions.
//!
//! Measured 2026-12-05 (`render --integrator ao` without a reach, a random packing of 1000
//! unit spheres at volume fraction 0.4, 128 x 128, two threads): 18.0 s without the sky,
//! 1.9 s with it (the cells, and the caps the sky drops before their union).

use std::f64::consts::{FRAC_PI_2, TAU};
use std::sync::OnceLock;

use glam::DVec3;

/// Bands of polar angle.
const BANDS: usize = 32;
/// Sectors of azimuth: the bits of a band's mask.
const SECTORS: usize = 64;
/// Slack (radians) for the rounding of the tests: marking is stricter, touching looser.
const SLACK: f64 = 1e-9;

/// The directions of the hemisphere about a normal that known caps hold.
pub struct Sky {
    e1: DVec3,
    e2: DVec3,
    n: DVec3,
    bands: [u64; BANDS],
}

/// A direction in the sky's frame: its polar angle from the normal and its azimuth.
#[derive(Clone, Copy)]
struct Polar {
    theta: f64,
    phi: f64,
}

/// Per band: its centre's polar angle (sine and cosine) and the radius of the caps that bound
/// its cells.
struct Band {
    sin: f64,
    cos: f64,
    theta: f64,
    radius: f64,
}

fn bands() -> &'static [Band; BANDS] {
    static BANDS_: OnceLock<[Band; BANDS]> = OnceLock::new();
    BANDS_.get_or_init(|| {
        std::array::from_fn(|b| {
            let (t0, t1) = (
                b as f64 * FRAC_PI_2 / BANDS as f64,
                (b + 1) as f64 * FRAC_PI_2 / BANDS as f64,
            );
            let theta = 0.5 * (t0 + t1);
            let centre = unit(theta, 0.0);
            let half = 0.5 * TAU / SECTORS as f64;
            // The farthest point of the cell from its centre is on its boundary: the largest
            // angle to points along the four edges, plus half the spacing of those points.
            const STEPS: usize = 256;
            let mut far: f64 = 0.0;
            for k in 0..=STEPS {
                let f = k as f64 / STEPS as f64;
                for (t, p) in [
                    (t0 + f * (t1 - t0), -half),
                    (t0 + f * (t1 - t0), half),
                    (t0, -half + 2.0 * f * half),
                    (t1, -half + 2.0 * f * half),
                ] {
                    far = far.max(angle(centre, unit(t, p)));
                }
            }
            let spacing = (t1 - t0).max(2.0 * half) / STEPS as f64;
            Band {
                sin: theta.sin(),
                cos: theta.cos(),
                theta,
                radius: far + spacing,
            }
        })
    })
}

fn unit(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The angle between two unit vectors, to rounding at every size.
fn angle(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The sectors whose centres are within `half` of azimuth `phi` (`None`: all of them).
fn sectors(phi: f64, half: f64) -> u64 {
    let width = TAU / SECTORS as f64;
    let first = ((phi - half) / width - 0.5).ceil();
    let last = ((phi + half) / width - 0.5).floor();
    if last < first {
        return 0;
    }
    let count = last - first + 1.0;
    if count >= SECTORS as f64 {
        return u64::MAX;
    }
    let start = first.rem_euclid(SECTORS as f64) as u32;
    ((1u64 << count as u32) - 1).rotate_left(start)
}

impl Sky {
    /// An empty sky about the unit normal `n`.
    pub fn new(n: DVec3) -> Sky {
        let e1 = n.any_orthonormal_vector();
        Sky {
            e1,
            e2: n.cross(e1),
            n,
            bands: [0; BANDS],
        }
    }

    fn polar(&self, w: DVec3) -> Polar {
        let (x, y, z) = (w.dot(self.e1), w.dot(self.e2), w.dot(self.n));
        Polar {
            theta: x.hypot(y).atan2(z),
            phi: y.atan2(x),
        }
    }

    /// The cells of band `b` whose centres are within `radius` of `p`.
    fn near(b: &Band, p: Polar, radius: f64) -> u64 {
        if radius <= 0.0 || (b.theta - p.theta).abs() > radius {
            return 0;
        }
        // cos(angle) = cos θc cos θp + sin θc sin θp cos(φ - φp) >= cos(radius).
        let across = b.sin * p.theta.sin();
        let need = radius.min(std::f64::consts::PI).cos() - b.cos * p.theta.cos();
        if across <= 1e-300 {
            return if need <= 0.0 { u64::MAX } else { 0 };
        }
        let ratio = need / across;
        if ratio > 1.0 {
            0
        } else if ratio <= -1.0 {
            u64::MAX
        } else {
            sectors(p.phi, ratio.acos())
        }
    }

    /// Marks the cells that the cap about `axis` of angular radius `alpha` holds whole.
    pub fn cover(&mut self, axis: DVec3, alpha: f64) {
        let p = self.polar(axis);
        for (mask, b) in self.bands.iter_mut().zip(bands()) {
            *mask |= Self::near(b, p, alpha - b.radius - SLACK);
        }
    }

    /// Marks the cells that the intersection of `caps` (at most 8) holds whole: those every
    /// one of the caps holds.
    pub fn cover_all(&mut self, caps: &[super::cap::Cap]) {
        if caps.len() > 8 {
            // (Marking nothing is always safe.)
            return;
        }
        let mut polar = [(
            Polar {
                theta: 0.0,
                phi: 0.0,
            },
            0.0,
        ); 8];
        for (p, c) in polar.iter_mut().zip(caps) {
            *p = (self.polar(c.axis), c.cos.acos());
        }
        let polar = &polar[..caps.len()];
        for (mask, b) in self.bands.iter_mut().zip(bands()) {
            let mut all = u64::MAX;
            for &(p, alpha) in polar {
                all &= Self::near(b, p, alpha - b.radius - SLACK);
                if all == 0 {
                    break;
                }
            }
            *mask |= all;
        }
    }

    /// Whether every cell that the cone about `axis` of angular radius `beta` may touch is
    /// marked: then the cone's directions above the horizon are all blocked already.
    pub fn hides(&self, axis: DVec3, beta: f64) -> bool {
        let p = self.polar(axis);
        self.bands
            .iter()
            .zip(bands())
            .all(|(&mask, b)| Self::near(b, p, beta + b.radius + SLACK) & !mask == 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pseudo-random numbers of its own.
    fn next(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Whether the direction `w` (above the horizon) lies in a cell `sky` has marked.
    fn in_marked_cell(sky: &Sky, w: DVec3) -> bool {
        let p = sky.polar(w);
        let band = ((p.theta / FRAC_PI_2 * BANDS as f64) as usize).min(BANDS - 1);
        let sector = (p.phi.rem_euclid(TAU) / TAU * SECTORS as f64) as usize % SECTORS;
        sky.bands[band] >> sector & 1 == 1
    }

    #[test]
    fn marked_cells_lie_inside_the_caps_and_hidden_cones_inside_marked_cells() {
        // Directions drawn at random: one in a marked cell must be inside some cap; a cone
        // said hidden must have every sampled direction above the horizon inside some cap.
        let mut st = 9;
        for _ in 0..30 {
            let n = DVec3::new(
                next(&mut st) - 0.5,
                next(&mut st) - 0.5,
                next(&mut st) - 0.5,
            )
            .normalize();
            let mut sky = Sky::new(n);
            let mut caps = Vec::new();
            for _ in 0..6 {
                let a = DVec3::new(
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                )
                .normalize();
                let alpha = 0.2 + 1.2 * next(&mut st);
                sky.cover(a, alpha);
                caps.push((a, alpha));
            }
            let inside = |w: DVec3| caps.iter().any(|&(a, alpha)| angle(a, w) <= alpha);
            for _ in 0..2000 {
                let w = DVec3::new(
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                )
                .normalize();
                if w.dot(n) < 0.0 {
                    continue;
                }
                if in_marked_cell(&sky, w) {
                    assert!(inside(w), "a marked cell's direction outside every cap");
                }
            }
            for _ in 0..200 {
                let a = DVec3::new(
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                    next(&mut st) - 0.5,
                )
                .normalize();
                let beta = 0.3 * next(&mut st);
                if !sky.hides(a, beta) {
                    continue;
                }
                let (u, v) = a.any_orthonormal_pair();
                for k in 0..64 {
                    let r = beta * (k % 8) as f64 / 7.0;
                    let f = (k / 8) as f64 * TAU / 8.0;
                    let w = a * r.cos() + (u * f.cos() + v * f.sin()) * r.sin();
                    if w.dot(n) > 0.0 {
                        assert!(inside(w), "a hidden cone's direction outside every cap");
                    }
                }
            }
        }
    }

    #[test]
    fn cells_marked_by_an_intersection_of_caps_lie_inside_every_one() {
        let unit =
            |st: &mut u64| DVec3::new(next(st) - 0.5, next(st) - 0.5, next(st) - 0.5).normalize();
        let mut st = 17;
        let mut marked = 0;
        for _ in 0..60 {
            let n = unit(&mut st);
            let mut sky = Sky::new(n);
            // A region about a direction: 2 to 4 caps of radius 60 to 90 degrees whose axes
            // lean a little from it (a triangle's great circles have radius 90).
            let centre = unit(&mut st);
            let caps: Vec<super::super::cap::Cap> = (0..2 + (next(&mut st) * 3.0) as usize)
                .map(|_| super::super::cap::Cap {
                    axis: (centre + 0.6 * unit(&mut st)).normalize(),
                    cos: 0.5 * next(&mut st),
                })
                .collect();
            sky.cover_all(&caps);
            for _ in 0..4000 {
                let w = unit(&mut st);
                if w.dot(n) < 0.0 {
                    continue;
                }
                if in_marked_cell(&sky, w) {
                    marked += 1;
                    assert!(
                        caps.iter().all(|c| c.axis.dot(w) >= c.cos),
                        "a marked cell's direction outside a cap of the region"
                    );
                }
            }
        }
        assert!(marked > 1000, "{marked} directions in marked cells");
    }

    #[test]
    fn a_cap_over_the_whole_hemisphere_hides_everything() {
        let mut sky = Sky::new(DVec3::Z);
        assert!(!sky.hides(DVec3::X, 0.01));
        sky.cover(DVec3::Z, FRAC_PI_2 + 0.2);
        assert!(sky.bands.iter().all(|&m| m == u64::MAX));
        assert!(sky.hides(DVec3::new(0.3, 0.2, 0.9).normalize(), 0.1));
    }
}
