//! The ambient-occlusion dimension: scenes through `Integrator::Ao` (exact method, the centre
//! sampler), each pixel against a Monte Carlo estimate written here from docs/model.md
//! section 11 with the matrix's own geometry.
//!
//! - **Which scenes.** AO takes opaque spheres, triangles and Boxes exactly, and Cylinders
//!   and Cones (the generator's have all their parts) and gas spheres to a tolerance drawn by
//!   seed ([`tolerance`]), with an error channel per pixel: a bound where Cylinders or Cones
//!   occlude, an estimate where gas does. A scene with gas spheres *and* Cylinders or Cones
//!   (counted from its description, not from the library's answer) must be refused with an
//!   error that gives both counts; its *AO part*, the same tree without the gas, is checked
//!   instead. Every other scene is checked whole, its gas included. The generator scales
//!   uniformly only: it makes no ellipsoids.
//! - **Reach and weighting**, by seed ([`settings`]): infinite in half the scenes, else
//!   log-uniform from 0.1 to 3 world units (the scenes span about 3); cosine or uniform.
//! - **The reference** ([`reference`]): the pixel-centre ray's first opaque hit
//!   (`World::first_opaque`; gas is not a surface: the camera ray passes through it) and its
//!   normal on the viewer's side; AO 0 if that point is inside another opaque sphere or Box;
//!   else the mean of the visibility `V` over [`SIDE`]^2 directions, one in each cell of a
//!   grid on the unit square mapped onto the hemisphere (cosine- or uniformly-weighted, so
//!   each cell has equal weight). `V` is 0 if the direction meets another opaque primitive
//!   within the reach (the matrix's ray/sphere roots and `surface_reference::blocks_from`,
//!   a bounding sphere first, to skip the primitives the direction misses by far), else
//!   `exp(-tau)`, `tau` the optical depth of the gas spheres along it from the point (from
//!   the point itself when it is inside one) to the reach: each chord's integral of the
//!   density in closed form ([`gas_depth`]), which the self-tests hold to the quadrature of
//!   `World::depth`, and the reference as a whole to a thin-gas closed form and to
//!   one-dimensional integrals (`selftest.rs`).
//! - **The check** ([`check`]): `|library - p| <= z sigma + 1e-9 + err`, `err` the
//!   library's error channel at the pixel (0 where neither Cylinders, Cones nor gas
//!   occlude), with `sigma = sqrt(max(p (1 - p), q (1 - q)) / N)`, `q = min(z^2 / N, 1/2)`,
//!   and `z` from Bonferroni over every AO pixel of the run. A direction's `V` lies in
//!   [0, 1], so its variance is at most `p (1 - p)` for mean `p` (`E[V^2] <= E[V]`; equal
//!   when `V` is 0 or 1, without gas), and stratification only lowers the variance of the
//!   mean: the binomial sigma is an upper bound. The floor `q`: when the true value is
//!   `1 - e`, the directions with `V < 1` have measure at least `e`, and all N directions
//!   miss them with probability at most `exp(-e N)` (a stratified draw misses them no more
//!   often), so a reference that sees `p = 1` (or 0) may be off by up to about
//!   `ln(1 / alpha) / N = z^2 / (2 N)`; the floor allows `z^2 / N`, Wilson's bound at
//!   `p = 0`. Over the run, the summed error `sum (library - p)` of the pixels whose error
//!   channel is at most [`BIAS_ERR`] sigma must be within `z_1 sqrt(sum sigma^2)` plus
//!   their summed error channels, `z_1` for the false-alarm rate alone (a bias too small
//!   for any one pixel; the pixels' estimates are independent).
//! - **Exact cases**: a point with no other primitive, opaque or gas (of extinction above
//!   0), reaching above its tangent plane within the reach (by more than rounding) must be
//!   exactly 1 (or within the library's bound of it: the polyhedron about a Cylinder or Cone
//!   may rise where the solid does not); a point inside another opaque sphere or Box exactly
//!   0; a miss the background; every hit grey (R = G = B). A point within rounding of
//!   another opaque primitive's surface is left out (counted), where the library's rule for
//!   a point on a sphere or a face decides; a gas sphere's surface needs no such rule (the
//!   chord from the point is the same either side).
//! - **Cost**: [`SIDE`] = 256, N = 65 536 directions, in every scene. The CI run (`cargo
//!   test -p gtsphere --test it verify_matrix -- --nocapture`, which prints the seconds per
//!   dimension; 2 cores, shared), 307 scenes of which 84 are checked whole (59 with gas) and
//!   223 by their AO part, 5 523 pixels estimated (490 through gas): 33.3 s in `ao` of a
//!   125 s run, almost all of it the reference's directions; with every gas scene checked by
//!   its AO part instead (no gas rendered) `ao` took 33.0 s on the same machine, so gas at
//!   tolerances down to 1e-4 costs about a second (runs of the same code on that machine
//!   differ by a few seconds). With N = 2 304 (0.2 s for 48 scenes) a
//!   pixel's error would have to pass 0.06 at p = 1/2 to show; at 65 536 it is 0.011 there,
//!   2e-3 at p = 0.99 and 5e-4 at p = 1.
//! - **What the gas pixels show** (the soak's first 1 000 scenes, `VERIFY_FIRST=1000000
//!   VERIFY_SCENES=1000 cargo test -p gtsphere --test it verify_soak -- --ignored
//!   --nocapture`: 1 164 pixels through gas): the library's error channel is a median 0.03
//!   sigma (0.9 of the pixels below 1.2 sigma, the largest 27); the error over sigma has
//!   mean 0.005, spread 0.13 and largest magnitude 1.23 (0.82 beyond the channel): the
//!   stratified directions err far less than the binomial sigma allows.

