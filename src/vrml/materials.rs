//! Material sharing: spheres with equal materials point at one entry of `Scene::materials`.
//!
//! Exporters write a Material per Shape, so a file of a million spheres in a few colours has a
//! million Material nodes and a few distinct materials. Two steps share them:
//! - while reading, [`RecentMaterials`] (a small direct-mapped cache that stays in the CPU
//!   caches) finds a material equal to one seen recently, so files of few colours never store
//!   more than a few;
//! - [`merge_equal`] merges whatever duplicates the cache let through, in one pass over the
//!   materials: when the file is read, and while it is read whenever the materials stored
//!   have doubled since the last merge (so a file of 20 000 colours in random order never
//!   holds a copy per sphere).
//!
//! Together they give exactly what one table of all materials would (the first material of
//! each content keeps its place, in file order), but a file of a million distinct colours no
//! longer pays a cache miss into a large table for every Material node while it is read.

use rayon::prelude::*;

use crate::scene::{mix_in_lanes, same_words, Material, MaterialTable, Scene};

/// Every field's bits ([`Material::key`]).
fn material_key(m: &Material) -> [u64; 15] {
    m.key()
}

/// A fixed (same on every call and every run) hash of a material's key: the lanes' mix, then
/// a final avalanche so that every input bit reaches both the low bits (cache slots) and the
/// high bits (tags).
fn hash_key(key: &[u64; 15]) -> u64 {
    let mut h = mix_in_lanes(key);
    h ^= h >> 33;
    h = h.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    h ^= h >> 33;
    h = h.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    h ^ (h >> 33)
}

/// Slots of [`RecentMaterials`]: 32 KiB, small enough to stay in the L1/L2 caches.
const RECENT_SLOTS: usize = 4096;

/// Materials stored before duplicates are first looked for (6.8 MB): below this, what the
/// cache lets through costs nothing worth a merge.
const MERGE_MIN: usize = 1 << 16;

/// A direct-mapped cache from material content to its index in `Scene::materials`, and the
/// bookkeeping of the merges that remove the duplicates it lets through.
///
/// A material equal to the last one that hashed to its slot is found; any other is pushed
/// and takes the slot. No slot is ever emptied, so an empty slot means no stored material
/// has that slot. Hence while no slot has been taken from another material since the
/// materials were last merged (or ever), every material pushed had no equal before it (an
/// equal one would have hashed to the same slot and still be there): the materials are
/// distinct, and `evicted` says whether that still holds.
pub(crate) struct RecentMaterials {
    /// The high half of the material's hash over its index + 1 into `Scene::materials`; 0 is
    /// empty. (Only a material whose hash matches is read and compared.)
    slots: Box<[u64; RECENT_SLOTS]>,
    evicted: bool,
    /// The hash of each stored material, for [`merge_equal`].
    hashes: Vec<u64>,
    /// Merge again once this many materials are stored (so that a file of many repeated
    /// colours never holds many copies: memory stays within a small factor of the merged set).
    next_merge: usize,
    /// Make the last merge on the thread pool (the main reader of a file read in pieces, for
    /// which it would otherwise be the one part not shared out; one reader stays on one
    /// thread). The merges while reading stay on the main reader's thread: the other cores
    /// are reading pieces then, and sharing them with the pool's threads cost more than it
    /// gained (two-thread parse time 0.985-0.995 with them on one thread, proto 0.97-0.99,
    /// 21 rounds each in turns).
    pub(crate) parallel: bool,
}

impl Default for RecentMaterials {
    fn default() -> Self {
        RecentMaterials {
            slots: Box::new([0; RECENT_SLOTS]),
            evicted: false,
            hashes: Vec::new(),
            next_merge: MERGE_MIN,
            parallel: false,
        }
    }
}

impl RecentMaterials {
    /// The index of `m` in `mats`: a recent equal material's, or a new one's. Every material
    /// of `mats` must have come through here (or through a merge).
    #[inline]
    pub(crate) fn index(&mut self, m: &Material, mats: &mut MaterialTable) -> u32 {
        let key = material_key(m);
        let hash = hash_key(&key);
        let slot = hash as usize % RECENT_SLOTS;
        let tag = hash & !0xFFFF_FFFF;
        let e = self.slots[slot];
        if e != 0 {
            let i = (e as u32).wrapping_sub(1);
            if e & !0xFFFF_FFFF == tag && same_words(&material_key(&mats.get(i as usize)), &key) {
                return i;
            }
            self.evicted = true;
        }
        let i = mats.len() as u32;
        mats.push(*m);
        self.hashes.push(hash);
        self.slots[slot] = tag | (u64::from(i) + 1);
        i
    }

