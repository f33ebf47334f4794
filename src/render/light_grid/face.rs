//! One face of a light's frame: a grid of square cells, each listing the spheres whose
//! silhouettes cover it by their distance from the light, and the walk of a line through the
//! cells.

use glam::DVec2;

/// One face of a light's frame: a grid of `n.0 x n.1` square cells of side `h` from `lo`.
#[derive(Debug, Default)]
pub(super) struct Face {
    /// Point lights: the face's axis, its sign and the two in-face axes (unused otherwise).
    pub(super) axis: (usize, f64, usize, usize),
    pub(super) lo: DVec2,
    pub(super) h: f64,
    pub(super) inv_h: f64,
    pub(super) n: (usize, usize),
    /// Rounding allowance of coordinates on this face.
    pub(super) pad: f64,
    /// Cell `k` holds `entries[start[k] .. start[k + 1]]`, sorted by distance.
    pub(super) start: Vec<u32>,
    /// Per cell, the largest radius (distance units) of a sphere listed there, rounded up.
    pub(super) reach: Vec<f32>,
    /// (distance of the centre as f32, primitive index).
    pub(super) entries: Vec<(f32, u32)>,
}

impl Face {
    /// An empty grid over the rectangle `lo..hi` holding `listed` silhouettes, whose widths
    /// `widths` sample: cells twice the typical width (about 2.25 cells a sphere), but no more
    /// cells than spheres.
    pub(super) fn sized(
        axis: (usize, f64, usize, usize),
        (lo, hi): (DVec2, DVec2),
        widths: &mut [f64],
        listed: usize,
        pad: f64,
    ) -> Face {
        if widths.is_empty() {
            return Face {
                axis,
                start: vec![0],
                ..Face::default()
            };
        }
        let mid = widths.len() / 2;
        let median = *widths.select_nth_unstable_by(mid, f64::total_cmp).1;
        let extent = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
        let mut h = (2.0 * median).max(extent.max_element() * 1e-6);
        if extent.x / h * (extent.y / h) > listed as f64 {
            h = (extent.x * extent.y / listed as f64).sqrt();
        }
        let n = (
            ((extent.x / h).ceil() as usize).clamp(1, 1 << 15),
            ((extent.y / h).ceil() as usize).clamp(1, 1 << 15),
        );
        // The grid covers [lo, lo + n h], at least the rectangle.
        let h = h.max(extent.x / n.0 as f64).max(extent.y / n.1 as f64) * (1.0 + 1e-12);
        Face {
            axis,
            lo,
            h,
            inv_h: 1.0 / h,
            n,
            pad,
            start: vec![0; n.0 * n.1 + 1],
            reach: vec![0.0; n.0 * n.1],
            entries: Vec::new(),
        }
    }

    pub(super) fn cells(&self) -> usize {
        self.n.0 * self.n.1
    }

    /// The cell range `(i0, i1, j0, j1)` (inclusive) a rectangle covers.
    pub(super) fn cover(&self, lo: DVec2, hi: DVec2) -> (usize, usize, usize, usize) {
        let cell = |x: f64, o: f64, n: usize| (((x - o) * self.inv_h).max(0.0) as usize).min(n - 1);
        (
            cell(lo.x, self.lo.x, self.n.0),
            cell(hi.x, self.lo.x, self.n.0),
            cell(lo.y, self.lo.y, self.n.1),
            cell(hi.y, self.lo.y, self.n.1),
        )
    }

    /// Calls `visit(cell)` for every cell within `pad` (plus a little) of the segment `p q`.
    pub(super) fn walk(&self, p: DVec2, q: DVec2, pad: f64, mut visit: impl FnMut(usize)) {
        let pad = pad + 1e-9 * self.h;
        let (ny, nx) = (self.n.1, self.n.0);
        let top = self.lo.y + ny as f64 * self.h;
        let right = self.lo.x + nx as f64 * self.h;
        let (ymin, ymax) = (p.y.min(q.y) - pad, p.y.max(q.y) + pad);
        if ymax < self.lo.y || ymin > top || p.x.max(q.x) + pad < self.lo.x {
            return;
        }
        if p.x.min(q.x) - pad > right {
            return;
        }
        let row = |y: f64| (((y - self.lo.y) * self.inv_h).max(0.0) as usize).min(ny - 1);
        let d = q - p;
        for j in row(ymin)..=row(ymax) {
            let y0 = self.lo.y + j as f64 * self.h - pad;
            let y1 = y0 + self.h + 2.0 * pad;
            // The part of the segment within the row (grown by pad), as parameters in [0, 1].
            let (mut s0, mut s1) = (0.0f64, 1.0f64);
            if d.y != 0.0 {
                let (a, b) = ((y0 - p.y) / d.y, (y1 - p.y) / d.y);
                s0 = s0.max(a.min(b));
                s1 = s1.min(a.max(b));
                if s0 > s1 {
                    continue;
                }
            }
            let (xa, xb) = (p.x + s0 * d.x, p.x + s1 * d.x);
            let (x0, x1) = (xa.min(xb) - pad, xa.max(xb) + pad);
            if x1 < self.lo.x || x0 > right {
                continue;
            }
            let col = |x: f64| (((x - self.lo.x) * self.inv_h).max(0.0) as usize).min(nx - 1);
            for i in col(x0)..=col(x1) {
                visit(j * nx + i);
            }
        }
    }

    /// Appends the spheres of `cell` whose distance key may lie within `[k0, k1]` grown by
    /// their radius.
    pub(super) fn scan(&self, cell: usize, (k0, k1): (f64, f64), out: &mut Vec<u32>) {
        let (a, b) = (self.start[cell] as usize, self.start[cell + 1] as usize);
        if a == b {
            return;
        }
        let r = self.reach[cell] as f64;
        // f32 keys: a relative margin far above their rounding (2^-24).
        let lo = k0 - r - 1e-6 * (k0.abs() + r);
        let hi = k1 + r + 1e-6 * (k1.abs() + r);
        let list = &self.entries[a..b];
        let from = list.partition_point(|e| (e.0 as f64) < lo);
        for e in &list[from..] {
            if e.0 as f64 > hi {
                break;
            }
            out.push(e.1);
        }
    }
}