use glam::{DAffine3, DVec3};
use gtsphere::render::ao::{AoMethod, AoSettings, Weighting};
use gtsphere::render::Film;

use super::reference::gas_depth::gas_depth;
use super::reference::sphere_roots;
use super::scenes::SceneDesc;
use super::world::{Gas, Solid, World};
use crate::support::Rng;
use crate::surface_reference::{blocks_from, RefShape};

mod refusal;
pub use refusal::{ao_part, Unsupported};

/// Directions per pixel: a `SIDE` x `SIDE` grid.
pub const SIDE: u32 = 256;

/// The pixels in the summed error ([`Tally::bias_z`]) are those whose error channel is at
/// most this many sigma, so that the channels they add to its allowance stay small against
/// `z_1 sqrt(sum sigma^2)` (at 1/100, up to ten thousand pixels add less than a third
/// of it): every pixel without Cylinders, Cones or gas, and most through gas.
const BIAS_ERR: f64 = 0.01;

/// Room for the rounding of a hit point, relative to the scene's unit and the point's
/// distance from the origin.
const BAND: f64 = 1e-9;

/// The reach and weighting scene `seed` is rendered with.
pub fn settings(seed: u64) -> AoSettings {
    let mut rng = Rng::new(seed ^ 0xa0_5e77_1295);
    let reach = if rng.f() < 0.5 {
        f64::INFINITY
    } else {
        rng.log10(-1.0, 0.5)
    };
    let weighting = if rng.f() < 0.5 {
        Weighting::Cosine
    } else {
        Weighting::Uniform
    };
    AoSettings {
        reach,
        weighting,
        colours: false,
        method: AoMethod::Exact,
    }
}

/// The tolerance scene `seed`'s AO is rendered at (`--tol`): the bound of its error where
/// Cylinders or Cones occlude and the target of its estimate where gas does, from 1e-2 to
/// 1e-4 (tighter ones cost the CI run more than they tell: the error channel and the
/// reference's sigma, about 2e-3, are then far apart anyway). Gas scenes take the same
/// range: their nested quadrature costs the CI run about a second over it (module comment).
pub fn tolerance(seed: u64) -> f64 {
    Rng::new(seed ^ 0x70_1e7a_9ce5).log10(-4.0, -2.0)
}

/// The command line's AO options for `s` at the tolerance `tol`.
pub fn cli_args(s: &AoSettings, tol: f64) -> String {
    let mut out = format!("--integrator ao --tol {tol:e}");
    if s.reach.is_finite() {
        out.push_str(&format!(" --ao-reach {:e}", s.reach));
    }
    let w = match s.weighting {
        Weighting::Cosine => "cosine",
        Weighting::Uniform => "uniform",
    };
    out.push_str(&format!(" --ao-weighting {w}"));
    out
}

