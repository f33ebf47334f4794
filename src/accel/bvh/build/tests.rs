use super::{
    chunk_ranges, permute_in_place, piece_ranges, radix_sort, sort_and_cut, MAX_CHUNKS, MAX_PIECES,
};
use crate::accel::bvh::Packed;
use crate::testing::Rng;
use glam::DVec3;

/// `n` Morton codes: uniform (`kind` 0), clustered in one top bucket (1, so the deeper
/// passes do the work), or few repeated values (2).
fn random_codes(rng: &mut Rng, n: usize, kind: u32) -> Vec<u64> {
    (0..n)
        .map(|_| match kind {
            0 => rng.u64() >> 1,
            1 => (5u64 << 56) | (rng.u64() >> 20),
            _ => rng.below(7) as u64 * 0x0101_0101_0101,
        })
        .collect()
}

fn codes_of(keys: &[(u64, u32)]) -> Vec<u64> {
    keys.iter().map(|k| k.0).collect()
}

/// The in-place radix sort against the standard sort: codes in order, every primitive
/// still beside its own code, none lost, for uniform, clustered (one top bucket, so the
/// deeper passes do the work), repeated and tiny inputs.
#[test]
fn radix_sort_orders_codes_and_keeps_each_prim_with_its_code() {
    let mut rng = Rng::new(31);
    for (n, kind) in [
        (0, 0),
        (1, 0),
        (31, 0),
        (33, 0),
        (5000, 0),
        (5000, 1),
        (5000, 2),
        (70000, 0),
    ] {
        let mut codes = random_codes(&mut rng, n, kind);
        let original = codes.clone();
        let mut prims: Vec<Packed> = (0..n)
            .map(|i| {
                Packed::new(
                    DVec3::ZERO,
                    1.0,
                    (0, crate::scene::Color::default()),
                    i as u32,
                    false,
                    false,
                )
            })
            .collect();
        radix_sort(&mut prims, &mut codes, 56, 1);
        let mut want = original.clone();
        want.sort_unstable();
        assert_eq!(codes, want, "n {n} kind {kind}");
        for (p, c) in prims.iter().zip(&codes) {
            assert_eq!(original[p.sphere as usize], *c);
        }
        let mut ids: Vec<u32> = prims.iter().map(|p| p.sphere).collect();
        ids.sort_unstable();
        assert!(ids.iter().enumerate().all(|(i, &v)| v == i as u32));
    }
}

/// Stopping the sort at runs of `per_chunk` leaves the chunks a full sort gives: the same
/// ranges, each with the same codes. Uniform and clustered codes (one top bucket, so the
/// deeper passes run), chunks larger and smaller than the buckets, and more cells than
/// chunks allowed (the fixed counts, which need the full sort).
#[test]
fn sorting_as_far_as_the_chunks_need_gives_the_same_chunks() {
    let mut rng = Rng::new(41);
    for (n, per, kind) in [
        (20000, 1000, 0),
        (20000, 1500, 0),
        (20000, 300, 0),
        (20000, 1000, 1),
        (20000, 20000, 0),
        (5000, 40, 2),
    ] {
        let codes = random_codes(&mut rng, n, kind);
        let prims: Vec<Packed> = (0..n)
            .map(|i| {
                Packed::new(
                    DVec3::ZERO,
                    1.0,
                    (0, crate::scene::Color::default()),
                    i as u32,
                    false,
                    false,
                )
            })
            .collect();
        let (mut full, mut full_prims) = (codes.clone(), prims.clone());
        radix_sort(&mut full_prims, &mut full, 56, 1);
        let (mut part, mut part_prims) = (codes.clone(), prims);
        let got = sort_and_cut(&mut part_prims, &mut part, per);
        for (p, c) in part_prims.iter().zip(&part) {
            assert_eq!(codes[p.sphere as usize], *c);
        }
        let ranges = chunk_ranges(&full, per);
        assert_eq!(got, ranges, "n {n} per {per} kind {kind}");
        for r in ranges {
            let mut got = part[r.clone()].to_vec();
            got.sort_unstable();
            assert_eq!(got, full[r], "n {n} per {per} kind {kind}");
        }
    }
}

/// A packed primitive is made in place of an IR sphere (`prepare`'s `into_iter().map()
/// .collect()` reuses the allocation only when it is no larger and as aligned): grown past
/// that, a large scene would silently hold both lists.
#[test]
fn packed_primitives_fit_in_place_of_spheres() {
    use crate::scene::Sphere;
    use std::mem::{align_of, size_of};
    assert_eq!(size_of::<Packed>(), 48);
    assert!(size_of::<Packed>() <= size_of::<Sphere>());
    assert_eq!(align_of::<Packed>(), align_of::<Sphere>());
}

