//! Typical particle spacing: the median distance from a point to its nearest neighbour, found
//! with a uniform grid.

use glam::DVec3;
use rayon::prelude::*;

/// The median over `points` of the distance to the nearest other point at a different
/// position; `None` if fewer than 2 distinct finite positions. (A distance beyond the f64
/// range is infinite, one below about 1e-154 may round to 0.)
///
/// - Non-finite points are ignored. Points at the same position (`==`, so `-0.0 == 0.0`)
///   are one position for the search, but each counts in the median. An even count takes the
///   mean of the two middle distances.
/// - A uniform grid over the box of the 1st to 99th percentile of each coordinate (points
///   outside fall in the border cells), about one point per cell; each search visits shells
///   of cells until no unvisited cell can hold a nearer point. Exact; O(n) for points spread
///   evenly over their box, slower when most points crowd into a few cells (clusters far
///   apart, or a surface tilted in its box).
pub fn median_nearest_distance(points: &[DVec3]) -> Option<f64> {
    // +0.0 makes -0.0 into 0.0, so equal positions have equal bits.
    let pts: Vec<DVec3> = points
        .iter()
        .filter(|p| p.is_finite())
        .map(|&p| p + DVec3::ZERO)
        .collect();
    let grid = Grid::new(&pts)?;
    let near: Vec<f64> = (0..grid.points.len())
        .into_par_iter()
        .map(|k| grid.nearest(k).sqrt())
        .collect();
    let mut dist = Vec::with_capacity(pts.len());
    for (&d, &count) in near.iter().zip(&grid.count) {
        dist.extend(std::iter::repeat_n(d, count));
    }
    let (len, m) = (dist.len(), dist.len() / 2);
    let (low, &mut upper, _) = dist.select_nth_unstable_by(m, f64::total_cmp);
    Some(if len % 2 == 1 {
        upper
    } else {
        let lower = low.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lower + upper)
    })
}

/// The distinct positions sorted by cell, with their multiplicities.
struct Grid {
    lo: DVec3,
    /// Cell edge.
    h: f64,
    dims: [usize; 3],
    /// `points[start[c]..start[c + 1]]` are the distinct positions in cell `c`.
    start: Vec<usize>,
    points: Vec<DVec3>,
    count: Vec<usize>,
    /// Rounding allowance of the cell indices, in cells (see `nearest`).
    slack: f64,
}