/// The reference at one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AoRef {
    /// The ray meets nothing: the background.
    Miss,
    /// The hit point is inside another sphere or solid: exactly 0.
    Inside,
    /// Nothing (opaque or gas) rises above the hit point's tangent plane within the reach:
    /// exactly 1.
    Open,
    /// The mean visibility over the directions traced, `p`; `gas`: gas spheres were among
    /// the occluders traced.
    Estimate { p: f64, gas: bool },
    /// The hit point is within rounding of another primitive's surface: not checked.
    OnAnother,
}

/// An occluder as the reference traces it: its primitive, its solid, and a sphere that
/// bounds it.
struct Occluder {
    k: usize,
    solid: Solid,
    centre: DVec3,
    radius: f64,
    /// Corners of its convex hull (Boxes and triangles), or of a box holding it (Cylinders
    /// and Cones).
    corners: Vec<DVec3>,
}

fn occluders(world: &World) -> Vec<Occluder> {
    let mut out = Vec::new();
    for (k, p) in world.prims.iter().enumerate() {
        if p.gas().is_some() {
            continue;
        }
        match p.solid {
            Solid::Sphere { c, r } => out.push(Occluder {
                k,
                solid: p.solid,
                centre: c,
                radius: r,
                corners: Vec::new(),
            }),
            Solid::Surface { shape, to_world } => {
                let corners: Vec<DVec3> = match shape {
                    RefShape::Triangle { p } => p.to_vec(),
                    RefShape::Cuboid { size } => box_corners(size / 2.0, &to_world),
                    RefShape::Cylinder { r, h } | RefShape::Cone { r, h } => {
                        box_corners(DVec3::new(r, h / 2.0, r), &to_world)
                    }
                };
                let centre = corners.iter().copied().sum::<DVec3>() / corners.len() as f64;
                let radius = corners
                    .iter()
                    .map(|q| (*q - centre).length())
                    .fold(0.0f64, f64::max);
                out.push(Occluder {
                    k,
                    solid: p.solid,
                    centre,
                    radius: radius * (1.0 + 1e-12),
                    corners,
                });
            }
        }
    }
    out
}

/// The gas spheres of `world` that attenuate (extinction above 0).
fn gas_occluders(world: &World) -> Vec<Gas> {
    world
        .prims
        .iter()
        .filter_map(|p| p.gas())
        .filter(|g| g.sigma0 > 0.0)
        .collect()
}

fn box_corners(half: DVec3, to_world: &DAffine3) -> Vec<DVec3> {
    (0..8)
        .map(|b| {
            let s = DVec3::new(
                if b & 1 == 0 { -1.0 } else { 1.0 },
                if b & 2 == 0 { -1.0 } else { 1.0 },
                if b & 4 == 0 { -1.0 } else { 1.0 },
            );
            to_world.transform_point3(s * half)
        })
        .collect()
}

/// Where `x` is with respect to occluder `o`: -1 inside, 0 on its surface (to rounding
/// `band`), 1 outside. Triangles have no inside.
fn side(o: &Occluder, x: DVec3, band: f64) -> i32 {
    let depth = match o.solid {
        Solid::Sphere { c, r } => (r - (x - c).length()) / r.max(1.0),
        Solid::Surface {
            shape: RefShape::Cuboid { size },
            to_world,
        } => {
            let p = to_world.inverse().transform_point3(x);
            let half = size / 2.0;
            (0..3)
                .map(|i| (half[i] - p[i].abs()) / half[i])
                .fold(f64::INFINITY, f64::min)
        }
        Solid::Surface {
            shape: RefShape::Cylinder { r, h },
            to_world,
        } => {
            let p = to_world.inverse().transform_point3(x);
            ((r - p.x.hypot(p.z)) / r).min((h / 2.0 - p.y.abs()) / (h / 2.0))
        }
        Solid::Surface {
            shape: RefShape::Cone { r, h },
            to_world,
        } => {
            // Apex at y = h/2, base of radius r at y = -h/2.
            let p = to_world.inverse().transform_point3(x);
            let at = r * (h / 2.0 - p.y) / h;
            ((at - p.x.hypot(p.z)) / r).min((p.y + h / 2.0) / (h / 2.0))
        }
        Solid::Surface { .. } => return 1,
    };
    if depth.abs() <= band {
        0
    } else if depth > 0.0 {
        -1
    } else {
        1
    }
}

