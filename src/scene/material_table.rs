//! The scene's materials, stored compactly: a file with a colour per sphere has about as many
//! distinct materials as spheres, and a 104-byte [`Material`] each would be most of a large
//! scene's memory (issue 16). Materials that differ only in their diffuse colour, the usual
//! case (VMD, OVITO and `convert` write one Material per colour), share one stored record of
//! everything else; an entry is then its diffuse colour and the index of that record. A
//! colour whose channels are all `k / 255` (8-bit colours, as particle tables give and
//! `convert` writes) is stored as those three bytes, so such an entry is 8 bytes; any other
//! colour takes a slot of 24 bytes in a colour list. Every value is kept exactly as given:
//! [`MaterialTable::get`] returns the very `Material` that was pushed (a channel is taken as
//! 8-bit only when `k as f64 / 255.0` is bit for bit the value).

use glam::DVec3;

use super::Material;

/// Slots of the direct-mapped cache that finds a stored record equal to a new one.
const SLOTS: usize = 1024;

/// Tags an 8-bit colour in `MaterialTable::diffuse`.
const BYTES: u32 = 1 << 31;

/// `c` as `BYTES | r g b` when every channel is exactly `k / 255` for a byte `k`.
fn as_bytes(c: DVec3) -> Option<u32> {
    let byte = |v: f64| {
        let k = (v * 255.0).round();
        let exact = (k / 255.0).to_bits() == v.to_bits();
        // (Not -0, which passes the other tests but would come back as +0.)
        ((0.0..=255.0).contains(&k) && k.is_sign_positive() && exact).then_some(k as u32)
    };
    Some(BYTES | byte(c.x)? << 16 | byte(c.y)? << 8 | byte(c.z)?)
}

fn from_bytes(e: u32) -> DVec3 {
    let channel = |k: u32| f64::from(k & 0xff) / 255.0;
    DVec3::new(channel(e >> 16), channel(e >> 8), channel(e))
}

/// The materials of a scene, indexed by `Sphere::material` and `Surface::material`.
#[derive(Clone, Default)]
pub struct MaterialTable {
    /// Each entry's diffuse colour: `BYTES | r << 16 | g << 8 | b` for an 8-bit colour,
    /// else an index into `colours`.
    diffuse: Vec<u32>,
    /// The diffuse colours that are not 8-bit.
    colours: Vec<DVec3>,
    /// Each entry's record in `rest`.
    rest_of: Vec<u32>,
    /// Everything but the diffuse colour (stored with a zero diffuse colour).
    rest: Vec<Material>,
    /// A cache from a record's content to its index in `rest` + 1 (0: empty). Only a search
    /// aid: a record it misses is stored again, which costs memory, never a wrong material.
    recent: Option<Box<[u32; SLOTS]>>,
}

/// The bits of everything but the diffuse colour.
fn rest_key(m: &Material) -> [u64; 10] {
    let k = m.key();
    [
        k[3], k[4], k[5], k[6], k[7], k[8], k[9], k[10], k[11], k[12],
    ]
}

