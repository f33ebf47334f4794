//! The scene's materials, stored compactly: a file with a colour per sphere has about as many
//! distinct materials as spheres, and a 104-byte [`Material`] each would be most of a large
//! scene's memory. Two observations make most materials 8 bytes:
//! - materials that differ only in their diffuse colour, the usual case (VMD, OVITO and
//!   `convert` write one Material per colour), share one stored record of everything else;
//! - the channel values of the colours are few, even when the colours are many: 256 for
//!   8-bit colours, at most 100 001 for colours written with 5 decimals. They go in a
//!   palette.
//!
//! An entry is then one word: the palette indices of its three channels (18 bits each) and
//! its record's index (9 bits). A material whose record is past the 512th, or whose channel
//! values are past the palette's 2^18th, is stored whole instead (its colour and record index,
//! 32 bytes). Every value is kept exactly as given, by its bits: [`MaterialTable::get`]
//! returns the very `Material` that was pushed.

use glam::DVec3;
use hashbrown::HashMap;

use super::Material;

/// Slots of the direct-mapped cache that finds a stored record equal to a new one.
const SLOTS: usize = 1024;

/// Slots of the channel value cache (4 KiB).
const CHANNEL_SLOTS: usize = 1024;

/// Tags a packed entry (else: an index into `MaterialTable::wide`).
const PACKED: u64 = 1 << 63;
const CHANNEL_BITS: u32 = 18;
const CHANNEL: u64 = (1 << CHANNEL_BITS) - 1;
/// Records a packed entry can name.
const PACKED_RECORDS: u32 = 1 << 9;

/// The materials of a scene, indexed by `Sphere::material` and `Surface::material`.
#[derive(Clone, Default)]
pub struct MaterialTable {
    /// Each entry: `PACKED | record << 54 | r << 36 | g << 18 | b` (palette indices), or an
    /// index into `wide`.
    entries: Vec<u64>,
    /// Channel values of packed colours.
    palette: Vec<f64>,
    /// Where each value's bits are in `palette`; rebuilt when needed after
    /// [`MaterialTable::shrink_to_fit`] dropped it.
    palette_index: Option<HashMap<u64, u32>>,
    /// Entries that do not pack: diffuse colour and record.
    wide: Vec<(DVec3, u32)>,
    /// Everything but the diffuse colour (stored with a zero diffuse colour).
    rest: Vec<Material>,
    /// A cache from a record's content to its index in `rest` + 1 (0: empty). Only a search
    /// aid: a record it misses is stored again, which costs memory, never a wrong material.
    recent: Option<Box<[u32; SLOTS]>>,
    /// A cache from a channel value's bits to its index in `palette` + 1 (0: empty), looked
    /// at before `palette_index` (a hash map probe for each of three channels was 40 % of a
    /// push's instructions).
    recent_channels: Option<Box<[u32; CHANNEL_SLOTS]>>,
    /// The record found or stored last, looked at before the cache (most files have one
    /// record: materials that differ in their diffuse colour only).
    last_record: u32,
}

/// The bits of everything but the diffuse colour.
fn rest_key(m: &Material) -> [u64; 12] {
    let k = m.key();
    [
        k[3], k[4], k[5], k[6], k[7], k[8], k[9], k[10], k[11], k[12], k[13], k[14],
    ]
}

