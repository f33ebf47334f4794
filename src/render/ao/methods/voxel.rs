//! Ambient occlusion by voxel cone tracing, as MegaMol's sphere renderer computes it in its
//! `Ambient_Occlusion` mode (MDAO): the spheres' volume splatted into a density grid with
//! mip levels, and three cones about the normal marched through it (S. Grottel et al.,
//! MegaMol, <https://github.com/UniStuttgart-VISUS/megamol>, `plugins/moldyn_gl`:
//! `SphereRenderer.cpp`, `misc/MDAOVolumeGenerator.cpp`, and the shaders
//! `mdao_volume_generator/inc/mdao_volume_{geometry,fragment}_main.inc.glsl`,
//! `sphere_renderer/inc/mdao_deferred_fragment_ambocc.inc.glsl`; cone tracing after
//! C. Crassin et al., "Interactive Indirect Illumination Using Voxel Cone Tracing", Computer
//! Graphics Forum 30(7), 2011).
//!
//! MegaMol's parameters and defaults ([`VoxelSettings::MEGAMOL`]): `ao::volsize` 128 voxels
//! along the longest edge, `ao::apex` 50 degrees, `ao::offset` 0.01, `ao::strength` 1,
//! `ao::conelen` 0.8 (offset and length in units of the scene's box).
//!
//! What follows MegaMol:
//! - the grid covers the box of the spheres with cubic voxels, [`VoxelSettings::resolution`]
//!   along its longest edge;
//! - a voxel's share of a sphere: 0 if it lies outside, 1 if its farthest corner is inside,
//!   else the fraction of its 27 points (corners, edge and face midpoints, centre) inside
//!   the sphere; the spheres' shares add, clamped at 1 (additive blending into an 8-bit
//!   texture);
//! - mip levels of 2x2x2 means, up to level `ceil(log2 resolution) - 1`; a lookup is
//!   trilinear within a level and linear between levels (`GL_LINEAR_MIPMAP_LINEAR`), 0
//!   outside the grid (`GL_CLAMP_TO_BORDER`);
//! - three cones whose axes lie `atan(r / h)` (29.2 degrees at a 50-degree apex) from the
//!   normal, 120 degrees apart, each of diameter `w t` at distance `t`,
//!   `w = 2 tan(apex / 2)` (`generate3ConeDirections`);
//! - each cone is marched from `t = offset + 0.0001`, reading the level
//!   `log2(w t / voxel)` at `x + t axis`, accumulating `a += (1 - a) density` front to back,
//!   stopping once `a > 0.99`, stepping `t += w t` while `t` is shorter than the cone; the
//!   unoccluded fraction is `1 - clamp(strength (a_1 + a_2 + a_3) / 3, 0, 1)`.
//!
//! What is simplified or differs:
//! - densities are f32, not 8-bit (no quantisation to 1/255);
//! - a voxel is outside a sphere when its closest point is: MegaMol's shader takes, per
//!   axis, the nearer face's distance, which wrongly discards voxels that a sphere's centre
//!   lies across (every voxel holding a whole sphere among them, so that its branch for a
//!   sphere inside one voxel is never reached); here those voxels count, a sphere inside one
//!   voxel adding its volume's share;
//! - distances are world distances, the box's longest edge standing for MegaMol's unit (its
//!   coordinates are normalised per axis, which stretches the cones in a box that is not a
//!   cube; the two agree in a cube); a finite reach is the cones' length, and with an
//!   unlimited reach `cone_length` of the longest edge is;
//! - the cones' frame: MegaMol turns them about the normal by `cross(n, position)` left
//!   unnormalised, which also tilts them towards the normal by the sine of the angle
//!   between the two; here that vector is normalised (any perpendicular where it vanishes);
//! - mip sizes halve rounding down, a texel the mean of the children present (MegaMol: a
//!   compute shader's 8-texel sums over 8, or the driver's `glGenerateMipmap`); the grid's
//!   first side is not rounded up to a multiple of 4;
//! - the shading point is the exact hit, not one reconstructed from a depth buffer.
//!
//! The sphere the point is on is in the grid, so the method occludes a point by its own
//! sphere: at the default settings, the surface of a sphere that nothing occludes gets 0.82
//! on average (0.79 at least) when the sphere fills the grid, 64 voxels a radius, and 0.90
//! (0.73 at least) at 3.2 voxels a radius, as in a box 40 radii across, rather than 1
//! (`methods::tests`, reach 1 radius or unlimited alike).
//!
//! The grid is built once per render ([`crate::render::View::ao_grid`]), on one thread: 4
//! bytes a voxel, and a seventh more for the mip levels, at most `resolution³` voxels (9.6
//! MB at 128; the resolution is at most 512, 614 MB).

use glam::DVec3;