fn slot(key: &[u64; 10]) -> usize {
    let mut h: u64 = 0;
    for &k in key {
        h = (h.rotate_left(23) ^ k).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    (h >> 40) as usize % SLOTS
}

impl MaterialTable {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn len(&self) -> usize {
        self.diffuse.len()
    }

    pub fn is_empty(&self) -> bool {
        self.diffuse.is_empty()
    }

    /// Material `i`. Panics when `i` is out of range, as indexing a `Vec` would.
    #[inline]
    pub fn get(&self, i: usize) -> Material {
        let e = self.diffuse[i];
        Material {
            diffuse: if e & BYTES != 0 {
                from_bytes(e)
            } else {
                self.colours[e as usize]
            },
            ..self.rest[self.rest_of[i] as usize]
        }
    }

    /// Appends `m` (no search for an equal material: the loader shares materials) and returns
    /// its index.
    pub fn push(&mut self, m: Material) -> u32 {
        let key = rest_key(&m);
        let s = slot(&key);
        let recent = self.recent.get_or_insert_with(|| Box::new([0; SLOTS]));
        let found = match recent[s] {
            0 => None,
            e => {
                let r = e - 1;
                (rest_key(&self.rest[r as usize]) == key).then_some(r)
            }
        };
        let r = found.unwrap_or_else(|| {
            let r = self.rest.len() as u32;
            self.rest.push(Material {
                diffuse: DVec3::ZERO,
                ..m
            });
            recent[s] = r + 1;
            r
        });
        let i = self.diffuse.len() as u32;
        let colour = as_bytes(m.diffuse).unwrap_or_else(|| {
            self.colours.push(m.diffuse);
            (self.colours.len() - 1) as u32
        });
        self.diffuse.push(colour);
        self.rest_of.push(r);
        i
    }

    /// Swaps entries `a` and `b`.
    pub fn swap(&mut self, a: usize, b: usize) {
        self.diffuse.swap(a, b);
        self.rest_of.swap(a, b);
    }

    /// Keeps the first `len` entries. (Colours of the dropped entries stay in the colour
    /// list until [`MaterialTable::shrink_to_fit`].)
    pub fn truncate(&mut self, len: usize) {
        self.diffuse.truncate(len);
        self.rest_of.truncate(len);
    }

    /// Frees spare capacity, colours no entry uses any more, and the search cache (the table
    /// is complete).
    pub fn shrink_to_fit(&mut self) {
        if self.diffuse.iter().filter(|&&e| e & BYTES == 0).count() < self.colours.len() {
            let mut kept = Vec::new();
            for e in self.diffuse.iter_mut().filter(|e| **e & BYTES == 0) {
                kept.push(self.colours[*e as usize]);
                *e = (kept.len() - 1) as u32;
            }
            self.colours = kept;
        }
        self.diffuse.shrink_to_fit();
        self.colours.shrink_to_fit();
        self.rest_of.shrink_to_fit();
        self.rest.shrink_to_fit();
        self.recent = None;
    }

    pub fn iter(&self) -> impl ExactSizeIterator<Item = Material> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        self.diffuse.capacity() * size_of::<u32>()
            + self.colours.capacity() * size_of::<DVec3>()
            + self.rest_of.capacity() * size_of::<u32>()
            + self.rest.capacity() * size_of::<Material>()
            + self.recent.as_ref().map_or(0, |_| SLOTS * size_of::<u32>())
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
        let mut table = MaterialTable::new();
        for m in materials {
            table.push(m);
        }
        table
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
    use super::{MaterialTable, SLOTS};
    use crate::scene::Material;
    use glam::DVec3;

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

    /// Every material comes back exactly, through pushes, swaps and truncation, with records
    /// shared (5 * 3 * 2 combinations of the rest) or not (more kinds than cache slots).
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
            }
            let mut want = all.clone();
            table.swap(3, 1000);
            want.swap(3, 1000);
            table.truncate(2000);
            want.truncate(2000);
            table.shrink_to_fit();
            assert_eq!(table, MaterialTable::from(want.clone()));
            assert!(want.iter().enumerate().all(|(i, m)| table.get(i) == *m));
            // Colours of the truncated entries were given back.
            assert!(table.colours.len() <= 2000 * 2 / 3 + 1);
        }
    }

    /// Only a channel that is bit for bit `k / 255` is stored as a byte: its neighbours in f64,
    /// -0, values past 1 and NaN keep their own bits.
    #[test]
    fn only_exact_bytes_are_stored_as_bytes() {
        let near = (100.0f64 / 255.0).next_up();
        let cases = [
            DVec3::new(100.0 / 255.0, 0.0, 1.0),
            DVec3::new(near, 0.0, 1.0),
            DVec3::new(-0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(f64::NAN, 0.0, 1.0),
            DVec3::new(0.5, 0.0, 1.0),
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
        // The first is bytes; the five others are not.
        assert_eq!(table.colours.len(), 5);
    }

    #[test]
    fn signed_zeros_and_nan_payloads_stay_apart() {
        let a = Material::default();
        let b = Material {
            ambient_intensity: -0.0,
            ..Material::default()
        };
        let c = Material {
            ambient_intensity: 0.0,
            ..Material::default()
        };
        let table: MaterialTable = [a, b, c].into_iter().collect();
        assert_eq!(
            table.get(1).ambient_intensity.to_bits(),
            (-0.0f64).to_bits()
        );
        assert_eq!(table.get(2).ambient_intensity.to_bits(), 0.0f64.to_bits());
    }
}