/// A multiply-xor mix of `words` (fixed: the same on every call and every run) in three
/// independent lanes, words 0, 3, 6, ... in the first: a third of the dependent
/// multiplications of one chain, which sat before every material's cache lookup. Not yet
/// avalanched: callers finish it for the bits they use.
pub(crate) fn mix_in_lanes(words: &[u64]) -> u64 {
    let mut lanes = [0u64, 1, 2];
    for chunk in words.chunks(3) {
        for (h, &k) in lanes.iter_mut().zip(chunk) {
            *h = (h.rotate_left(23) ^ k).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    lanes[0] ^ lanes[1].rotate_left(21) ^ lanes[2].rotate_left(42)
}

/// `a == b` for keys of material bits, word by word without a branch or a `memcmp` call
/// (the record cache compares one key a sphere: the call was 2-3 % of reading in `perf`).
#[inline(always)]
pub(crate) fn same_words<const N: usize>(a: &[u64; N], b: &[u64; N]) -> bool {
    a.iter().zip(b).fold(0, |d, (x, y)| d | (x ^ y)) == 0
}

/// The two slots of the record cache a key may sit in (two, so that two records used in turn
/// that hash to one slot do not evict each other and get stored again at every turn).
fn slots(key: &[u64; 12]) -> [usize; 2] {
    let mut h = mix_in_lanes(key);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    [(h >> 40) as usize % SLOTS, (h >> 20) as usize % SLOTS]
}

impl MaterialTable {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Material `i`. Panics when `i` is out of range, as indexing a `Vec` would.
    #[inline]
    pub fn get(&self, i: usize) -> Material {
        let e = self.entries[i];
        let (diffuse, record) = if e & PACKED != 0 {
            let channel = |shift: u32| self.palette[(e >> shift & CHANNEL) as usize];
            (
                DVec3::new(channel(2 * CHANNEL_BITS), channel(CHANNEL_BITS), channel(0)),
                (e >> (3 * CHANNEL_BITS)) as u32 & (PACKED_RECORDS - 1),
            )
        } else {
            self.wide[e as usize]
        };
        Material {
            diffuse,
            ..self.rest[record as usize]
        }
    }

    /// The palette index of value `v`, added if new and there is room.
    fn channel(&mut self, v: f64) -> Option<u64> {
        let bits = v.to_bits();
        let slot = (bits.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 54) as usize % CHANNEL_SLOTS;
        let recent = self
            .recent_channels
            .get_or_insert_with(|| Box::new([0; CHANNEL_SLOTS]));
        let e = recent[slot] as usize;
        if e != 0 && self.palette[e - 1].to_bits() == bits {
            return Some(e as u64 - 1);
        }
        let k = self.channel_slow(v)?;
        if let Some(recent) = &mut self.recent_channels {
            recent[slot] = k as u32 + 1;
        }
        Some(k)
    }

    /// [`Self::channel`] past its cache.
    fn channel_slow(&mut self, v: f64) -> Option<u64> {
        let palette = &self.palette;
        let index = self.palette_index.get_or_insert_with(|| {
            palette
                .iter()
                .enumerate()
                .map(|(k, v)| (v.to_bits(), k as u32))
                .collect()
        });
        if let Some(&k) = index.get(&v.to_bits()) {
            return Some(u64::from(k));
        }
        let k = self.palette.len();
        if k as u64 > CHANNEL {
            return None;
        }
        self.palette.push(v);
        index.insert(v.to_bits(), k as u32);
        Some(k as u64)
    }

    /// Appends every material of `other`, in order: what [`Self::push`] of each would store,
    /// with `other`'s palette and records looked up once each rather than once per material
    /// (for the tables of a file's pieces read on other threads).
    pub fn append(&mut self, other: &MaterialTable) {
        let records: Vec<u32> = other.rest.iter().map(|m| self.record(m)).collect();
        let palette: Vec<Option<u64>> = other.palette.iter().map(|&v| self.channel(v)).collect();
        self.entries.reserve(other.entries.len());
        for (i, &e) in other.entries.iter().enumerate() {
            let word = if e & PACKED != 0 {
                let r = records[(e >> (3 * CHANNEL_BITS)) as usize & (PACKED_RECORDS as usize - 1)];
                let channel = |shift: u32| palette[(e >> shift & CHANNEL) as usize];
                match (channel(2 * CHANNEL_BITS), channel(CHANNEL_BITS), channel(0)) {
                    (Some(x), Some(y), Some(z)) if r < PACKED_RECORDS => Ok(PACKED
                        | u64::from(r) << (3 * CHANNEL_BITS)
                        | x << (2 * CHANNEL_BITS)
                        | y << CHANNEL_BITS
                        | z),
                    _ => Err((other.get(i).diffuse, r)),
                }
            } else {
                let (c, r) = other.wide[e as usize];
                Err((c, records[r as usize]))
            };
            let entry = word.unwrap_or_else(|wide| {
                self.wide.push(wide);
                (self.wide.len() - 1) as u64
            });
            self.entries.push(entry);
        }
    }

    /// The index in `rest` of a record equal to `m`'s (all but the diffuse colour), stored if
    /// the cache finds none.
    fn record(&mut self, m: &Material) -> u32 {
        let key = rest_key(m);
        let last = self.last_record;
        if self
            .rest
            .get(last as usize)
            .is_some_and(|l| same_words(&rest_key(l), &key))
        {
            return last;
        }
        let [a, b] = slots(&key);
        let recent = self.recent.get_or_insert_with(|| Box::new([0; SLOTS]));
        let rest = &self.rest;
        let at = |s: usize| match recent[s] {
            0 => None,
            e => same_words(&rest_key(&rest[e as usize - 1]), &key).then_some(e - 1),
        };
        if let Some(r) = at(a).or_else(|| at(b)) {
            self.last_record = r;
            return r;
        }
        let r = self.rest.len() as u32;
        self.rest.push(Material {
            diffuse: DVec3::ZERO,
            ..*m
        });
        // An empty slot of the two, else the first.
        let s = if recent[a] != 0 && recent[b] == 0 {
            b
        } else {
            a
        };
        recent[s] = r + 1;
        self.last_record = r;
        r
    }

    /// Appends `m` (no search for an equal material: the loader shares materials) and returns
    /// its index.
    pub fn push(&mut self, m: Material) -> u32 {
        let r = self.record(&m);
        let i = self.entries.len() as u32;
        let c = m.diffuse;
        let packed = if r < PACKED_RECORDS {
            (|| {
                let (x, y, z) = (self.channel(c.x)?, self.channel(c.y)?, self.channel(c.z)?);
                Some(
                    PACKED
                        | u64::from(r) << (3 * CHANNEL_BITS)
                        | x << (2 * CHANNEL_BITS)
                        | y << CHANNEL_BITS
                        | z,
                )
            })()
        } else {
            None
        };
        let entry = packed.unwrap_or_else(|| {
            self.wide.push((c, r));
            (self.wide.len() - 1) as u64
        });
        self.entries.push(entry);
        i
    }

    /// Whether some material may be gas (`Material::is_gas`): false means none is. (Answered
    /// from the shared records alone, which gas-ness does not depend on the diffuse colour of;
    /// a record no entry uses any more can make it true for nothing.)
    pub fn may_have_gas(&self) -> bool {
        self.rest.iter().any(Material::is_gas)
    }

    /// Whether some gas material may have a density profile other than constant (answered
    /// like [`Self::may_have_gas`]).
    pub fn may_have_profiled_gas(&self) -> bool {
        self.rest
            .iter()
            .any(|m| m.is_gas() && m.profile != super::Profile::Constant)
    }

    /// Swaps entries `a` and `b`.
    pub fn swap(&mut self, a: usize, b: usize) {
        self.entries.swap(a, b);
    }

    /// Keeps the first `len` entries. (What only the dropped entries used stays until
    /// [`MaterialTable::shrink_to_fit`].)
    pub fn truncate(&mut self, len: usize) {
        self.entries.truncate(len);
    }

    /// Room for `more` entries, if it can be had (a hint: asked for without aborting).
    pub fn try_reserve(&mut self, more: usize) {
        let _ = self.entries.try_reserve_exact(more);
    }

    /// Frees spare capacity, wide entries no entry uses any more, and the search aids (the
    /// table is complete; a later push rebuilds them).
    pub fn shrink_to_fit(&mut self) {
        let used = self.entries.iter().filter(|&&e| e & PACKED == 0).count();
        if used < self.wide.len() {
            let mut kept = Vec::with_capacity(used);
            for e in self.entries.iter_mut().filter(|e| **e & PACKED == 0) {
                kept.push(self.wide[*e as usize]);
                *e = (kept.len() - 1) as u64;
            }
            self.wide = kept;
        }
        self.entries.shrink_to_fit();
        self.palette.shrink_to_fit();
        self.wide.shrink_to_fit();
        self.rest.shrink_to_fit();
        self.palette_index = None;
        self.recent = None;
        self.recent_channels = None;
    }

    pub fn iter(&self) -> impl ExactSizeIterator<Item = Material> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.entries.capacity() * size_of::<u64>()
            + self.palette.capacity() * size_of::<f64>()
            + self.palette_index.as_ref().map_or(0, |m| m.capacity() * 16)
            + self.wide.capacity() * size_of::<(DVec3, u32)>()
            + self.rest.capacity() * size_of::<Material>()
            + self.recent.as_ref().map_or(0, |_| SLOTS * size_of::<u32>())
            + self
                .recent_channels
                .as_ref()
                .map_or(0, |_| CHANNEL_SLOTS * size_of::<u32>())
    }
}

impl PartialEq for MaterialTable {
    /// Equal when the materials are, whatever records they share.
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().zip(other.iter()).all(|(a, b)| a == b)
    }
}

