//! Is a point set a tessellated sphere? Exporters such as Jmol write every atom as a mesh
//! whose vertices lie on a sphere; this finds that sphere, or says there is none.

use glam::DVec3;

/// Fewest vertices accepted: an icosahedron, the coarsest sphere tessellation in use.
pub const MIN_POINTS: usize = 12;

/// Largest `|distance - r| / r` over the vertices. Jmol writes unit-sphere vertices with three
/// decimals (distances 0.99945 .. 1.00048 from the centre, 5.2e-4); three-decimal rounding of
/// a unit vector can be off by up to `sqrt(3) * 5e-4 = 8.7e-4`, so 2e-3 keeps every such
/// mesh and still rejects ellipsoids flatter than 0.4 %.
pub const RADIUS_TOLERANCE: f64 = 2e-3;

/// The vertices must reach at least this fraction of `r` along each of 26 directions (the
/// axes, face and body diagonals of a cube). An icosahedron reaches 0.795 (its inradius)
/// in the worst direction; a circle, a hemisphere or two circles (a cylinder's rims, which
/// are equidistant from its centre) fall short in some direction: two circles at half-height
/// `h` and radius `a` with `a^2 + h^2 = r^2` cannot have both `a` and `h` >= 0.75 r.
pub const MIN_REACH: f64 = 0.75;

/// The sphere through `points` (x, y, z triples), if they all lie on one within
/// [`RADIUS_TOLERANCE`] and spread over all of it (see [`MIN_REACH`]); `None` otherwise.
///
/// The centre is the centre of the points' bounding box: for any tessellation symmetric
/// enough to cover the sphere it is the sphere's centre up to the vertices' own rounding.
/// The radius is the middle of the smallest and largest distance from it.
pub fn sphere_through(points: &[f64]) -> Option<(DVec3, f64)> {
    if points.len() % 3 != 0 || points.len() / 3 < MIN_POINTS {
        return None;
    }
    let pts = || points.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2]));
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in pts() {
        if !p.is_finite() {
            return None;
        }
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let center = 0.5 * lo + 0.5 * hi;
    let (mut dmin, mut dmax) = (f64::INFINITY, 0.0f64);
    for p in pts() {
        let d = (p - center).length();
        dmin = dmin.min(d);
        dmax = dmax.max(d);
    }
    let r = 0.5 * (dmin + dmax);
    if !(r > 0.0 && r.is_finite() && center.is_finite()) || dmax - dmin > 2.0 * RADIUS_TOLERANCE * r
    {
        return None;
    }
    // Support in each of the 26 directions (13 lines, both ways): max and min of (p - c).u.
    let mut reach = [(f64::NEG_INFINITY, f64::INFINITY); 13];
    for p in pts() {
        let q = p - center;
        for (k, u) in directions().enumerate() {
            let s = q.dot(u);
            reach[k].0 = reach[k].0.max(s);
            reach[k].1 = reach[k].1.min(s);
        }
    }
    reach
        .iter()
        .all(|&(hi, lo)| hi >= MIN_REACH * r && -lo >= MIN_REACH * r)
        .then_some((center, r))
}

/// The 13 lines through a cube's centre and its face centres, edge midpoints and corners.
fn directions() -> impl Iterator<Item = DVec3> {
    const D: [[f64; 3]; 13] = [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, -1.0],
        [0.0, 1.0, 1.0],
        [0.0, 1.0, -1.0],
        [1.0, 1.0, 1.0],
        [1.0, 1.0, -1.0],
        [1.0, -1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    D.iter().map(|d| DVec3::from_array(*d).normalize())
}
