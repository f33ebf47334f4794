//! Per-corner normals of a polygon mesh by the VRML97 `creaseAngle` rule.

use glam::DVec3;

use super::triangulate::area_normal;

/// The normal at each corner of each polygon (indices into `points`), by VRML97's
/// `creaseAngle` rule:
///
/// - A face's normal is its unit Newell normal (zero for zero area, see
///   [`super::triangulate()`]).
/// - A corner's normal is the normalised sum of the normals of the faces at its point (same
///   point index): the face itself, and every other face whose normal is less than
///   `crease_angle` (radians) from it. So 0 gives flat faces, `pi` smooth ones.
/// - Faces are weighted by their corner angle at the point (in `[0, pi]`, between the
///   corner's two edges; a face at a point twice counts both corners).
/// - A zero-area face's corners take the sum over all non-zero faces at the point; a corner
///   whose sum is zero takes its face's normal (zero for a zero-area face, or an index out
///   of range).
pub fn crease_normals(points: &[DVec3], polygons: &[&[u32]], crease_angle: f64) -> Vec<Vec<DVec3>> {
    let normal: Vec<DVec3> = polygons
        .iter()
        .map(|poly| area_normal(points, poly).map_or(DVec3::ZERO, |(n, _)| n.normalize_or_zero()))
        .collect();
    // Corner angles, for faces with a normal (all their indices are in range).
    let angle: Vec<Vec<f64>> = polygons
        .iter()
        .zip(&normal)
        .map(|(poly, n)| {
            if *n == DVec3::ZERO {
                return Vec::new();
            }
            let m = poly.len();
            (0..m)
                .map(|k| {
                    let p = points[poly[k] as usize];
                    let a = points[poly[(k + m - 1) % m] as usize] - p;
                    let b = points[poly[(k + 1) % m] as usize] - p;
                    a.cross(b).length().atan2(a.dot(b))
                })
                .collect()
        })
        .collect();
    // The corners at each point: `at[start[v]..start[v + 1]]`, as (face, corner).
    let mut start = vec![0usize; points.len() + 1];
    for poly in polygons {
        for &v in poly.iter().filter(|&&v| (v as usize) < points.len()) {
            start[v as usize + 1] += 1;
        }
    }
    for v in 0..points.len() {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut at = vec![(0usize, 0usize); start[points.len()]];
    for (f, poly) in polygons.iter().enumerate() {
        for (k, &v) in poly.iter().enumerate() {
            if (v as usize) < points.len() {
                at[fill[v as usize]] = (f, k);
                fill[v as usize] += 1;
            }
        }
    }

    polygons
        .iter()
        .enumerate()
        .map(|(f, poly)| {
            let nf = normal[f];
            poly.iter()
                .map(|&v| {
                    let Some(range) = start.get(v as usize..v as usize + 2) else {
                        return nf;
                    };
                    let mut sum = DVec3::ZERO;
                    for &(g, k) in &at[range[0]..range[1]] {
                        let ng = normal[g];
                        if ng == DVec3::ZERO {
                            continue;
                        }
                        let smooth = g == f
                            || nf == DVec3::ZERO
                            || nf.dot(ng).clamp(-1.0, 1.0).acos() < crease_angle;
                        if smooth {
                            sum += angle[g][k] * ng;
                        }
                    }
                    let s = sum.normalize_or_zero();
                    if s == DVec3::ZERO {
                        nf
                    } else {
                        s
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::fit::tests::icosphere;
    use crate::geom::mesh::tests_support::vtk_sphere;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// The unit cube [-1, 1]^3: corner `i` at (+-1, +-1, +-1) by bits of `i`; 6 outward quads.
    fn cube() -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let points = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect();
        let faces = vec![
            vec![0, 2, 3, 1], // z = -1
            vec![4, 5, 7, 6], // z = +1
            vec![0, 1, 5, 4], // y = -1
            vec![2, 6, 7, 3], // y = +1
            vec![0, 4, 6, 2], // x = -1
            vec![1, 3, 7, 5], // x = +1
        ];
        (points, faces)
    }

    fn run(points: &[DVec3], faces: &[Vec<u32>], crease: f64) -> Vec<Vec<DVec3>> {
        let polys: Vec<&[u32]> = faces.iter().map(|f| f.as_slice()).collect();
        let n = crease_normals(points, &polys, crease);
        assert_eq!(n.len(), faces.len());
        assert!(n.iter().zip(faces).all(|(n, f)| n.len() == f.len()));
        n
    }

    #[test]
    fn cube_flat_and_smooth() {
        let (points, faces) = cube();
        let face_normal = [
            -DVec3::Z,
            DVec3::Z,
            -DVec3::Y,
            DVec3::Y,
            -DVec3::X,
            DVec3::X,
        ];
        // Neighbouring faces are 90 degrees apart: flat unless the crease angle exceeds it.
        for crease in [0.0, 0.5, FRAC_PI_2] {
            let n = run(&points, &faces, crease);
            for (f, corners) in n.iter().enumerate() {
                for c in corners {
                    assert_eq!(*c, face_normal[f], "crease {crease}");
                }
            }
        }
        for crease in [FRAC_PI_2 + 1e-9, 2.0, PI] {
            let n = run(&points, &faces, crease);
            for (f, corners) in n.iter().enumerate() {
                for (k, c) in corners.iter().enumerate() {
                    // By hand: the corner (sx, sy, sz) gets (sx, sy, sz) / sqrt(3).
                    let want = points[faces[f][k] as usize] / 3f64.sqrt();
                    assert!((*c - want).length() < 1e-15, "{c} vs {want}");
                }
            }
        }
    }

    #[test]
    fn corner_angle_weights() {
        // At the origin: a right angle of a face with normal +z, a 45-degree angle of a face
        // with normal -x. Smooth: (pi/2) z + (pi/4) (-x), normalised: (-1, 0, 2) / sqrt(5).
        let points = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(0.0, 1.0, 1.0),
        ];
        let faces = vec![vec![0, 1, 2], vec![0, 3, 4]];
        let n = run(&points, &faces, PI);
        let want = DVec3::new(-1.0, 0.0, 2.0) / 5f64.sqrt();
        assert!((n[0][0] - want).length() < 1e-15 && (n[1][0] - want).length() < 1e-15);
        // Corners at unshared points keep the face normal.
        assert_eq!((n[0][1], n[1][2]), (DVec3::Z, -DVec3::X));
        let n = run(&points, &faces, 1.5);
        assert_eq!((n[0][0], n[1][0]), (DVec3::Z, -DVec3::X));
    }

    #[test]
    fn zero_area_faces() {
        let points = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            2.0 * DVec3::X,
            5.0 * DVec3::Z,
        ];
        // Face 1 is collinear (0, 1, 3) and shares points 0 and 1 with face 0; face 2 is a
        // repeated point far away; face 3 has an index out of range.
        let faces = vec![vec![0, 1, 2], vec![0, 1, 3], vec![4, 4, 4], vec![2, 9, 0]];
        let n = run(&points, &faces, 0.0);
        assert_eq!(n[0], vec![DVec3::Z; 3]);
        assert_eq!(n[1], vec![DVec3::Z, DVec3::Z, DVec3::ZERO]);
        assert_eq!(n[2], vec![DVec3::ZERO; 3]);
        assert_eq!(n[3], vec![DVec3::Z, DVec3::ZERO, DVec3::Z]);
        assert!(crease_normals(&[], &[], 1.0).is_empty());
        assert_eq!(
            crease_normals(&[], &[&[0, 1, 2]], f64::NAN),
            vec![vec![DVec3::ZERO; 3]]
        );
    }

    #[test]
    fn smooth_sphere_normals_are_radial() {
        let uv = vtk_sphere(DVec3::ZERO, 1.0, 48, 32, true);
        let (v, t) = icosphere(3);
        let ico = (v, t.iter().map(|t| t.to_vec()).collect::<Vec<_>>());
        for (points, faces) in [uv, ico] {
            let (mut worst, mut flat_worst) = (0.0f64, 0.0f64);
            for (crease, worst) in [(PI, &mut worst), (0.0, &mut flat_worst)] {
                let n = run(&points, &faces, crease);
                for (f, corners) in n.iter().enumerate() {
                    for (k, c) in corners.iter().enumerate() {
                        let radial = points[faces[f][k] as usize].normalize();
                        *worst = worst.max((*c - radial).length());
                    }
                }
            }
            assert!(worst < 1e-2, "{worst}");
            assert!(flat_worst > 3e-2, "{flat_worst}: flat faces are not radial");
        }
    }
}
