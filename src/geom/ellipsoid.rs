//! Ellipsoids: images of the unit sphere under an affine map, intersected in object space.

use glam::{DAffine3, DVec3};

use super::sphere::{exponent, scale_down, sphere_roots};

/// Parameters `t0 <= t1` where the line `o + t d` meets the ellipsoid `to_world(unit sphere)`,
/// given `to_object = to_world^-1`, or `None` if it misses.
///
/// The roots are in the same ray parameter `t` as in world space: an affine map sends
/// `o + t d` to `to_object(o) + t M d` (M its linear part), so `o` is mapped as a point, `d` as
/// a vector, and neither is normalised. Accuracy is that of [`sphere_roots`] on the mapped ray,
/// plus the rounding of the map itself (~eps times the object-space distance to the origin).
pub fn ellipsoid_roots(o: DVec3, d: DVec3, to_object: &DAffine3) -> Option<(f64, f64)> {
    sphere_roots(
        to_object.transform_point3(o),
        to_object.transform_vector3(d),
        DVec3::ZERO,
        1.0,
    )
}

/// Outward unit world normal at the world point `p` on the ellipsoid: the gradient of
/// `|to_object(p)|^2 - 1`, i.e. `normalize(M^T to_object(p))` with `M = to_object.matrix3`.
///
/// Returns `DVec3::ZERO` where the gradient is zero (`p` at the centre) or not finite.
pub fn ellipsoid_normal(p: DVec3, to_object: &DAffine3) -> DVec3 {
    let g = to_object.matrix3.transpose() * to_object.transform_point3(p);
    let gmax = g.abs().max_element();
    if gmax == 0.0 || !gmax.is_finite() {
        return DVec3::ZERO;
    }
    // Scale by a power of two (exact) before squaring so that a very flat or very large
    // ellipsoid cannot overflow or underflow |g|^2.
    let g = scale_down(g, exponent(gmax));
    g / g.length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    #[test]
    fn identity_map_is_the_unit_sphere() {
        let (o, d) = (DVec3::new(0.25, -0.5, -3.0), DVec3::new(0.1, 0.2, 1.0));
        assert_eq!(
            ellipsoid_roots(o, d, &DAffine3::IDENTITY),
            sphere_roots(o, d, DVec3::ZERO, 1.0)
        );
    }

    #[test]
    fn axis_aligned_ellipsoid_matches_closed_form() {
        // Semi-axes (2, 4, 8) centred at (1, 1, 1); every number here is a power of two.
        let to_world = DAffine3::from_mat3_translation(
            DMat3::from_diagonal(DVec3::new(2.0, 4.0, 8.0)),
            DVec3::ONE,
        );
        let to_object = to_world.inverse();
        let o = DVec3::new(1.0, 1.0, -15.0);
        assert_eq!(ellipsoid_roots(o, DVec3::Z, &to_object), Some((8.0, 24.0)));
        assert_eq!(ellipsoid_roots(o, DVec3::X, &to_object), None);
        let n = |p: DVec3| ellipsoid_normal(p, &to_object);
        assert_eq!(n(DVec3::new(3.0, 1.0, 1.0)), DVec3::X);
        assert_eq!(n(DVec3::new(1.0, -3.0, 1.0)), -DVec3::Y);
        assert_eq!(n(DVec3::new(1.0, 1.0, 9.0)), DVec3::Z);
        assert_eq!(n(DVec3::ONE), DVec3::ZERO);
        // A general point: the gradient of x^2/4 + y^2/16 + z^2/64 is (x/4, y/16, z/64)/2.
        let q = DVec3::new(1.0, 2.0, 4.0) / 21f64.sqrt(); // |(1, 2, 4)| = sqrt(21)
        let p = DVec3::ONE + q * DVec3::new(2.0, 4.0, 8.0);
        let want = (q / DVec3::new(2.0, 4.0, 8.0)).normalize();
        assert!((n(p) - want).length() < 1e-15, "{:?} vs {want:?}", n(p));
    }
}