impl Grid {
    fn new(pts: &[DVec3]) -> Option<Grid> {
        let n = pts.len();
        if n < 2 {
            return None;
        }
        let (mut lo, mut hi) = (DVec3::ZERO, DVec3::ZERO);
        // Percentiles of a sample (any box gives exact results; this one sets the cells).
        let step = n.div_ceil(1 << 16);
        for axis in 0..3 {
            let mut v: Vec<f64> = pts.iter().step_by(step).map(|p| p[axis]).collect();
            let (m, cut) = (v.len(), v.len() / 100);
            let (_, &mut a, _) = v.select_nth_unstable_by(cut, f64::total_cmp);
            let (_, &mut b, _) = v.select_nth_unstable_by(m - 1 - cut, f64::total_cmp);
            lo[axis] = a;
            hi[axis] = b;
        }
        let mut extent = hi - lo;
        if extent == DVec3::ZERO {
            // Nearly all points at one position: the whole box.
            lo = pts.iter().copied().fold(DVec3::INFINITY, DVec3::min);
            hi = pts.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
            extent = hi - lo;
        }
        // About one point per cell in the axes that have an extent (log form: no overflow).
        let spread: Vec<f64> = extent.to_array().into_iter().filter(|&e| e > 0.0).collect();
        if spread.is_empty() {
            return None;
        }
        let logs: f64 = spread.iter().map(|e| e.ln()).sum();
        let mut h = ((logs - (n as f64).ln()) / spread.len() as f64).exp();
        if !(h > 0.0 && h.is_finite()) {
            h = extent.max_element();
        }
        let cells_for = |h: f64| {
            extent
                .to_array()
                .map(|e| ((e / h).floor() as usize).saturating_add(1))
        };
        let mut dims = cells_for(h);
        while dims
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .is_none_or(|c| c > 2 * n + 8)
        {
            h *= 1.25;
            dims = cells_for(h);
        }
        let cell_of = |p: DVec3| {
            let i = ((p - lo) / h).to_array();
            let c = |a: usize| (i[a].max(0.0) as usize).min(dims[a] - 1);
            c(0) + dims[0] * (c(1) + dims[1] * c(2))
        };
        let cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0usize; cells + 1];
        let cell: Vec<usize> = pts.iter().map(|&p| cell_of(p)).collect();
        for &c in &cell {
            start[c + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut sorted = vec![DVec3::ZERO; n];
        for (&p, &c) in pts.iter().zip(&cell) {
            sorted[fill[c]] = p;
            fill[c] += 1;
        }
        // Distinct positions per cell, with counts.
        let (mut points, mut count) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let mut new_start = vec![0usize; cells + 1];
        for c in 0..cells {
            let run = &mut sorted[start[c]..start[c + 1]];
            run.sort_unstable_by(|a, b| {
                (a.x.total_cmp(&b.x))
                    .then(a.y.total_cmp(&b.y))
                    .then(a.z.total_cmp(&b.z))
            });
            for &p in run.iter() {
                if points.len() > new_start[c] && points.last() == Some(&p) {
                    *count.last_mut().unwrap() += 1;
                } else {
                    points.push(p);
                    count.push(1);
                }
            }
            new_start[c + 1] = points.len();
        }
        if points.len() < 2 {
            return None;
        }
        // Cell indices are rounded: |x - lo| / h is off by a few eps (|x| + |lo|) / h.
        let size = lo.abs().max(hi.abs()).max_element() / h;
        let slack =
            8.0 * f64::EPSILON * (size + dims.iter().max().copied().unwrap_or(1) as f64 + 2.0);
        Some(Grid {
            lo,
            h,
            dims,
            start: new_start,
            points,
            count,
            slack,
        })
    }

    /// Squared distance from position `k` to the nearest other position.
    fn nearest(&self, k: usize) -> f64 {
        let p = self.points[k];
        let t = ((p - self.lo) / self.h).to_array();
        let dims = self.dims.map(|d| d as isize);
        let at: [isize; 3] = std::array::from_fn(|a| (t[a].max(0.0) as isize).min(dims[a] - 1));
        let mut best = f64::INFINITY;
        // Positions in cells x0..=x1 of row (y, z): one slice, cells being sorted.
        let scan = |best: &mut f64, y: isize, z: isize, x0: isize, x1: isize| {
            let row = (y + dims[1] * z) * dims[0];
            let (a, b) = (
                self.start[(row + x0) as usize],
                self.start[(row + x1) as usize + 1],
            );
            for (j, q) in self.points[a..b].iter().enumerate() {
                let d2 = (*q - p).length_squared();
                if d2 < *best && a + j != k {
                    *best = d2;
                }
            }
        };
        let mut s = 0isize;
        loop {
            // The shell of cells `s` away (Chebyshev) from `at`, clipped to the grid.
            let lo = at.map(|c| (c - s).max(0));
            let hi: [isize; 3] = std::array::from_fn(|a| (at[a] + s).min(dims[a] - 1));
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    if s == 0 || (z - at[2]).abs() == s || (y - at[1]).abs() == s {
                        scan(&mut best, y, z, lo[0], hi[0]);
                    } else {
                        if at[0] - s >= 0 {
                            scan(&mut best, y, z, at[0] - s, at[0] - s);
                        }
                        if at[0] + s < dims[0] {
                            scan(&mut best, y, z, at[0] + s, at[0] + s);
                        }
                    }
                }
            }
            // Unvisited cells lie beyond the block's walls that are not the grid's; their
            // points are farther than the nearest such wall, less the index rounding.
            let mut wall = f64::INFINITY;
            for a in 0..3 {
                if at[a] - s > 0 {
                    wall = wall.min(t[a] - (at[a] - s) as f64);
                }
                if at[a] + s < dims[a] - 1 {
                    wall = wall.min((at[a] + s + 1) as f64 - t[a]);
                }
            }
            if wall == f64::INFINITY {
                return best;
            }
            let reach = (wall - self.slack) * self.h;
            if reach > 0.0 && best <= reach * reach {
                return best;
            }
            s += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Rng;

    /// O(n^2): the same definition, point by point.
    fn brute(points: &[DVec3]) -> Option<f64> {
        let pts: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
        let mut d: Vec<f64> = Vec::new();
        for &p in &pts {
            let best = pts
                .iter()
                .filter(|&&q| q != p)
                .map(|&q| (q - p).length())
                .fold(f64::INFINITY, f64::min);
            if best.is_finite() {
                d.push(best);
            }
        }
        if d.len() < pts.len() || d.is_empty() {
            return None; // some point has no distinct neighbour: one position only
        }
        d.sort_by(f64::total_cmp);
        let m = d.len() / 2;
        Some(if d.len() % 2 == 1 {
            d[m]
        } else {
            0.5 * (d[m - 1] + d[m])
        })
    }

    fn random_set(rng: &mut Rng, kind: usize) -> Vec<DVec3> {
        let n = 1 + rng.below(600);
        let scale = rng.log10(-6.0, 6.0);
        let shift = scale * rng.range(-100.0, 100.0);
        let u = |rng: &mut Rng| DVec3::new(rng.f(), rng.f(), rng.f());
        let mut pts: Vec<DVec3> = match kind {
            // Uniform in a box.
            0 => (0..n).map(|_| u(rng)).collect(),
            // A few tight clusters far apart.
            1 => {
                let centres: Vec<DVec3> = (0..1 + rng.below(5)).map(|_| u(rng) * 1e3).collect();
                (0..n)
                    .map(|_| centres[rng.below(centres.len())] + u(rng) * rng.log10(-4.0, 0.0))
                    .collect()
            }
            // In a plane, on a line, or on a small integer lattice (many ties and repeats).
            2 => (0..n).map(|_| DVec3::new(rng.f(), rng.f(), 0.5)).collect(),
            3 => (0..n).map(|_| DVec3::new(rng.f(), 2.0, 3.0)).collect(),
            4 => (0..n)
                .map(|_| {
                    DVec3::new(
                        rng.below(4) as f64,
                        rng.below(4) as f64,
                        rng.below(2) as f64,
                    )
                })
                .collect(),
            // Uniform with a few far outliers.
            _ => (0..n)
                .map(|_| if rng.f() < 0.03 { u(rng) * 1e6 } else { u(rng) })
                .collect(),
        };
        // Duplicates, -0.0, non-finite points.
        for _ in 0..rng.below(n / 2 + 1) {
            let p = pts[rng.below(pts.len())];
            pts.push(p);
        }
        let mut pts: Vec<DVec3> = pts.into_iter().map(|p| p * scale + shift).collect();
        if rng.f() < 0.2 {
            pts.push(DVec3::new(-0.0, 0.0, 0.0));
            pts.push(DVec3::new(0.0, -0.0, 0.0));
        }
        if rng.f() < 0.2 {
            pts.push(DVec3::new(f64::NAN, 0.0, 0.0));
            pts.push(DVec3::splat(f64::INFINITY));
        }
        pts
    }

    #[test]
    fn matches_brute_force() {
        let mut rng = Rng::new(0xd15);
        let mut some = [0usize; 6];
        for case in 0..600 {
            let kind = case % 6;
            let pts = random_set(&mut rng, kind);
            let want = brute(&pts);
            assert_eq!(
                median_nearest_distance(&pts),
                want,
                "case {case} kind {kind}"
            );
            some[kind] += want.is_some() as usize;
        }
        assert!(some.iter().all(|&s| s > 80), "{some:?}");
    }

    #[test]
    fn known_values_and_none() {
        assert_eq!(median_nearest_distance(&[]), None);
        assert_eq!(median_nearest_distance(&[DVec3::ONE]), None);
        assert_eq!(median_nearest_distance(&[DVec3::ONE; 50]), None);
        assert_eq!(
            median_nearest_distance(&[DVec3::ZERO, DVec3::new(-0.0, 0.0, -0.0), DVec3::NAN]),
            None
        );
        // Spacing 1 on a line, a far point: distances 1, 1, 1, 1, 1e3 - 3.
        let mut line: Vec<DVec3> = (0..4).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        line.push(DVec3::new(1e3, 0.0, 0.0));
        assert_eq!(median_nearest_distance(&line), Some(1.0));
        // Two points: even count, both at distance 5.
        let two = [DVec3::ZERO, DVec3::new(3.0, 4.0, 0.0)];
        assert_eq!(median_nearest_distance(&two), Some(5.0));
        // Even count, mean of the middle two: distances 1, 1, 2, 2 (two pairs).
        let pairs = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(12.0, 0.0, 0.0),
        ];
        assert_eq!(median_nearest_distance(&pairs), Some(1.5));
        // A simple cubic lattice, spacing 0.25, copied twice: every distance 0.25.
        let mut lattice = Vec::new();
        for i in 0..1000 {
            let p = DVec3::new((i % 10) as f64, (i / 10 % 10) as f64, (i / 100) as f64) * 0.25;
            lattice.extend([p, p]);
        }
        assert_eq!(median_nearest_distance(&lattice), Some(0.25));
    }
}
