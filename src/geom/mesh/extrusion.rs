//! VRML97's Extrusion (6.18) as points and faces: the cross-section, scaled and rotated at
//! each spine point, placed in that point's spine-aligned cross-section plane (SCP), joined
//! ring to ring by quads, and closed by caps. The faces are written as a `coordIndex` (each
//! face's corners, then -1), so that an Extrusion is drawn like any IndexedFaceSet.

use glam::{DQuat, DVec2, DVec3};

/// An Extrusion's geometry fields.
#[derive(Clone, Debug)]
pub struct Extrusion {
    /// `crossSection`: the 2D outline, in the x-z plane of each spine point's cross-section plane.
    pub cross_section: Vec<DVec2>,
    /// `spine`: the points the cross-section is swept along, in local space.
    pub spine: Vec<DVec3>,
    /// `scale`: the cross-section's scale in x and z at each spine point (one value for all, or
    /// one per point).
    pub scale: Vec<DVec2>,
    /// `orientation`: the cross-section's rotation at each spine point (one for all, or one per
    /// point).
    pub orientation: Vec<DQuat>,
    /// `beginCap`: whether the cross-section at the first spine point is closed by a face.
    pub begin_cap: bool,
    /// `endCap`: whether the cross-section at the last spine point is closed by a face.
    pub end_cap: bool,
}

impl Default for Extrusion {
    /// VRML97's defaults: a unit square along the y axis from 0 to 1, both caps.
    fn default() -> Self {
        Extrusion {
            cross_section: [
                (1.0, 1.0),
                (1.0, -1.0),
                (-1.0, -1.0),
                (-1.0, 1.0),
                (1.0, 1.0),
            ]
            .map(|(x, z)| DVec2::new(x, z))
            .to_vec(),
            spine: vec![DVec3::ZERO, DVec3::Y],
            scale: vec![DVec2::ONE],
            orientation: vec![DQuat::IDENTITY],
            begin_cap: true,
            end_cap: true,
        }
    }
}

/// Fills the zero vectors of `v` from their nearest non-zero predecessor (or, before the
/// first non-zero one, from it). False when all are zero.
fn fill_zeros(v: &mut [DVec3]) -> bool {
    let Some(first) = v.iter().copied().find(|z| *z != DVec3::ZERO) else {
        return false;
    };
    let mut last = first;
    for z in v.iter_mut() {
        if *z == DVec3::ZERO {
            *z = last;
        } else {
            last = *z;
        }
    }
    true
}

/// The SCP axes `(X, Y, Z)` at every spine point (VRML97 6.18.1).
fn scp(spine: &[DVec3]) -> Vec<(DVec3, DVec3, DVec3)> {
    let n = spine.len();
    let closed = n > 2 && spine[0] == spine[n - 1];
    let mut y: Vec<DVec3> = (0..n)
        .map(|i| {
            let d = if closed && (i == 0 || i == n - 1) {
                spine[1] - spine[n - 2]
            } else if i == 0 {
                spine[1] - spine[0]
            } else if i == n - 1 {
                spine[n - 1] - spine[n - 2]
            } else {
                spine[i + 1] - spine[i - 1]
            };
            d.normalize_or_zero()
        })
        .collect();
    if !fill_zeros(&mut y) {
        // Every spine point in one place: the y axis.
        y.iter_mut().for_each(|v| *v = DVec3::Y);
    }
    let mut z: Vec<DVec3> = (0..n)
        .map(|i| {
            let c = if closed && (i == 0 || i == n - 1) {
                (spine[1] - spine[0]).cross(spine[n - 2] - spine[0])
            } else if i == 0 || i == n - 1 {
                // Open ends take their neighbour's (filled in below).
                DVec3::ZERO
            } else {
                (spine[i + 1] - spine[i]).cross(spine[i - 1] - spine[i])
            };
            c.normalize_or_zero()
        })
        .collect();
    if fill_zeros(&mut z) {
        // Consecutive Z axes turn by less than 90 degrees.
        for i in 1..n {
            if z[i].dot(z[i - 1]) < 0.0 {
                z[i] = -z[i];
            }
        }
        (0..n).map(|i| (y[i].cross(z[i]), y[i], z[i])).collect()
    } else {
        // A straight spine: the rotation taking +y to its direction turns the x and z axes.
        let r = DQuat::from_rotation_arc(DVec3::Y, y[0]);
        let (x, z) = (r * DVec3::X, r * DVec3::Z);
        (0..n).map(|i| (x, y[i], z)).collect()
    }
}

