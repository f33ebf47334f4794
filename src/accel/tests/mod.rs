//! The BVH (f32 padded boxes) against a brute-force loop over every sphere: the closest hit,
//! the any-hit query and the all-hits query must find exactly what the loop finds, for tiny
//! and huge spheres, far-off scenes, rays from far away, axis-parallel and grazing rays.

use std::collections::BTreeSet;

use crate::accel::{Prim, SphereBvh};
use crate::geom::sphere_roots;
use glam::DVec3;

use crate::testing::Rng;

mod benchmark_scene;

impl Rng {
    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.f(), self.f(), self.f()) * 2.0 - 1.0;
            if v.length_squared() > 1e-6 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

fn prims(rng: &mut Rng, n: usize, offset: DVec3, extent: f64, r_lo: f64, r_hi: f64) -> Vec<Prim> {
    (0..n)
        .map(|i| Prim {
            center: offset + (DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0) * extent,
            radius: r_lo * (r_hi / r_lo).powf(rng.f()),
            color: crate::scene::Color::default(),
            material: 0,
            sphere: i as u32,
            ellipsoid: None,
            gas: false,
            sigma: 0.0,
            profile: crate::scene::Profile::Constant,
        })
        .collect()
}

/// Brute force: the smallest first root > 0 (one-sided, as the renderer's camera rays).
fn brute_closest(ps: &[Prim], o: DVec3, d: DVec3) -> Option<(f64, u32)> {
    ps.iter()
        .filter_map(|p| {
            let (t0, _) = sphere_roots(o, d, p.center, p.radius)?;
            (t0 > 0.0).then_some((t0, p.sphere))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

fn check_scene(seed: u64, n: usize, offset: DVec3, extent: f64, r_lo: f64, r_hi: f64) {
    let mut rng = Rng(seed);
    let ps = prims(&mut rng, n, offset, extent, r_lo, r_hi);
    // One chunk; a few; as many as allowed (a chunk per n / 16 spheres).
    let one = SphereBvh::build(ps.clone(), &[]);
    let few = SphereBvh::build_chunked(ps.clone(), &[], (n / 5, n / 5));
    let many = SphereBvh::build_chunked(ps.clone(), &[], (1, 1));
    // A few chunks, each built in pieces (as many as allowed) joined under one root.
    let pieces = SphereBvh::build_chunked(ps.clone(), &[], (n / 3, 1));
    for bvh in [&one, &few, &many, &pieces] {
        check_rays(seed, &ps, bvh, offset, extent, &mut rng);
        check_packets(seed, &ps, bvh, offset, extent, &mut rng);
        check_regions(&ps, bvh, offset, extent, &mut rng);
    }
}

/// `near_region` with a box region visits every primitive whose box meets it.
fn check_regions(ps: &[Prim], bvh: &SphereBvh, offset: DVec3, extent: f64, rng: &mut Rng) {
    let mut stack = Vec::new();
    for _ in 0..20 {
        let c = offset + (rng.unit() * 0.6) * extent;
        let h = DVec3::splat(extent * 0.05 * (0.1 + rng.f()));
        let (a, b) = (c - h, c + h);
        let meets = |lo: DVec3, hi: DVec3| lo.cmple(b).all() && hi.cmpge(a).all();
        let mut seen = vec![false; ps.len()];
        bvh.near_region(meets, |_, p| seen[p.sphere as usize] = true, &mut stack);
        for p in ps {
            if meets(p.center - p.radius, p.center + p.radius) {
                assert!(
                    seen[p.sphere as usize],
                    "sphere {} near {c} missed",
                    p.sphere
                );
            }
        }
    }
}

fn check_rays(seed: u64, ps: &[Prim], bvh: &SphereBvh, offset: DVec3, extent: f64, rng: &mut Rng) {
    let n = ps.len();
    let mut hits = 0;
    let mut blocked_skipping = [0; 2];
    for k in 0..400 {
        // Origins: inside the cloud, just outside, and far away (1e4 extents).
        let dist = [0.0, 2.0, 1e4][k % 3] * extent;
        let o = offset + rng.unit() * dist + (DVec3::new(rng.f(), rng.f(), rng.f()) - 0.5) * extent;
        let mut d = match k % 6 {
            // Aim at a sphere (some rays graze it: aim at its rim).
            0 | 1 => {
                let p = &ps[(rng.f() * n as f64) as usize % n];
                let rim = p.center + rng.unit() * p.radius * (1.0 - 1e-9 * rng.f());
                (rim - o).normalize()
            }
            2 => DVec3::Z,
            3 => DVec3::new(1e-9, -1.0, 3e-10).normalize(),
            // Negative zeros (a DirectionalLight along -x gives to_light (1, 0, -0)).
            4 => DVec3::new(-0.0, 0.3 * rng.f() - 0.15, -1.0).normalize(),
            _ => rng.unit(),
        };
        if d.length_squared() == 0.0 || !d.is_finite() {
            d = DVec3::X;
        }
        let want = brute_closest(ps, o, d);
        let got = bvh
            .closest(o, d, 0.0, f64::INFINITY, |_, _, (t0, _)| {
                (t0 > 0.0).then_some(t0)
            })
            .map(|h| (h.t, bvh.prim(h.prim).sphere));
        assert_eq!(got, want, "closest: seed {seed} ray {k} o {o} d {d}");
        hits += usize::from(want.is_some());

        // Any hit within a segment, and all hits.
        let tmax = extent * 2.0 * rng.f() + dist;
        let brute_any = ps.iter().any(|p| {
            sphere_roots(o, d, p.center, p.radius).is_some_and(|(t0, _)| t0 > 0.0 && t0 < tmax)
        });
        let got_any = bvh.any(o, d, 0.0, tmax, |_, _, (t0, _)| t0 > 0.0 && t0 < tmax);
        assert_eq!(got_any, brute_any, "any: seed {seed} ray {k}");

        // An any-hit query passing over a primitive (as a shadow ray does its own sphere).
        let skip = (rng.f() * n as f64) as u32 % n as u32;
        let skipped = bvh.prim(skip).sphere;
        let brute_skip = ps.iter().any(|p| {
            p.sphere != skipped
                && sphere_roots(o, d, p.center, p.radius)
                    .is_some_and(|(t0, _)| t0 > 0.0 && t0 < tmax)
        });
        let got = bvh.any_except(o, d, 0.0, tmax, Some(skip), |i, _, (t0, _)| {
            assert_ne!(
                i, skip,
                "seed {seed} ray {k}: the skipped primitive was offered"
            );
            t0 > 0.0 && t0 < tmax
        });
        assert_eq!(got, brute_skip, "any_except: seed {seed} ray {k}");
        blocked_skipping[usize::from(got)] += 1;

        let brute_all: BTreeSet<u32> = ps
            .iter()
            .filter(|p| {
                sphere_roots(o, d, p.center, p.radius).is_some_and(|(t0, t1)| t1 > 0.0 && t0 < tmax)
            })
            .map(|p| p.sphere)
            .collect();
        let mut got_all = BTreeSet::new();
        bvh.all(o, d, 0.0, tmax, |_, p, (t0, t1)| {
            if t1 > 0.0 && t0 < tmax {
                got_all.insert(p.sphere);
            }
        });
        assert_eq!(got_all, brute_all, "all: seed {seed} ray {k}");
    }
    assert!(hits > 40, "only {hits} rays hit: the test lost its teeth");
    // Both answers occur (a scene of one sphere, passed over, blocks nothing).
    assert!(
        n < 10 || blocked_skipping.iter().all(|&b| b > 20),
        "{blocked_skipping:?}"
    );
}

/// `closest_packet`'s answers as `brute_closest` gives them (one-sided, from `t > 0`).
fn packet_closest(
    bvh: &SphereBvh,
    rays: &[(DVec3, DVec3)],
    stack: &mut crate::accel::PacketStack,
) -> Vec<Option<(f64, u32)>> {
    let mut got = [None; crate::accel::PACKET];
    bvh.closest_packet(
        rays,
        0.0,
        f64::INFINITY,
        &mut got,
        stack,
        |_, _, _, (t0, _)| (t0 > 0.0).then_some(t0),
    );
    got[..rays.len()]
        .iter()
        .map(|h| h.map(|h| (h.t, bvh.prim(h.prim).sphere)))
        .collect()
}

/// `closest_packet` against brute force and against `closest` one ray at a time: coherent
/// packets from one origin (a camera tile's pixels, from wide to a millionth of a sphere
/// apart), parallel rays from a grid of origins, rays straddling an axis plane (mixed
/// direction signs), and unrelated rays, from inside the cloud, near it and far away.
fn check_packets(
    seed: u64,
    ps: &[Prim],
    bvh: &SphereBvh,
    offset: DVec3,
    extent: f64,
    rng: &mut Rng,
) {
    let n = ps.len();
    let mut stack = crate::accel::PacketStack::default();
    let mut hits = 0;
    for k in 0..120 {
        let dist = [0.0, 2.0, 1e4][k % 3] * extent;
        let o = offset + rng.unit() * dist + (DVec3::new(rng.f(), rng.f(), rng.f()) - 0.5) * extent;
        let p = &ps[(rng.f() * n as f64) as usize % n];
        // The packet's centre aims at a sphere's centre or its rim.
        let aim = p.center + rng.unit() * p.radius * [0.0, 0.5, 1.0 - 1e-9][k % 3];
        let axis = (aim - o).normalize();
        let (u, v) = (
            axis.cross(rng.unit()).normalize(),
            axis.cross(rng.unit()).normalize(),
        );
        let spread = [1e-6, 0.3, 1.0, 5.0][(k / 3) % 4] * p.radius / (aim - o).length().max(1e-300);
        let count = 1 + (rng.f() * 16.0) as usize % 16;
        let mut os = vec![o; count];
        let mut ds = vec![axis; count];
        for j in 0..count {
            let (a, b) = ((j % 4) as f64 - 1.5, (j / 4) as f64 - 1.5);
            match (k / 12) % 5 {
                // One origin, a grid of directions.
                0 | 1 => ds[j] = (axis + (a * u + b * v) * spread).normalize(),
                // Parallel rays from a grid of origins.
                2 => os[j] = o + (a * u + b * v) * p.radius * 0.7,
                // Straddling the plane x = 0 of directions (some x components of either sign).
                3 => ds[j] = DVec3::new((a + b) * 1e-3, axis.y, axis.z).normalize(),
                // Unrelated rays.
                _ => {
                    os[j] = offset + rng.unit() * dist;
                    ds[j] = rng.unit();
                }
            }
        }
        if k % 5 == 4 {
            // Directions of other lengths (the parameters scale with them).
            for d in &mut ds {
                *d *= [1e-3, 0.5, 7.0][k % 3] * (1.0 + rng.f());
            }
        }
        let rays: Vec<(DVec3, DVec3)> = os.iter().copied().zip(ds.iter().copied()).collect();
        let got = packet_closest(bvh, &rays, &mut stack);
        for j in 0..count {
            let (o, d) = (os[j], ds[j]);
            let want = brute_closest(ps, o, d);
            let one = bvh
                .closest(o, d, 0.0, f64::INFINITY, |_, _, (t0, _)| {
                    (t0 > 0.0).then_some(t0)
                })
                .map(|h| (h.t, bvh.prim(h.prim).sphere));
            let got = got[j];
            assert_eq!(
                got, want,
                "packet: seed {seed} packet {k} ray {j} o {o} d {d}"
            );
            assert_eq!(one, want);
            hits += usize::from(want.is_some());
        }
    }
    assert!(
        hits > 100,
        "only {hits} packet rays hit: the test lost its teeth"
    );
}

#[test]
fn bvh_matches_brute_force_unit_scene() {
    check_scene(1, 2000, DVec3::ZERO, 1.0, 0.005, 0.05);
}

#[test]
fn bvh_matches_brute_force_tiny_spheres_far_from_origin() {
    // Coordinates near 1e6 with radii near 1e-4: f32 boxes without the recentring and
    // padding would lose these spheres entirely.
    check_scene(2, 1500, DVec3::new(1e6, -2e6, 5e5), 1.0, 1e-4, 1e-3);
}

#[test]
fn bvh_matches_brute_force_mixed_scales() {
    check_scene(3, 1500, DVec3::new(-30.0, 4.0, 7.0), 100.0, 1e-3, 20.0);
}

#[test]
fn bvh_single_sphere_and_empty() {
    check_scene(4, 1, DVec3::ZERO, 1.0, 0.5, 0.5);
    let empty = SphereBvh::build(Vec::new(), &[]);
    assert!(empty
        .closest(DVec3::ZERO, DVec3::Z, 0.0, f64::INFINITY, |_, _, r| Some(
            r.0
        ))
        .is_none());
}

/// The grazing case through the BVH: a sphere of radius 1e-3 at distance 1e4,
/// rays within 1e-9 (relative) of tangency: the BVH agrees with the exact sphere test on
/// every ray (that test is checked against exact arithmetic in `geom`).
#[test]
fn grazing_rays_through_the_bvh() {
    let c = DVec3::new(3e3, -4e3, 9e3);
    let r = 1e-3;
    let mut rng = Rng(9);
    let others = prims(&mut rng, 50, c, 0.05, 1e-4, 1e-3);
    let mut ps = vec![Prim {
        center: c,
        radius: r,
        color: crate::scene::Color::default(),
        material: 0,
        sphere: 999,
        ellipsoid: None,
        gas: false,
        sigma: 0.0,
        profile: crate::scene::Profile::Constant,
    }];
    ps.extend(others);
    let bvh = SphereBvh::build(ps.clone(), &[]);
    let (mut hit, mut miss) = (0, 0);
    for k in 0..2000 {
        let o = DVec3::ZERO;
        let axis = (c - o).normalize();
        let side = axis.cross(rng.unit()).normalize();
        let off = r * (1.0 + (rng.f() * 2.0 - 1.0) * 1e-9);
        let d = ((c + side * off) - o).normalize();
        let want = brute_closest(&ps, o, d);
        let got = bvh
            .closest(o, d, 0.0, f64::INFINITY, |_, _, (t0, _)| {
                (t0 > 0.0).then_some(t0)
            })
            .map(|h| (h.t, bvh.prim(h.prim).sphere));
        assert_eq!(got, want, "ray {k}");
        if let Some((t, _)) = got {
            assert!(t.is_finite());
            hit += 1;
        } else {
            miss += 1;
        }
    }
    assert!(hit > 100 && miss > 100, "hit {hit} miss {miss}");

    // The same grazing rays sixteen at a time: one origin, directions a millionth of the
    // sphere apart, so they walk as one packet.
    let mut stack = crate::accel::PacketStack::default();
    let (mut hit, mut miss) = (0, 0);
    for k in 0..200 {
        let axis = c.normalize();
        let side = axis.cross(rng.unit()).normalize();
        let rays: Vec<(DVec3, DVec3)> = (0..16)
            .map(|_| {
                let off = r * (1.0 + (rng.f() * 2.0 - 1.0) * 1e-9);
                (DVec3::ZERO, (c + side * off).normalize())
            })
            .collect();
        let got = packet_closest(&bvh, &rays, &mut stack);
        for (j, &(o, d)) in rays.iter().enumerate() {
            let want = brute_closest(&ps, o, d);
            assert_eq!(got[j], want, "packet {k} ray {j}");
            if want.is_some() {
                hit += 1;
            } else {
                miss += 1;
            }
        }
    }
    assert!(hit > 200 && miss > 200, "packets: hit {hit} miss {miss}");
}

/// `n` spheres, sphere `i` at `center(i)` of radius `radius(i)`.
fn cluster(n: usize, center: impl Fn(usize) -> DVec3, radius: impl Fn(usize) -> f64) -> Vec<Prim> {
    (0..n)
        .map(|i| Prim {
            center: center(i),
            radius: radius(i),
            color: crate::scene::Color::default(),
            material: 0,
            sphere: i as u32,
            ellipsoid: None,
            gas: false,
            sigma: 0.0,
            profile: crate::scene::Profile::Constant,
        })
        .collect()
}

/// A depth bound of `O(log n)`: twice the depth of a balanced binary tree, plus a little.
fn assert_log_depth(bvh: &SphereBvh, n: usize) {
    let bound = 2 * n.next_power_of_two().trailing_zeros() as usize + 4;
    assert!(
        bvh.depth() <= bound,
        "{n} primitives: depth {} > {bound}",
        bvh.depth()
    );
}

/// Closest hits of rays aimed near the centres of `ps[aim]` against brute force.
fn check_cluster_rays(ps: &[Prim], aim: std::ops::Range<usize>, bvh: &SphereBvh, seed: u64) {
    let mut rng = Rng(seed);
    let mut hits = 0;
    for _ in 0..200 {
        let target = ps[aim.start + (rng.f() * aim.len() as f64) as usize % aim.len()].center;
        let o = target + rng.unit() * 3.0;
        let d = (target + (DVec3::new(rng.f(), rng.f(), rng.f()) - 0.5) * 0.03 - o).normalize();
        let got = bvh
            .closest(o, d, 0.0, f64::INFINITY, |_, _, (t0, _)| {
                (t0 > 0.0).then_some(t0)
            })
            .map(|h| (h.t, bvh.prim(h.prim).sphere));
        // Ties between coincident spheres go to the first, as in the brute force.
        let want = brute_closest(ps, o, d);
        assert_eq!(got, want, "ray {o} {d}");
        hits += usize::from(want.is_some());
    }
    assert!(hits > 50, "only {hits} rays hit: the test lost its teeth");
}

/// Coincident spheres (one centre, one radius) build a tree `O(log n)` deep: PLOC alone
/// merges one pair of equal boxes per pass, a chain as deep as the cluster.
#[test]
fn coincident_spheres_build_a_shallow_tree() {
    let n = 4096;
    let ps = cluster(n, |_| DVec3::new(0.3, -0.2, 0.1), |_| 0.01);
    let bvh = SphereBvh::build(ps.clone(), &[]);
    assert_log_depth(&bvh, n);
    check_cluster_rays(&ps, 0..n, &bvh, 11);
}

/// Concentric spheres of growing radii (one Morton code, costs rising along the input
/// order), and a few centres among them.
#[test]
fn concentric_spheres_build_a_shallow_tree() {
    let n = 3000;
    let ps = cluster(
        n,
        |i| DVec3::new((i % 3) as f64 * 0.5, 0.0, 0.0),
        |i| 0.01 + 1e-5 * i as f64,
    );
    let bvh = SphereBvh::build(ps.clone(), &[]);
    assert_log_depth(&bvh, n);
    check_cluster_rays(&ps, 0..n, &bvh, 12);
}

/// 1e5 coincident spheres and a few far ones: a bounded depth, every hit as brute force.
#[test]
fn coincident_cluster_with_far_spheres_builds_a_shallow_tree() {
    let n = 100_000;
    let far = [
        DVec3::new(50.0, 0.0, 0.0),
        DVec3::new(0.0, -80.0, 3.0),
        DVec3::splat(1e3),
    ];
    let ps = cluster(
        n + far.len(),
        |i| if i < n { DVec3::ZERO } else { far[i - n] },
        |i| if i < n { 0.5 } else { 1.0 },
    );
    let bvh = SphereBvh::build(ps.clone(), &[]);
    assert_log_depth(&bvh, ps.len());
    check_cluster_rays(&ps, n - 5..ps.len(), &bvh, 13);
}

/// A row of equally spaced spheres and one sphere 1e12 away: the far one puts the whole
/// row in one Morton cell, whose equal merge costs PLOC alone pairs one per pass.
#[test]
fn row_of_spheres_beside_a_far_one_builds_a_shallow_tree() {
    let n = 4096;
    let ps = cluster(
        n + 1,
        |i| {
            if i < n {
                DVec3::new(i as f64 * 0.03, 0.0, 0.0)
            } else {
                DVec3::splat(1e12)
            }
        },
        |_| 0.01,
    );
    let bvh = SphereBvh::build(ps.clone(), &[]);
    assert_log_depth(&bvh, ps.len());
    check_cluster_rays(&ps, 0..n, &bvh, 14);
}