#[test]
fn chunks_follow_morton_cells_and_cover_everything() {
    let mut rng = Rng::new(7);
    // Uniform codes: 8 octants of about n / 8 each, and room for n / 7.5 per chunk.
    let n = 8000;
    let mut keys: Vec<(u64, u32)> = (0..n).map(|i| (rng.u64() >> 1, i)).collect();
    keys.sort_unstable();
    let ranges = chunk_ranges(&codes_of(&keys), n as usize * 2 / 15);
    assert_eq!(ranges.len(), 8);
    for r in &ranges {
        let top = |k: &(u64, u32)| k.0 >> 60;
        assert!(keys[r.clone()]
            .iter()
            .all(|k| top(k) == top(&keys[r.start])));
    }
    // Any sizes: contiguous cover, each within the limit, at most MAX_CHUNKS.
    for (n, per) in [
        (0, 1),
        (1, 1),
        (100, 7),
        (1000, 63),
        (1000, 1000),
        (5000, 313),
    ] {
        let mut keys: Vec<(u64, u32)> = (0..n).map(|i| (rng.u64() >> (1 + i % 50), i)).collect();
        keys.sort_unstable();
        let ranges = chunk_ranges(&codes_of(&keys), per);
        assert!(ranges.len() <= MAX_CHUNKS.max(n.div_ceil(per as u32) as usize));
        let mut at = 0;
        for r in ranges {
            assert_eq!(r.start, at);
            assert!(r.end > r.start && r.end - r.start <= per);
            at = r.end;
        }
        assert_eq!(at, n as usize);
    }
    // Equal codes: fixed counts.
    let keys = vec![(5u64, 0u32); 100];
    assert_eq!(chunk_ranges(&codes_of(&keys), 30).len(), 4);
}

/// A chunk's pieces: a contiguous cover of the chunk in at most [`MAX_PIECES`] runs, each
/// within the size asked where the cells allow it, on Morton cells when they fit.
#[test]
fn pieces_cover_a_chunk_in_at_most_eight_runs() {
    let mut rng = Rng::new(8);
    for (n, piece) in [
        (1, 1),
        (9, 1),
        (1000, 125),
        (1000, 40),
        (5000, 700),
        (64, 1000),
    ] {
        let mut codes = random_codes(&mut rng, n, 0);
        codes.sort_unstable();
        let ranges = piece_ranges(&codes, piece);
        assert!(
            !ranges.is_empty() && ranges.len() <= MAX_PIECES,
            "{n} {piece}"
        );
        let mut at = 0;
        for r in &ranges {
            assert_eq!(r.start, at);
            assert!(r.end > r.start);
            at = r.end;
        }
        assert_eq!(at, n);
        if n.div_ceil(piece) <= MAX_PIECES / 2 {
            assert!(
                ranges.iter().all(|r| r.len() <= piece),
                "{n} {piece} {ranges:?}"
            );
        }
    }
    // Equal codes: fixed counts.
    assert_eq!(piece_ranges(&[3; 100], 30).len(), 4);
    assert_eq!(piece_ranges(&[3; 100], 5).len(), MAX_PIECES);
}

#[test]
fn permutation_in_place_matches_a_copy() {
    let mut rng = Rng::new(12345);
    for n in [0usize, 1, 2, 3, 10, 100, 1000] {
        // A random permutation by Fisher-Yates.
        let mut order: Vec<u32> = (0..n as u32).collect();
        for k in (1..n).rev() {
            order.swap(k, rng.below(k + 1));
        }
        let v: Vec<u64> = (0..n as u64).map(|x| x * 7 + 1).collect();
        let want: Vec<u64> = order.iter().map(|&i| v[i as usize]).collect();
        let mut got = v.clone();
        permute_in_place(&mut got, &order);
        assert_eq!(got, want);
    }
}

/// A cluster of 1000 small spheres and one sphere of radius 1e9 far away (an extent 1e10
/// times the cluster's detail): segments through the cluster test few primitives exactly
/// (each chunk's f32 frame fits its own primitives, and the outsized one has a chunk of its
/// own), and still every sphere whose box a segment meets.
#[test]
fn an_outsized_far_sphere_leaves_the_cluster_cheap_to_trace() {
    let mut rng = Rng::new(7);
    let sphere = |center: DVec3, radius: f64, i: usize| crate::accel::Prim {
        center,
        radius,
        color: crate::scene::Color::default(),
        material: 0,
        sphere: i as u32,
        ellipsoid: None,
        gas: false,
        sigma: 0.0,
        profile: crate::scene::Profile::Constant,
    };
    let mut ps: Vec<_> = (0..1000)
        .map(|i| {
            let c = DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0;
            sphere(c, 0.01, i)
        })
        .collect();
    ps.push(sphere(DVec3::new(1e10, 3e9, -2e9), 1e9, 1000));
    let bvh = crate::accel::SphereBvh::build(ps.clone(), &[]);
    let (mut tested, rays) = (0usize, 200);
    for _ in 0..rays {
        let o = DVec3::new(rng.f(), rng.f(), rng.f()) * 6.0 - 3.0;
        let target = DVec3::new(rng.f(), rng.f(), rng.f()) * 2.0 - 1.0;
        let d = target - o;
        let mut seen = vec![false; ps.len()];
        bvh.any_prim_except((o, d), (0.0, 2.0), None, |i| {
            tested += 1;
            seen[bvh.prim(i).sphere as usize] = true;
            false
        });
        // Every sphere whose box the segment meets is among those tested.
        for p in &ps {
            let (lo, hi) = (p.center - p.radius, p.center + p.radius);
            let (mut t0, mut t1) = (0.0f64, 2.0f64);
            for a in 0..3 {
                let (u, v) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
            }
            assert!(
                t0 > t1 || seen[p.sphere as usize],
                "sphere {} missed",
                p.sphere
            );
        }
    }
    assert!(tested < 50 * rays, "{} exact tests per ray", tested / rays);
}