/// The points (`spine.len()` rings of `cross_section.len()`) and faces of `e`; `None` for
/// fewer than two spine points or cross-section points, or points that are not finite.
/// Side quads run `(i, j), (i, j+1), (i+1, j+1), (i+1, j)`, and the end cap follows the
/// cross-section while the begin cap runs against it: with VRML's default cross-section
/// every face's counter-clockwise side is outside.
pub fn extrusion_mesh(e: &Extrusion) -> Option<(Vec<DVec3>, Vec<i64>)> {
    let (n, m) = (e.spine.len(), e.cross_section.len());
    if n < 2 || m < 2 {
        return None;
    }
    let axes = scp(&e.spine);
    let mut points = Vec::with_capacity(n * m);
    for (i, &(x, y, z)) in axes.iter().enumerate() {
        let s = e
            .scale
            .get(i)
            .or(e.scale.last())
            .copied()
            .unwrap_or(DVec2::ONE);
        let r = e
            .orientation
            .get(i)
            .or(e.orientation.last())
            .copied()
            .unwrap_or(DQuat::IDENTITY);
        for c in &e.cross_section {
            let p = r * DVec3::new(s.x * c.x, 0.0, s.y * c.y);
            points.push(e.spine[i] + x * p.x + y * p.y + z * p.z);
        }
    }
    if !points.iter().all(|p| p.is_finite()) {
        return None;
    }
    let at = |i: usize, j: usize| (i * m + j) as i64;
    let mut index = Vec::new();
    for i in 0..n - 1 {
        for j in 0..m - 1 {
            index.extend([at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j), -1]);
        }
    }
    // A closed cross-section repeats its first point: the caps use it once.
    let ring = if e.cross_section[0] == e.cross_section[m - 1] {
        m - 1
    } else {
        m
    };
    if ring >= 3 {
        if e.begin_cap {
            index.extend((0..ring).rev().map(|j| at(0, j)));
            index.push(-1);
        }
        if e.end_cap {
            index.extend((0..ring).map(|j| at(n - 1, j)));
            index.push(-1);
        }
    }
    Some((points, index))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default Extrusion is the box [-1, 1] x [0, 1] x [-1, 1]: six faces (four quads and
    /// two square caps), each facing out.
    #[test]
    fn the_default_extrusion_is_a_box_facing_out() {
        let (points, index) = extrusion_mesh(&Extrusion::default()).unwrap();
        assert_eq!(points.len(), 10);
        let faces = crate::geom::mesh::faces(&index);
        assert_eq!(faces.len(), 6);
        let centre = DVec3::new(0.0, 0.5, 0.0);
        for f in faces {
            let poly: Vec<u32> = index[f].iter().map(|&i| i as u32).collect();
            let n = crate::geom::mesh::triangulate::newell_normal(&points, &poly);
            let c = poly.iter().map(|&i| points[i as usize]).sum::<DVec3>() / poly.len() as f64;
            assert!(n.dot(c - centre) > 0.0, "face {poly:?} faces in: {n}");
            // The Newell normal is twice the area: 2 x 1 sides, 2 x 2 caps.
            assert!((n.length() - if c.y == 0.5 { 4.0 } else { 8.0 }).abs() < 1e-12);
        }
    }

    /// A bent spine: every ring lies in the plane through its spine point perpendicular to
    /// the spine's local direction, at the cross-section's distances, and consecutive Z axes
    /// never flip.
    #[test]
    fn rings_lie_in_their_cross_section_planes() {
        let spine = vec![
            DVec3::new(0.6, 0.35, 0.0),
            DVec3::new(1.5, 0.2, 0.0),
            DVec3::new(2.0, 0.0, 0.5),
            DVec3::new(2.2, 1.0, 1.5),
        ];
        let circle: Vec<DVec2> = (0..=12)
            .map(|k| {
                let a = -std::f64::consts::TAU * k as f64 / 12.0;
                DVec2::new(0.1 * a.cos(), 0.1 * a.sin())
            })
            .collect();
        let e = Extrusion {
            cross_section: circle.clone(),
            spine: spine.clone(),
            scale: vec![
                DVec2::ONE,
                DVec2::splat(0.7),
                DVec2::splat(0.5),
                DVec2::splat(0.5),
            ],
            ..Extrusion::default()
        };
        let (points, index) = extrusion_mesh(&e).unwrap();
        let axes = scp(&spine);
        for (i, &(x, y, z)) in axes.iter().enumerate() {
            assert!(
                (x.length() - 1.0).abs() < 1e-12
                    && x.dot(y).abs() < 1e-12
                    && y.dot(z).abs() < 1e-12
            );
            if i > 0 {
                assert!(z.dot(axes[i - 1].2) >= 0.0);
            }
            let s = e.scale[i].x;
            for j in 0..circle.len() {
                let p = points[i * circle.len() + j] - spine[i];
                assert!(p.dot(y).abs() < 1e-12, "ring {i} leaves its plane");
                assert!((p.length() - 0.1 * s).abs() < 1e-12);
            }
        }
        // 3 x 12 quads and two 12-gon caps.
        assert_eq!(crate::geom::mesh::faces(&index).len(), 36 + 2);
        assert!(extrusion_mesh(&Extrusion {
            spine: vec![DVec3::ZERO],
            ..Extrusion::default()
        })
        .is_none());
    }
}
