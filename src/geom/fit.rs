//! Is a point set a tessellated sphere? Exporters write particles as meshes whose vertices lie
//! on a sphere (Jmol one mesh per atom, VTK glyphs all in one mesh, see [`super::mesh`]); this
//! finds that sphere, or says there is none.

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
///
/// vtkSphereSource meshes as VTK writes them (pole on z, first meridian on x; theta
/// resolution `T` meridians, phi resolution `P` latitudes counting both poles, so
/// `T (P - 2) + 2` points) pass for `T >= 5` and `P >= 4` except 5 x 4: every `T <= 4` or
/// `P = 3` falls short.
pub const MIN_REACH: f64 = 0.75;

/// The sphere through `points` (x, y, z triples): [`sphere_fit`] of the triples; `None` also
/// when the length is not a multiple of 3.
#[cfg(test)]
pub fn sphere_through(points: &[f64]) -> Option<(DVec3, f64)> {
    if points.len() % 3 != 0 || points.len() / 3 < MIN_POINTS {
        return None;
    }
    let pts: Vec<DVec3> = points
        .chunks_exact(3)
        .map(|p| DVec3::new(p[0], p[1], p[2]))
        .collect();
    sphere_fit(&pts)
}

/// The sphere `(centre, radius)` through `points`, if there are at least [`MIN_POINTS`] of
/// them (repeats count), all finite, all within [`RADIUS_TOLERANCE`] of one sphere and spread
/// over all of it (see [`MIN_REACH`]); `None` otherwise.
///
/// The centre is the algebraic least-squares fit `|p|^2 = 2 c.p + k`, solved by Givens QR in
/// coordinates centred on the bounding box and scaled by a power of two (exact for points on
/// a sphere up to their own rounding, and free of overflow). The radius is the mean distance
/// from that centre (nearer the true radius of 3-decimal vertices than the mid-range). For
/// VTK glyph spheres at coordinates up to 1e3, both come within 1e-10 r of the generating
/// sphere (tests: within 1e-9 r).
pub fn sphere_fit(points: &[DVec3]) -> Option<(DVec3, f64)> {
    if points.len() < MIN_POINTS {
        return None;
    }
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &p in points {
        if !p.is_finite() {
            return None;
        }
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let mid = 0.5 * lo + 0.5 * hi;
    let half = (0.5 * hi - 0.5 * lo).max_element();
    if !(half > 0.0 && half.is_finite()) {
        return None;
    }
    // A power of two >= half: scaling by it is exact.
    let scale = 2f64.powi(half.log2().ceil() as i32);
    let local = |p: DVec3| (p - mid) / scale;

    // Rows [2x, 2y, 2z, 1 | x^2 + y^2 + z^2] rotated into the upper triangle `r` (4 x 5).
    let mut r = [[0.0f64; 5]; 4];
    for &p in points {
        let q = local(p);
        let mut row = [2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0, q.length_squared()];
        for j in 0..4 {
            if row[j] == 0.0 {
                continue;
            }
            let h = r[j][j].hypot(row[j]);
            let (c, s) = (r[j][j] / h, row[j] / h);
            for k in j..5 {
                let (a, b) = (r[j][k], row[k]);
                r[j][k] = c * a + s * b;
                row[k] = c * b - s * a;
            }
        }
    }
    // Rank test: a plane or a line of points leaves a (near) zero pivot.
    let pivot = r.iter().enumerate().map(|(j, row)| row[j].abs());
    let (pmin, pmax) = pivot.fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    if pmin.is_nan() || pmin <= 1e-10 * pmax {
        return None;
    }
    let mut x = [0.0f64; 4];
    for j in (0..4).rev() {
        let tail: f64 = (j + 1..4).map(|k| r[j][k] * x[k]).sum();
        x[j] = (r[j][4] - tail) / r[j][j];
    }
    let c_local = DVec3::new(x[0], x[1], x[2]);
    let center = mid + c_local * scale;

    let n = points.len() as f64;
    let dist = |p: DVec3| (local(p) - c_local).length();
    let radius_local = points.iter().map(|&p| dist(p)).sum::<f64>() / n;
    let radius = radius_local * scale;
    if !(radius_local > 0.0 && radius.is_finite() && center.is_finite()) {
        return None;
    }
    let tol = RADIUS_TOLERANCE * radius_local;
    if !points
        .iter()
        .all(|&p| (dist(p) - radius_local).abs() <= tol)
    {
        return None;
    }
    // Support in each of the 26 directions (13 lines, both ways): max and min of (p - c).u.
    let mut reach = [(f64::NEG_INFINITY, f64::INFINITY); 13];
    for &p in points {
        let q = local(p) - c_local;
        for (k, u) in directions().enumerate() {
            let s = q.dot(u);
            reach[k].0 = reach[k].0.max(s);
            reach[k].1 = reach[k].1.min(s);
        }
    }
    let need = MIN_REACH * radius_local;
    reach
        .iter()
        .all(|&(hi, lo)| hi >= need && -lo >= need)
        .then_some((center, radius))
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geom::mesh::tests_support::vtk_sphere;
    use crate::testing::Rng;
    use hashbrown::HashMap;
    use std::f64::consts::TAU;

    /// A unit icosphere: the icosahedron with each triangle split into 4, `level` times.
    /// Returns the vertices and the triangles.
    pub(crate) fn icosphere(level: usize) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let g = (1.0 + 5f64.sqrt()) / 2.0;
        let mut v = Vec::new();
        for a in [-1.0, 1.0] {
            for b in [-g, g] {
                v.push(DVec3::new(0.0, a, b).normalize());
                v.push(DVec3::new(a, b, 0.0).normalize());
                v.push(DVec3::new(b, 0.0, a).normalize());
            }
        }
        // Faces: the triples at mutual edge distance, wound outward.
        let edge = (v[0]
            - v[1..]
                .iter()
                .copied()
                .min_by(|a, b| (v[0] - *a).length().total_cmp(&(v[0] - *b).length()))
                .unwrap())
        .length();
        let near = |a: usize, b: usize| ((v[a] - v[b]).length() - edge).abs() < 1e-9;
        let mut t = Vec::new();
        for a in 0..12 {
            for b in a + 1..12 {
                for c in b + 1..12 {
                    if near(a, b) && near(b, c) && near(a, c) {
                        let out = (v[b] - v[a]).cross(v[c] - v[a]).dot(v[a]) > 0.0;
                        let (a, b, c) = (a as u32, b as u32, c as u32);
                        t.push(if out { [a, b, c] } else { [a, c, b] });
                    }
                }
            }
        }
        assert_eq!(t.len(), 20);
        for _ in 0..level {
            let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
            let mut next = Vec::new();
            for [a, b, c] in t {
                let mut m = |i: u32, j: u32| {
                    *mid.entry((i.min(j), i.max(j))).or_insert_with(|| {
                        v.push((v[i as usize] + v[j as usize]).normalize());
                        v.len() as u32 - 1
                    })
                };
                let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            t = next;
        }
        (v, t)
    }

    fn uv(t: usize, p: usize) -> Vec<DVec3> {
        vtk_sphere(DVec3::ZERO, 1.0, t, p, true).0
    }

    fn round3(v: &[DVec3]) -> Vec<DVec3> {
        v.iter().map(|p| (*p * 1000.0).round() / 1000.0).collect()
    }

    #[test]
    fn jmol_three_decimal_unit_spheres_are_accepted() {
        let mut cases = Vec::new();
        for level in 0..=3 {
            cases.push((format!("icosphere {level}"), icosphere(level).0));
        }
        for (t, p) in [(8, 6), (12, 8), (16, 10), (24, 13), (40, 21)] {
            cases.push((format!("uv {t}x{p}"), uv(t, p)));
        }
        for (name, pts) in cases {
            let pts = round3(&pts);
            let (c, r) = sphere_fit(&pts).unwrap_or_else(|| panic!("{name}"));
            // Rounding moves a vertex by up to 8.7e-4 (all 12 of an icosahedron alike).
            assert!(
                c.length() < 1e-3 && (r - 1.0).abs() < 1e-3,
                "{name}: {c} {r}"
            );
        }
    }

    #[test]
    fn non_spheres_are_rejected() {
        let circle = |n: usize, a: f64, z: f64| -> Vec<DVec3> {
            (0..n)
                .map(|i| {
                    let t = TAU * i as f64 / n as f64;
                    DVec3::new(a * t.cos(), a * t.sin(), z)
                })
                .collect()
        };
        let mut cases: Vec<(String, Vec<DVec3>)> = Vec::new();
        // Cylinder rims: two circles at +-h, a^2 + h^2 = 1 (all points at distance 1).
        for deg in [20.0f64, 35.0, 45.0, 55.0, 70.0] {
            let (a, h) = (deg.to_radians().cos(), deg.to_radians().sin());
            let mut pts = circle(32, a, h);
            pts.extend(circle(32, a, -h));
            cases.push((format!("cylinder rims {deg}"), pts));
        }
        // Hemispheres: the upper half of a UV sphere, equator included, and of an icosphere.
        let hemi: Vec<DVec3> = uv(24, 13).into_iter().filter(|p| p.z >= -1e-12).collect();
        cases.push(("uv hemisphere".into(), hemi));
        let hemi: Vec<DVec3> = icosphere(3).0.into_iter().filter(|p| p.z >= 0.0).collect();
        cases.push(("icosphere hemisphere".into(), hemi));
        // Ellipsoids flattened by 0.4 % along each axis (UV spheres reach poles and equator).
        for axis in 0..3 {
            for pts in [uv(16, 11), icosphere(3).0] {
                let mut s = DVec3::ONE;
                s[axis] = 0.996;
                cases.push((
                    format!("flattened {axis}"),
                    pts.iter().map(|p| *p * s).collect(),
                ));
            }
        }
        // A circle and a plane grid: rank deficient.
        cases.push(("circle".into(), circle(40, 1.0, 0.3)));
        cases.push((
            "grid".into(),
            (0..25)
                .map(|i| DVec3::new((i % 5) as f64, (i / 5) as f64, 2.0))
                .collect(),
        ));
        for (name, pts) in cases {
            assert_eq!(sphere_fit(&pts), None, "{name}");
        }
        // Still accepted at 0.3 % flattening, as the tolerance doc says (0.4 % is the edge).
        let pts: Vec<DVec3> = uv(16, 11)
            .iter()
            .map(|p| *p * DVec3::new(1.0, 1.0, 0.997))
            .collect();
        assert!(sphere_fit(&pts).is_some());
    }

    #[test]
    fn degenerate_input_gives_none() {
        assert_eq!(sphere_fit(&[]), None);
        assert_eq!(sphere_fit(&[DVec3::ONE; 40]), None);
        let mut pts = uv(16, 10);
        assert!(sphere_fit(&pts).is_some());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            pts[7].y = bad;
            assert_eq!(sphere_fit(&pts), None);
        }
        assert_eq!(sphere_fit(&uv(16, 10)[..11]), None, "fewer than MIN_POINTS");
        assert_eq!(sphere_through(&[0.0; 37]), None);
        let huge: Vec<DVec3> = uv(16, 10).iter().map(|p| *p * 1e308).collect();
        assert_eq!(sphere_fit(&huge), None, "radius beyond f64");
        let tiny: Vec<DVec3> = uv(16, 10).iter().map(|p| *p * 1e-300).collect();
        let (c, r) = sphere_fit(&tiny).expect("tiny sphere");
        assert!(
            c.length() < 1e-312 && (r / 1e-300 - 1.0).abs() < 1e-12,
            "{c} {r}"
        );
        let big: Vec<DVec3> = uv(16, 10).iter().map(|p| *p * 1e300 + 3e300).collect();
        let (c, r) = sphere_fit(&big).expect("big sphere");
        assert!((c / 3e300 - 1.0).abs().max_element() < 1e-12 && (r / 1e300 - 1.0).abs() < 1e-12);
    }

    /// Which vtkSphereSource resolutions (axis-aligned, theta from 0) the reach test accepts.
    #[test]
    fn accepted_vtk_resolutions() {
        let mut rng = Rng::new(5);
        for t in 3..=32 {
            for p in 3..=32 {
                let c = DVec3::new(rng.range(-1e3, 1e3), rng.range(-1e3, 1e3), 5.0);
                let r = rng.log10(-3.0, 1.0);
                let got = sphere_fit(&vtk_sphere(c, r, t, p, true).0).is_some();
                let want = t >= 5 && p >= 4 && (t, p) != (5, 4);
                assert_eq!(got, want, "theta {t} phi {p}");
            }
        }
    }
}