/// Whether occluder `o` may hold a point above the plane through `x` of normal `n` within
/// `reach` of `x` (`band`: rounding, counted against it).
fn rises(o: &Occluder, x: DVec3, n: DVec3, reach: f64, band: f64) -> bool {
    if (o.centre - x).length() - o.radius > reach + band {
        return false;
    }
    match o.solid {
        Solid::Sphere { c, r } => n.dot(c - x) + r > -band,
        Solid::Surface { .. } => o.corners.iter().any(|q| n.dot(*q - x) > -band),
    }
}

/// Whether gas sphere `g` may hold a point above the plane through `x` of normal `n` within
/// `reach` of `x` (`band`: rounding, counted against it).
fn gas_rises(g: &Gas, x: DVec3, n: DVec3, reach: f64, band: f64) -> bool {
    (g.c - x).length() - g.r <= reach + band && n.dot(g.c - x) + g.r > -band
}

/// The transmittance of the gas spheres `gas` along `x + s w`, `0 <= s <= reach`.
fn transmittance(gas: &[&Gas], x: DVec3, w: DVec3, reach: f64) -> f64 {
    let mut tau = 0.0;
    for g in gas {
        if let Some((t0, t1)) = sphere_roots(g.c, g.r, x, w) {
            let (a, b) = (t0.max(0.0), t1.min(reach));
            if b > a {
                tau += gas_depth(g, x, w, a, b);
            }
        }
    }
    (-tau).exp()
}

/// Whether the ray `x + s w`, `0 < s <= reach`, meets occluder `o`.
fn blocks(o: &Occluder, x: DVec3, w: DVec3, reach: f64) -> bool {
    let near =
        |c: DVec3, r: f64| sphere_roots(c, r, x, w).is_some_and(|(t0, t1)| t1 > 0.0 && t0 <= reach);
    match o.solid {
        Solid::Sphere { c, r } => near(c, r),
        Solid::Surface { shape, to_world } => {
            near(o.centre, o.radius) && blocks_from(&shape, &to_world, x, w, 0.0, reach)
        }
    }
}

/// Direction of cell point `(u, v)` in `[0, 1)^2` about the frame `(t, b, n)`: cosine-weighted
/// (`r = sqrt(u)`) or uniform in solid angle (`cos theta = u`).
fn direction(u: f64, v: f64, weighting: Weighting, t: DVec3, b: DVec3, n: DVec3) -> DVec3 {
    let (sin_t, cos_t) = match weighting {
        Weighting::Cosine => (u.sqrt(), (1.0 - u).sqrt()),
        Weighting::Uniform => ((1.0 - u * u).max(0.0).sqrt(), u),
    };
    let phi = std::f64::consts::TAU * v;
    (t * phi.cos() + b * phi.sin()) * sin_t + n * cos_t
}

/// Two unit vectors completing the unit `n` to an orthonormal frame.
fn frame(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.x.abs() < 0.6 { DVec3::X } else { DVec3::Y };
    let t = n.cross(a).normalize();
    (t, n.cross(t))
}