impl std::fmt::Debug for MaterialTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl From<Vec<Material>> for MaterialTable {
    fn from(materials: Vec<Material>) -> Self {
        materials.into_iter().collect()
    }
}

impl FromIterator<Material> for MaterialTable {
    fn from_iter<I: IntoIterator<Item = Material>>(iter: I) -> Self {
        let mut table = MaterialTable::new();
        for m in iter {
            table.push(m);
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::{same_words, MaterialTable, CHANNEL, PACKED, PACKED_RECORDS, SLOTS};
    use crate::scene::Material;
    use glam::DVec3;

    #[test]
    fn same_words_is_equality() {
        let mut rng = crate::testing::Rng::new(7);
        for _ in 0..2000 {
            let a: [u64; 12] = std::array::from_fn(|_| rng.below(4) as u64);
            let mut b = a;
            assert!(same_words(&a, &b));
            // One bit of one word (any bit, the sign bit too), or two words.
            b[rng.below(12)] ^= 1 << rng.below(64);
            if rng.below(2) == 0 {
                b[rng.below(12)] ^= 1 << rng.below(64);
            }
            assert_eq!(same_words(&a, &b), a == b, "{a:?} {b:?}");
        }
    }

    fn material(i: usize) -> Material {
        Material {
            // Every third colour 8-bit.
            diffuse: if i % 3 == 1 {
                DVec3::new((i % 256) as f64 / 255.0, 1.0, 0.0)
            } else {
                DVec3::new(i as f64 / 7.0, 0.25, -0.0)
            },
            transparency: if i % 3 == 0 { 0.5 } else { 0.0 },
            shininess: (i % 5) as f64,
            unlit: i % 11 == 0,
            ..Material::default()
        }
    }

    fn wide_entries(t: &MaterialTable) -> usize {
        t.entries.iter().filter(|&&e| e & PACKED == 0).count()
    }

    /// Every material comes back exactly, through pushes, swaps and truncation, with records
    /// shared (5 * 3 * 2 combinations of the rest: every entry packed) or not (more records
    /// than a packed entry can name: the later ones wide).
    #[test]
    fn materials_come_back_exactly() {
        for kinds in [1, 30, 3 * SLOTS] {
            let all: Vec<Material> = (0..4 * SLOTS)
                .map(|i| {
                    let mut m = material(i);
                    m.ambient_intensity = (i % kinds) as f64 * 1e-3;
                    m
                })
                .collect();
            let mut table: MaterialTable = all.iter().copied().collect();
            assert_eq!(table.len(), all.len());
            assert!(all.iter().enumerate().all(|(i, m)| table.get(i) == *m));
            if kinds == 1 {
                // Diffuse colours alone differ: 2 x 5 x 2 records of the rest.
                assert!(table.rest.len() <= 30, "{} records", table.rest.len());
                assert!(table.wide.is_empty());
            } else if kinds > PACKED_RECORDS as usize {
                assert!(wide_entries(&table) > 0);
            }
            let mut want = all.clone();
            table.swap(3, 1000);
            want.swap(3, 1000);
            table.truncate(2000);
            want.truncate(2000);
            table.shrink_to_fit();
            assert_eq!(table, MaterialTable::from(want.clone()));
            assert!(want.iter().enumerate().all(|(i, m)| table.get(i) == *m));
            // Wide entries of the truncated ones were given back.
            assert_eq!(table.wide.len(), wide_entries(&table));
            // A push after the search aids were dropped still shares and packs.
            let m = want[7];
            let i = table.push(m);
            assert_eq!(table.get(i as usize), m);
        }
    }

    /// Appending a table gives what pushing its materials one by one gives, whether they
    /// pack or not on either side (a full palette, records past the packed ones).
    #[test]
    fn append_is_push_of_each() {
        let mut rng = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        let mut material = |k: u64| Material {
            diffuse: DVec3::new((next() % k) as f64 / 7.0, -0.0, (next() % k) as f64),
            shininess: (next() % 600) as f64,
            ..Material::default()
        };
        for (k, n) in [(3, 50), (1000, 2000), (400_000, 3000)] {
            let a: Vec<Material> = (0..n).map(|_| material(k)).collect();
            let b: Vec<Material> = (0..n).map(|_| material(k)).collect();
            let mut appended: MaterialTable = a.iter().copied().collect();
            let other: MaterialTable = b.iter().copied().collect();
            appended.append(&other);
            let pushed: Vec<Material> = a.iter().chain(&b).copied().collect();
            assert_eq!(appended.len(), pushed.len());
            for (i, m) in pushed.iter().enumerate() {
                let got = appended.get(i);
                assert_eq!(format!("{got:?}"), format!("{m:?}"), "entry {i}");
            }
        }
    }

    /// Values keep their bits: f64 neighbours, -0, values past 1, NaN payloads.
    #[test]
    fn channel_values_keep_their_bits() {
        let near = (100.0f64 / 255.0).next_up();
        let cases = [
            DVec3::new(100.0 / 255.0, 0.0, 1.0),
            DVec3::new(near, 0.0, 1.0),
            DVec3::new(-0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(f64::NAN, 0.0, 1.0),
            DVec3::new(f64::from_bits(f64::NAN.to_bits() ^ 1), -0.0, 1.0),
        ];
        let table: MaterialTable = cases
            .iter()
            .map(|&c| Material {
                diffuse: c,
                ..Material::default()
            })
            .collect();
        for (i, c) in cases.iter().enumerate() {
            let got = table.get(i).diffuse;
            assert_eq!(
                got.to_array().map(f64::to_bits),
                c.to_array().map(f64::to_bits)
            );
        }
        // 0 and -0 apart, the two NaNs apart.
        assert_eq!(table.palette.len(), 8);
        assert!(table.wide.is_empty());
    }

    #[test]
    fn gas_is_seen_from_the_records() {
        let mut table: MaterialTable = (0..100).map(material).filter(|m| !m.is_gas()).collect();
        assert!(!table.may_have_gas());
        let gas = Material {
            transparency: 0.5,
            ..material(1)
        };
        table.push(gas);
        assert!(table.may_have_gas());
    }

    /// Past the palette's capacity, colours with new channel values are stored wide, and
    /// still come back exactly.
    #[test]
    fn a_full_palette_falls_back_to_wide_entries() {
        let n = CHANNEL as usize + 100;
        let colour = |i: usize| DVec3::new(i as f64 * 1e-7, 0.5, 0.25);
        let table: MaterialTable = (0..n)
            .map(|i| Material {
                diffuse: colour(i),
                ..Material::default()
            })
            .collect();
        assert_eq!(table.palette.len() as u64, CHANNEL + 1);
        assert!(table.wide.len() >= 100);
        assert!((0..n).all(|i| table.get(i).diffuse == colour(i)));
    }
}