/// The voxel method's parameters, MegaMol's `ao::` parameters (see the module comment).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelSettings {
    /// Voxels along the longest edge of the scene's box (`ao::volsize`), 2 to 512.
    pub resolution: u32,
    /// The cones' full aperture in degrees (`ao::apex`), 1 to 90.
    pub apex_degrees: f64,
    /// Where the cones start, a fraction of the box's longest edge (`ao::offset`), 0 to 0.2.
    pub offset: f64,
    /// The factor of the cones' mean occlusion (`ao::strength`), 0.1 to 20.
    pub strength: f64,
    /// The cones' length with an unlimited reach, a fraction of the box's longest edge
    /// (`ao::conelen`), 0.01 to 1; a finite reach is the length.
    pub cone_length: f64,
}

impl VoxelSettings {
    /// MegaMol's defaults.
    pub const MEGAMOL: VoxelSettings = VoxelSettings {
        resolution: 128,
        apex_degrees: 50.0,
        offset: 0.01,
        strength: 1.0,
        cone_length: 0.8,
    };

    /// Checks each parameter against its range (MegaMol's, the resolution's upper end
    /// lowered from 1024 to 512 for memory).
    pub fn check(&self) -> Result<(), String> {
        let ranges = [
            ("apex_degrees", self.apex_degrees, 1.0, 90.0),
            ("offset", self.offset, 0.0, 0.2),
            ("strength", self.strength, 0.1, 20.0),
            ("cone_length", self.cone_length, 0.01, 1.0),
        ];
        if !(2..=512).contains(&self.resolution) {
            return Err(format!(
                "the voxel AO method's resolution = {}: from 2 to 512 voxels",
                self.resolution
            ));
        }
        for (name, v, lo, hi) in ranges {
            if !(lo..=hi).contains(&v) {
                return Err(format!(
                    "the voxel AO method's {name} = {v}: from {lo} to {hi}"
                ));
            }
        }
        Ok(())
    }
}

impl Default for VoxelSettings {
    fn default() -> Self {
        VoxelSettings::MEGAMOL
    }
}

/// One mip level: its size in texels and their densities, x fastest.
struct Level {
    dims: [usize; 3],
    data: Vec<f32>,
}

impl Level {
    fn at(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }
}

/// The spheres' density grid with its mip levels.
pub struct Grid {
    /// The grid's lower corner.
    lo: DVec3,
    /// Its size along each axis (texels of level 0 times the voxel's side).
    extent: DVec3,
    /// The side of a voxel of level 0.
    voxel: f64,
    /// The longest edge of the spheres' box: the unit of the offset and the cone length.
    edge: f64,
    levels: Vec<Level>,
}

impl Grid {
    /// The grid of the balls `(centre, radius)` in the box `lo..hi`, `resolution` voxels
    /// along its longest edge (see the module comment). An empty or degenerate box gives a
    /// grid of one empty voxel.
    pub fn build(
        balls: impl Iterator<Item = (DVec3, f64)>,
        (lo, hi): (DVec3, DVec3),
        resolution: u32,
    ) -> Grid {
        let size = hi - lo;
        let edge = size.max_element();
        if !(edge > 0.0 && edge.is_finite() && lo.is_finite()) {
            return Grid {
                lo: DVec3::ZERO,
                extent: DVec3::ONE,
                voxel: 1.0,
                edge: 1.0,
                levels: vec![Level {
                    dims: [1; 3],
                    data: vec![0.0],
                }],
            };
        }
        let h = edge / f64::from(resolution);
        let dims = size
            .to_array()
            .map(|s| ((s / h - 1e-9).ceil() as usize).clamp(1, resolution as usize));
        let mut base = Level {
            dims,
            data: vec![0.0; dims[0] * dims[1] * dims[2]],
        };
        let last = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) - 1.0;
        for (c, r) in balls {
            let first = ((c - r - lo) / h).floor().clamp(DVec3::ZERO, last);
            let end = ((c + r - lo) / h).floor().clamp(DVec3::ZERO, last);
            let (first, end) = (first.as_uvec3(), end.as_uvec3());
            for k in first.z..=end.z {
                for j in first.y..=end.y {
                    for i in first.x..=end.x {
                        let corner = lo + DVec3::new(f64::from(i), f64::from(j), f64::from(k)) * h;
                        let share = coverage(c, r, corner, h);
                        if share > 0.0 {
                            let at = base.at(i as usize, j as usize, k as usize);
                            base.data[at] = (f64::from(base.data[at]) + share).min(1.0) as f32;
                        }
                    }
                }
            }
        }
        let top = (f64::from(resolution).log2().ceil() - 1.0).max(0.0) as usize;
        let mut levels = vec![base];
        while levels.len() <= top {
            let below = levels.last().expect("level 0 is there");
            if below.dims == [1; 3] {
                break;
            }
            levels.push(halve(below));
        }
        Grid {
            lo,
            extent: DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * h,
            voxel: h,
            edge,
            levels,
        }
    }

    /// Texels of level 0 along each axis.
    pub fn dims(&self) -> [usize; 3] {
        self.levels[0].dims
    }

    /// Mip levels, level 0 included.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Bytes the densities take.
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.data.len() * 4).sum()
    }

    /// The density at `p` read at level of detail `lod` (clamped to the levels there are),
    /// trilinear within a level and linear between the two levels around `lod`.
    pub fn density(&self, p: DVec3, lod: f64) -> f64 {
        let lod = lod.clamp(0.0, (self.levels.len() - 1) as f64);
        let l0 = lod.floor() as usize;
        let f = lod - l0 as f64;
        let a = self.trilinear(l0, p);
        if f == 0.0 {
            a
        } else {
            a + (self.trilinear(l0 + 1, p) - a) * f
        }
    }

    /// The trilinear lookup of level `l` at `p`, texel centres at half-integers and 0
    /// outside the grid.
    fn trilinear(&self, l: usize, p: DVec3) -> f64 {
        let level = &self.levels[l];
        let dims = level.dims;
        let n = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        let u = (p - self.lo) / self.extent * n - 0.5;
        let base = u.floor();
        let f = u - base;
        let texel = |i: f64, j: f64, k: f64| -> f64 {
            let inside = |v: f64, d: usize| v >= 0.0 && v < d as f64;
            if inside(i, dims[0]) && inside(j, dims[1]) && inside(k, dims[2]) {
                f64::from(level.data[level.at(i as usize, j as usize, k as usize)])
            } else {
                0.0
            }
        };
        let mut sum = 0.0;
        for corner in 0..8 {
            let o = DVec3::new(
                f64::from(corner & 1),
                f64::from((corner >> 1) & 1),
                f64::from(corner >> 2),
            );
            let w = (o * f + (DVec3::ONE - o) * (DVec3::ONE - f)).element_product();
            if w > 0.0 {
                let t = base + o;
                sum += w * texel(t.x, t.y, t.z);
            }
        }
        sum
    }
}