impl World {
    /// The reference AO of pixel `(i, j)` with `s`, directions drawn from `seed`.
    fn ao_pixel(
        &self,
        occ: &[Occluder],
        gas: &[Gas],
        i: u32,
        j: u32,
        s: &AoSettings,
        seed: u64,
    ) -> AoRef {
        let (o, w) = self.eye.ray(i, j);
        let Some(hit) = self.first_opaque(o, w) else {
            return AoRef::Miss;
        };
        let x = o + hit.t * w;
        let n = hit.n.normalize();
        let band = BAND * (1.0 + x.length());
        let others: Vec<&Occluder> = occ.iter().filter(|q| q.k != hit.k).collect();
        let mut on_another = false;
        for q in &others {
            match side(q, x, BAND) {
                -1 => return AoRef::Inside,
                0 => on_another = true,
                _ => {}
            }
        }
        if on_another {
            return AoRef::OnAnother;
        }
        let mut cands: Vec<&Occluder> = others
            .into_iter()
            .filter(|q| rises(q, x, n, s.reach, band))
            .collect();
        let gas: Vec<&Gas> = gas
            .iter()
            .filter(|g| gas_rises(g, x, n, s.reach, band))
            .collect();
        if cands.is_empty() && gas.is_empty() {
            return AoRef::Open;
        }
        let (t, b) = frame(n);
        let mut rng = Rng::new(
            seed.wrapping_mul(0x100_0000_01b3) ^ (u64::from(j) << 32 | u64::from(i)) ^ 0xa0,
        );
        let mut sum = 0.0;
        for a in 0..SIDE {
            for c in 0..SIDE {
                let u = (f64::from(a) + rng.f()) / f64::from(SIDE);
                let v = (f64::from(c) + rng.f()) / f64::from(SIDE);
                let d = direction(u, v, s.weighting, t, b, n);
                // The last occluder that blocked goes first: neighbouring cells are mostly
                // blocked by the same one.
                match cands.iter().position(|q| blocks(q, x, d, s.reach)) {
                    Some(p) => cands.swap(0, p),
                    None => sum += transmittance(&gas, x, d, s.reach),
                }
            }
        }
        AoRef::Estimate {
            p: sum / f64::from(SIDE * SIDE),
            gas: !gas.is_empty(),
        }
    }
}