    /// Materials were stored without [`Self::index`] (a chunk's, read on another thread),
    /// with their hashes as the chunk's [`Self::hashes`] gave them (if it had them all):
    /// duplicates may be among them, to be merged like any the cache lets through.
    pub(crate) fn stored_unchecked(&mut self, hashes: &[u64], before: usize, after: usize) {
        self.evicted = true;
        if self.hashes.len() == before && hashes.len() == after - before {
            self.hashes.extend_from_slice(hashes);
        } else {
            // Out of step: recomputed at the next merge.
            self.hashes.clear();
        }
    }

    /// Room for the hashes of `more` materials, if it can be had (a hint).
    pub(crate) fn try_reserve(&mut self, more: usize) {
        let _ = self.hashes.try_reserve_exact(more);
    }

    /// The hash of each material stored, when they are all known.
    pub(crate) fn hashes(&self, stored: usize) -> &[u64] {
        if self.hashes.len() == stored {
            &self.hashes
        } else {
            &[]
        }
    }

    /// Whether enough materials have piled up since the last merge that duplicates should be
    /// merged now (see [`RecentMaterials::merge`]).
    #[inline]
    pub(crate) fn wants_merge(&self, mats: &MaterialTable) -> bool {
        self.evicted && mats.len() >= self.next_merge
    }

    /// Merges equal materials (see [`merge_equal`]) if the cache may have let any through.
    /// Returns where each old index went when any moved: the caller must renumber every index
    /// it holds (spheres, open nodes). The cache follows by itself.
    pub(crate) fn merge(&mut self, mats: &mut MaterialTable) -> Option<Vec<u32>> {
        self.merge_on(mats, false)
    }

    /// [`Self::merge`], on the thread pool if `parallel`.
    fn merge_on(&mut self, mats: &mut MaterialTable, parallel: bool) -> Option<Vec<u32>> {
        if !self.evicted {
            return None;
        }
        let before = mats.len();
        let moved = merge_equal(mats, &mut self.hashes, parallel);
        if let Some(new_index) = &moved {
            for e in self.slots.iter_mut().filter(|e| **e != 0) {
                let i = (*e as u32 - 1) as usize;
                *e = *e & !0xFFFF_FFFF | (u64::from(new_index[i]) + 1);
            }
        }
        // The materials are distinct again. A merge that found few duplicates (distinct
        // colours) waits longer for the next, so that such files pay for about one pass.
        self.evicted = false;
        let factor = if 8 * (before - mats.len()) < before {
            4
        } else {
            2
        };
        self.next_merge = (factor * mats.len()).max(MERGE_MIN);
        moved
    }

    /// The last merge, when the whole file has been read.
    pub(crate) fn finish(mut self, scene: &mut Scene) {
        let parallel = self.parallel;
        let moved = self.merge_on(&mut scene.materials, parallel);
        scene.materials.shrink_to_fit();
        if let Some(new_index) = moved {
            // (A million spheres' lookups, side by side on the thread pool when reading was:
            // the read's last serial step after the merge.)
            if self.parallel {
                scene
                    .spheres
                    .par_iter_mut()
                    .with_min_len(1 << 14)
                    .for_each(|s| s.material = new_index[s.material as usize]);
            } else {
                for s in &mut scene.spheres {
                    s.material = new_index[s.material as usize];
                }
            }
            for s in &mut scene.surfaces {
                s.material = new_index[s.material as usize];
            }
        }
    }
}

