//! The ray test of one CWBVH node: all eight child boxes at once.
//!
//! obvhs's own test (`CwBvhNode::intersect_ray`) is written with SSE intrinsics: two passes of
//! four children, each quantised plane converted one byte at a time, and a branch per hit
//! child to build the mask. This one computes the same thing lane by lane over eight-element
//! arrays with no branches, which the compiler turns into SIMD of whatever width the function
//! is compiled for: two 4-wide halves on plain x86-64, one 8-wide pass inside the AVX2 clones
//! of the ray entry points (see mod.rs). The arithmetic is obvhs's, operation for
//! operation (a multiply, then an add, never fused), so the masks are identical; the tests
//! check that against obvhs.

use glam::Vec3A;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray;

/// obvhs's lower clamp of a box's entry parameter (`cwbvh::node::EPSILON`, private there);
/// mod.rs says why the frame makes it harmless.
const EPSILON: f32 = 1e-4;

/// obvhs's `ray_get_octant_inv4` (private there): for each axis, a bit set in every byte when
/// the ray's direction is not negative (x 4, y 2, z 1), for `get_child_and_index_bits`.
#[inline(always)]
pub(super) fn octant_inv4(direction: Vec3A) -> u32 {
    (if direction.x < 0.0 { 0 } else { 0x0404_0404 })
        | (if direction.y < 0.0 { 0 } else { 0x0202_0202 })
        | (if direction.z < 0.0 { 0 } else { 0x0101_0101 })
}

/// The traversal's hit mask for `node`: for each child box the ray meets within
/// `[EPSILON, ray.tmax]`, the child's bits (`get_child_and_index_bits`) shifted into place:
/// the internal children in the top byte in traversal order, the leaf children's primitives
/// in the low 24 bits.
#[inline(always)]
pub(super) fn child_hits(node: &CwBvhNode, ray: &Ray, oct_inv4: u32) -> u32 {
    let scale = node.compute_extent() * ray.inv_direction;
    let shift = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // The near and far planes of each axis, by the sign of the ray's direction.
    let planes = |negative: bool, lo: &[u8; 8], hi: &[u8; 8]| {
        if negative {
            (*hi, *lo)
        } else {
            (*lo, *hi)
        }
    };
    let (near_x, far_x) = planes(ray.direction.x < 0.0, &node.child_min_x, &node.child_max_x);
    let (near_y, far_y) = planes(ray.direction.y < 0.0, &node.child_min_y, &node.child_max_y);
    let (near_z, far_z) = planes(ray.direction.z < 0.0, &node.child_min_z, &node.child_max_z);
    let (bits, index) = node.get_child_and_index_bits(oct_inv4);
    let (bits, index) = (bits.to_le_bytes(), index.to_le_bytes());
    let mut lanes = [0u32; 8];
    for i in 0..8 {
        let t = |q: u8, s: f32, o: f32| f32::from(q) * s + o;
        // `a > b ? a : b` is one maxps (no NaN arises: obvhs keeps 1/d finite).
        let max = |a: f32, b: f32| if a > b { a } else { b };
        let min = |a: f32, b: f32| if a < b { a } else { b };
        let entry = max(
            max(
                t(near_x[i], scale.x, shift.x),
                t(near_y[i], scale.y, shift.y),
            ),
            max(t(near_z[i], scale.z, shift.z), EPSILON),
        );
        let exit = min(
            min(t(far_x[i], scale.x, shift.x), t(far_y[i], scale.y, shift.y)),
            min(t(far_z[i], scale.z, shift.z), ray.tmax),
        );
        let keep = if entry <= exit { u32::MAX } else { 0 };
        lanes[i] = (u32::from(bits[i]) << index[i]) & keep;
    }
    lanes.iter().fold(0, |m, &l| m | l)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::wide::collapse;
    use crate::accel::bvh::wide::tests::{bvh2, random_boxes};
    use crate::testing::Rng;
    use glam::vec3a;

    /// The same masks as obvhs's `intersect_ray` (an independent implementation of the same
    /// test) on every node of the trees our collapse builds over the collapse tests' random
    /// boxes, for rays from all octants, axis-parallel ones and ones with `tmax` cutting
    /// through the boxes.
    #[test]
    fn masks_match_obvhs() {
        let mut rng = Rng::new(7);
        let mut compared = 0;
        let mut hit = 0;
        for (n, kind) in [
            (50, 0),
            (3000, 0),
            (20000, 0),
            (300, 1),
            (2000, 2),
            (500, 3),
        ] {
            let boxes = random_boxes(&mut rng, n, kind);
            let (bvh, _) = collapse(&bvh2(&boxes), 3);
            let (lo, hi) = boxes.iter().fold(
                (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
                |(lo, hi), b| (lo.min(b.min), hi.max(b.max)),
            );
            let size = (hi - lo).max_element();
            for _ in 0..400 {
                let mut next = || rng.f() as f32;
                // Origins in and around the boxes' bounds.
                let origin = lo + (hi - lo) * vec3a(next(), next(), next()) * 1.4 - (hi - lo) * 0.2;
                let mut dir = vec3a(next(), next(), next()) * 2.0 - 1.0;
                // Most rays aimed at a box (most boxes are small), some along an axis or in
                // a coordinate plane.
                match (next() * 8.0) as u32 {
                    0 => dir = vec3a(dir.x, 0.0, 0.0),
                    1 => dir = vec3a(0.0, dir.y, dir.z),
                    2 => {}
                    _ => {
                        let b = &boxes[(next() * n as f32) as usize % n];
                        dir = b.center() - origin;
                    }
                }
                if dir == Vec3A::ZERO {
                    continue;
                }
                let tmax = if next() < 0.5 {
                    f32::INFINITY
                } else {
                    next() * 1.5 * size
                };
                let ray = Ray::new(origin, dir.normalize(), 0.0, tmax);
                let oct = octant_inv4(ray.direction);
                for node in &bvh.nodes {
                    let ours = child_hits(node, &ray, oct);
                    assert_eq!(ours, node.intersect_ray(&ray, oct), "{node:?} {ray:?}");
                    compared += 1;
                    hit += u32::from(ours != 0);
                }
            }
        }
        // The rays do meet boxes (the test is not all misses).
        assert!(hit > compared / 50, "{hit} of {compared}");
    }
}