/// The reference image (row-major) of `world` with `s`, rows split between threads.
pub fn reference(world: &World, s: &AoSettings, seed: u64) -> Vec<AoRef> {
    let occ = occluders(world);
    let gas = gas_occluders(world);
    let (w, h) = (world.eye.width, world.eye.height);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    let mut out = vec![AoRef::Miss; (w * h) as usize];
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|k| {
                let (occ, gas) = (&occ, &gas);
                scope.spawn(move || {
                    (k..h)
                        .step_by(threads as usize)
                        .flat_map(|j| (0..w).map(move |i| (i, j)))
                        .map(|(i, j)| {
                            (
                                (j * w + i) as usize,
                                world.ao_pixel(occ, gas, i, j, s, seed),
                            )
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for hd in handles {
            for (k, r) in hd.join().expect("AO reference thread") {
                out[k] = r;
            }
        }
    });
    out
}

/// What the AO checks found over a scene, or a run.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Scenes checked: all, those checked whole (not their AO part), and those of them with
    /// gas.
    pub scenes: u64,
    pub whole: u64,
    pub whole_gas: u64,
    /// Scenes AO must refuse (gas with Cylinders or Cones), and those the library refused
    /// with the right counts.
    pub to_refuse: u64,
    pub refused: u64,
    /// Pixels: estimated (checked statistically), those of them with gas among their
    /// occluders, open (exactly 1), inside (exactly 0), misses, and left out on another
    /// surface.
    pub estimated: u64,
    pub estimated_gas: u64,
    pub open: u64,
    pub inside: u64,
    pub misses: u64,
    pub on_another: u64,
    /// Largest |library - reference| beyond the library's error channel, over sigma: over
    /// every estimated pixel, and over those through gas.
    pub worst_z: f64,
    pub worst_z_gas: f64,
    /// Sums over the estimated pixels whose error channel is at most [`BIAS_ERR`] sigma of
    /// library - reference, of sigma^2 and of the error channel, and their count, for
    /// [`Tally::bias_z`].
    pub sum_err: f64,
    pub sum_var: f64,
    pub sum_channel: f64,
    pub bias_pixels: u64,
}

impl Tally {
    pub fn add(&mut self, o: &Tally) {
        self.scenes += o.scenes;
        self.whole += o.whole;
        self.whole_gas += o.whole_gas;
        self.to_refuse += o.to_refuse;
        self.refused += o.refused;
        self.estimated += o.estimated;
        self.estimated_gas += o.estimated_gas;
        self.open += o.open;
        self.inside += o.inside;
        self.misses += o.misses;
        self.on_another += o.on_another;
        self.worst_z = self.worst_z.max(o.worst_z);
        self.worst_z_gas = self.worst_z_gas.max(o.worst_z_gas);
        self.sum_err += o.sum_err;
        self.sum_var += o.sum_var;
        self.sum_channel += o.sum_channel;
        self.bias_pixels += o.bias_pixels;
    }

    /// The summed error of the estimated pixels, less their summed error channels, in
    /// standard errors (with the sum's sign): an error of the same sign everywhere, too small
    /// for any one pixel to show, shows here.
    pub fn bias_z(&self) -> f64 {
        if self.sum_var > 0.0 {
            let beyond = (self.sum_err.abs() - self.sum_channel).max(0.0);
            beyond.copysign(self.sum_err) / self.sum_var.sqrt()
        } else {
            0.0
        }
    }
}

/// The library's AO `film` of `desc` against `refs`: failures, one line each, into `fails`.
pub fn check(
    tally: &mut Tally,
    fails: &mut Vec<String>,
    desc: &SceneDesc,
    film: &Film,
    refs: &[AoRef],
    z: f64,
) {
    let n = f64::from(SIDE * SIDE);
    let q = (z * z / n).min(0.5);
    for (k, r) in refs.iter().enumerate() {
        let got = film.rgb[k];
        // The library's error channel: a bound where Cylinders or Cones occlude, an
        // estimate where gas does, 0 elsewhere.
        let err = film.error.as_ref().map_or(0.0, |e| e[k]);
        let at = format!(
            "ao pixel ({}, {})",
            k % desc.width as usize,
            k / desc.width as usize
        );
        if *r == AoRef::Miss {
            tally.misses += 1;
            if got != desc.background {
                fails.push(format!(
                    "{at}: the reference misses, the library has {got:?}, not the background {:?}",
                    desc.background
                ));
            }
            continue;
        }
        if got[0] != got[1] || got[0] != got[2] {
            fails.push(format!("{at}: not grey: {got:?}"));
            continue;
        }
        let v = got[0];
        match *r {
            AoRef::Inside | AoRef::Open => {
                let want = if *r == AoRef::Open { 1.0 } else { 0.0 };
                if *r == AoRef::Open {
                    tally.open += 1;
                } else {
                    tally.inside += 1;
                }
                // (Open: the polyhedron about a Cylinder or Cone may rise where the solid
                // does not, which the bound covers, to the rounding of the mean and the half
                // gap.)
                let within = v == want || (want == 1.0 && 1.0 - v <= err + 1e-12);
                if !within {
                    fails.push(format!(
                        "{at}: got {v:.17e}, exactly {want} expected ({})",
                        if want == 1.0 {
                            "nothing rises above the horizon within the reach"
                        } else {
                            "the point is inside another sphere or solid"
                        }
                    ));
                }
            }
            AoRef::Estimate { p, gas } => {
                tally.estimated += 1;
                tally.estimated_gas += u64::from(gas);
                let sigma = (p * (1.0 - p)).max(q * (1.0 - q)).sqrt() / n.sqrt();
                let e = (v - p).abs();
                if err <= BIAS_ERR * sigma {
                    // (A bracketed or estimated value may sit anywhere within its error
                    // channel, with a sign of its own: the channel is allowed for.)
                    tally.sum_err += v - p;
                    tally.sum_var += sigma * sigma;
                    tally.sum_channel += err;
                    tally.bias_pixels += 1;
                }
                let beyond = (e - err).max(0.0) / sigma;
                tally.worst_z = tally.worst_z.max(beyond);
                if gas {
                    tally.worst_z_gas = tally.worst_z_gas.max(beyond);
                }
                if e.is_nan() || e > z * sigma + 1e-9 + err {
                    fails.push(format!(
                        "{at}: got {v:.10e} (error channel {err:.2e}), reference {p:.6e} from \
                         {n} directions{}: error {e:.2e} = {:.2} sigma of {sigma:.2e} (z {z:.2})",
                        if gas { " through gas" } else { "" },
                        e / sigma
                    ));
                }
            }
            AoRef::OnAnother => tally.on_another += 1,
            AoRef::Miss => unreachable!("handled above"),
        }
    }
}