/// Merges equal materials: each content keeps its first entry, the entries stay in order (so
/// the unlit material at 0 stays at 0), and `hashes` (the [`hash_key`] of each material,
/// recomputed if the lengths differ) follows. Returns where each old entry went, or None when
/// the materials were already distinct (nothing moved).
///
/// The materials are split by the top bits of their hashes into buckets of a few thousand,
/// each deduplicated with a hash table small enough for the L1/L2 caches: one table over a
/// million materials missed the caches (and the TLB) on every probe.
///
/// With `parallel`, the buckets are deduplicated on the thread pool (the same result).
fn merge_equal(
    mats: &mut MaterialTable,
    hashes: &mut Vec<u64>,
    parallel: bool,
) -> Option<Vec<u32>> {
    let n = mats.len();
    if hashes.len() != n {
        *hashes = mats.iter().map(|m| hash_key(&material_key(&m))).collect();
    }
    if n < 2 {
        return None;
    }
    // About 4096 materials a bucket.
    let bits = (usize::BITS - n.leading_zeros()).saturating_sub(12).min(16);
    let bucket = |h: u64| {
        if bits == 0 {
            0
        } else {
            (h >> (64 - bits)) as usize
        }
    };
    let mut starts = vec![0usize; (1 << bits) + 1];
    for &h in hashes.iter() {
        starts[bucket(h) + 1] += 1;
    }
    for b in 0..1 << bits {
        starts[b + 1] += starts[b];
    }
    // By bucket, within a bucket in index order: the hash's high half over the index.
    let mut pairs = vec![0u64; n];
    let mut next = starts.clone();
    for (i, &h) in hashes.iter().enumerate() {
        let b = bucket(h);
        pairs[next[b]] = h & !0xFFFF_FFFF | i as u64;
        next[b] += 1;
    }
    // The duplicates in bucket `b`, as (material, the first equal to it), into `out`.
    let dups_in = |b: usize, table: &mut Vec<u32>, out: &mut Vec<(u32, u32)>| {
        let part = &pairs[starts[b]..starts[b + 1]];
        let size = (2 * part.len()).next_power_of_two();
        let mask = size - 1;
        table.clear();
        table.resize(size, 0);
        for (k, &p) in part.iter().enumerate() {
            let (tag, i) = ((p >> 32) as u32, p as u32);
            // Position + 1 in `part` of a first material; 0 is empty.
            let mut t = tag as usize & mask;
            loop {
                let e = table[t] as usize;
                if e == 0 {
                    table[t] = k as u32 + 1;
                    break;
                }
                let q = part[e - 1];
                let j = q as u32;
                if (q >> 32) as u32 == tag
                    && same_words(
                        &material_key(&mats.get(j as usize)),
                        &material_key(&mats.get(i as usize)),
                    )
                {
                    out.push((i, j));
                    break;
                }
                t = (t + 1) & mask;
            }
        }
    };
    // The buckets are independent (equal materials share a hash): side by side when asked.
    let dups: Vec<(u32, u32)> = if parallel {
        (0..1usize << bits)
            .into_par_iter()
            .map_init(Vec::new, |table, b| {
                let mut out = Vec::new();
                dups_in(b, table, &mut out);
                out
            })
            .flatten_iter()
            .collect()
    } else {
        let (mut table, mut out) = (Vec::new(), Vec::new());
        for b in 0..1 << bits {
            dups_in(b, &mut table, &mut out);
        }
        out
    };
    // `first[i]`: the first material equal to material i.
    let mut first: Vec<u32> = Vec::new();
    if !dups.is_empty() {
        first = (0..n as u32).collect();
        for (i, j) in dups {
            first[i as usize] = j;
        }
    }
    drop(pairs);
    if first.is_empty() {
        return None;
    }
    // Keep the first of each content, in order; `first[i]` becomes where entry i went.
    let mut kept = 0;
    for i in 0..n {
        let f = first[i] as usize;
        if f == i {
            mats.swap(kept, i);
            hashes.swap(kept, i);
            first[i] = kept as u32;
            kept += 1;
        } else {
            // (f < i, so its new place is already written.)
            first[i] = first[f];
        }
    }
    mats.truncate(kept);
    hashes.truncate(kept);
    Some(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Origin, Sphere};
    use glam::DVec3;

    fn material(i: usize) -> Material {
        Material {
            diffuse: DVec3::new(i as f64 / 7.0, 0.5, (i % 3) as f64),
            ..Material::default()
        }
    }

    /// Reads `picks` (material numbers) as spheres through the cache and the merges, as the
    /// lowering does, and checks the result against sharing done the obvious way: an ordered
    /// map from content to the first entry with it. Returns the most materials stored at once.
    fn check(picks: &[usize]) -> usize {
        // The merges one by one and on the thread pool: the same.
        check_with(picks, true);
        check_with(picks, false)
    }

    fn check_with(picks: &[usize], parallel: bool) -> usize {
        let mut recent = RecentMaterials {
            parallel,
            ..RecentMaterials::default()
        };
        let mut scene = Scene::default();
        let mut most = 0;
        for (k, &p) in picks.iter().enumerate() {
            let mut i = recent.index(&material(p), &mut scene.materials);
            most = most.max(scene.materials.len());
            if recent.wants_merge(&scene.materials) {
                // (On the pool when asked, as only the last merge is while reading: the same.)
                if let Some(new_index) = recent.merge_on(&mut scene.materials, parallel) {
                    for s in &mut scene.spheres {
                        s.material = new_index[s.material as usize];
                    }
                    i = new_index[i as usize];
                }
            }
            scene.spheres.push(Sphere {
                center: DVec3::new(k as f64, 0.0, 0.0),
                radius: 1.0,
                material: i,
                ellipsoid: None,
                origin: Origin::default(),
            });
        }
        recent.finish(&mut scene);
        let mut distinct: Vec<Material> = Vec::new();
        let mut seen = std::collections::BTreeMap::new();
        let mut expect = Vec::new();
        for &p in picks {
            let m = material(p);
            let at = *seen.entry(material_key(&m)).or_insert_with(|| {
                distinct.push(m);
                distinct.len() - 1
            });
            expect.push(at as u32);
        }
        assert_eq!(scene.materials, MaterialTable::from(distinct));
        let got: Vec<u32> = scene.spheres.iter().map(|s| s.material).collect();
        assert_eq!(got, expect);
        most
    }

    #[test]
    fn few_colours_are_shared_while_reading() {
        let picks: Vec<usize> = (0..20_000).map(|k| k * 7 % 5).collect();
        let mut recent = RecentMaterials::default();
        let mut mats = MaterialTable::new();
        for &p in &picks {
            recent.index(&material(p), &mut mats);
        }
        assert_eq!(mats.len(), 5);
        check(&picks);
    }

    #[test]
    fn many_colours_are_shared_when_the_cache_forgets() {
        // 20 000 distinct materials, each seen three times far apart: the cache evicts them.
        let picks: Vec<usize> = (0..60_000).map(|k| (k * 7919) % 20_000).collect();
        check(&picks);
        // All distinct, in order, then all again backwards.
        let picks: Vec<usize> = (0..10_000).chain((0..10_000).rev()).collect();
        check(&picks);
        // Nothing repeated: the merge must leave everything in place.
        let picks: Vec<usize> = (0..30_000).collect();
        check(&picks);
    }

    #[test]
    fn many_repeated_colours_are_merged_while_reading() {
        // 20 000 colours in a scrambled order, 300 000 spheres: the cache forgets nearly
        // every colour before it comes again, so only the merges keep the copies few.
        let picks: Vec<usize> = (0..300_000).map(|k| (k * 7919 + k / 3) % 20_000).collect();
        let most = check(&picks);
        assert!(most <= 2 * MERGE_MIN, "{most} materials stored at once");
    }

    #[test]
    fn pseudo_random_picks_match_the_obvious_sharing() {
        let mut rng = crate::testing::Rng::new(0x2545_F491_4F6C_DD1D);
        for round in 0..20 {
            let kinds = [3, 50, 5000, 100_000][round % 4];
            let picks: Vec<usize> = (0..3000).map(|_| rng.below(kinds)).collect();
            check(&picks);
        }
    }

    #[test]
    fn signed_zero_colours_stay_apart() {
        let mut recent = RecentMaterials::default();
        let mut mats = MaterialTable::new();
        let a = Material {
            emissive: DVec3::new(0.0, 0.0, 0.0),
            ..Material::default()
        };
        let b = Material {
            emissive: DVec3::new(-0.0, 0.0, 0.0),
            ..Material::default()
        };
        assert_ne!(recent.index(&a, &mut mats), recent.index(&b, &mut mats));
        assert_eq!(recent.index(&a, &mut mats), 0);
    }
}