/// The next mip level: half the texels (rounded down, at least 1) along each axis, each the
/// mean of its children that exist.
fn halve(below: &Level) -> Level {
    let d = below.dims;
    let dims = d.map(|n| (n / 2).max(1));
    let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let (mut sum, mut count) = (0.0f64, 0u32);
                for kk in 2 * k..(2 * k + 2).min(d[2]) {
                    for jj in 2 * j..(2 * j + 2).min(d[1]) {
                        for ii in 2 * i..(2 * i + 2).min(d[0]) {
                            sum += f64::from(below.data[below.at(ii, jj, kk)]);
                            count += 1;
                        }
                    }
                }
                data.push((sum / f64::from(count)) as f32);
            }
        }
    }
    Level { dims, data }
}

/// The share of the cubic voxel of lower corner `corner` and side `h` that the ball of
/// centre `c` and radius `r` fills, as the module comment says.
fn coverage(c: DVec3, r: f64, corner: DVec3, h: f64) -> f64 {
    let top = corner + h;
    let r2 = r * r;
    if (c.clamp(corner, top) - c).length_squared() >= r2 {
        return 0.0;
    }
    let far = (corner - c).abs().max((top - c).abs());
    if far.length_squared() <= r2 {
        return 1.0;
    }
    if (c - r).cmpge(corner).all() && (c + r).cmple(top).all() {
        return 4.0 / 3.0 * std::f64::consts::PI * r2 * r / (h * h * h);
    }
    let mut inside = 0u32;
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let q = corner + DVec3::new(f64::from(i), f64::from(j), f64::from(k)) * (0.5 * h);
                inside += u32::from((q - c).length_squared() < r2);
            }
        }
    }
    f64::from(inside) / 27.0
}

/// The three cones' axes in a frame whose y axis is the normal, for cones of diameter `w`
/// per unit of length (MegaMol's `generate3ConeDirections`).
pub fn cone_axes(w: f64) -> [DVec3; 3] {
    let height = (1.0 - w * w / 12.0).sqrt();
    let radius = 3f64.sqrt() / 3.0 * w;
    [0.0, 1.0, 2.0].map(|i: f64| {
        let (s, c) = (i / 3.0 * std::f64::consts::TAU).sin_cos();
        DVec3::new(c * radius, height, s * radius).normalize()
    })
}

/// The unoccluded fraction at `x` (unit normal `n`) by the cones of `v` through `grid`,
/// `reach` long when finite (see the module comment).
pub fn unoccluded(grid: &Grid, v: &VoxelSettings, reach: f64, (x, n): (DVec3, DVec3)) -> f64 {
    let w = 2.0 * (0.5 * v.apex_degrees.to_radians()).tan();
    let ex = n.cross(x.normalize_or_zero());
    let ex = if ex.length_squared() > 1e-20 {
        ex.normalize()
    } else {
        n.any_orthonormal_vector()
    };
    let ez = ex.cross(n);
    let length = if reach.is_finite() {
        reach
    } else {
        v.cone_length * grid.edge
    };
    let mut total = 0.0;
    for a in cone_axes(w) {
        let axis = ex * a.x + n * a.y + ez * a.z;
        let (mut occluded, mut t) = (0.0, (v.offset + 1e-4) * grid.edge);
        loop {
            let lod = (t * w / grid.voxel).log2();
            occluded += (1.0 - occluded) * grid.density(x + axis * t, lod);
            if occluded > 0.99 {
                break;
            }
            t += t * w;
            if t >= length {
                break;
            }
        }
        total += occluded;
    }
    1.0 - (v.strength * total / 3.0).clamp(0.0, 1.0)
}
