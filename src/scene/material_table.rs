//! The scene's materials, stored compactly: a file with a colour per sphere has about as many
//! distinct materials as spheres, and a 104-byte [`Material`] each would be most of a large
//! scene's memory (issue 16). Materials that differ only in their diffuse colour, the usual
//! case (VMD, OVITO and `convert` write one Material per colour), share one stored record of
//! everything else; an entry is then its diffuse colour and the index of that record, 28
//! bytes. Every value is kept exactly as given: [`MaterialTable::get`] returns the very
//! `Material` that was pushed.

use glam::DVec3;

use super::Material;

/// Slots of the direct-mapped cache that finds a stored record equal to a new one.
const SLOTS: usize = 1024;

/// The materials of a scene, indexed by `Sphere::material` and `Surface::material`.
#[derive(Clone, Default)]
pub struct MaterialTable {
    /// Each entry's diffuse colour.
    diffuse: Vec<DVec3>,
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
        Material {
            diffuse: self.diffuse[i],
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
        self.diffuse.push(m.diffuse);
        self.rest_of.push(r);
        i
    }

    /// Swaps entries `a` and `b`.
    pub fn swap(&mut self, a: usize, b: usize) {
        self.diffuse.swap(a, b);
        self.rest_of.swap(a, b);
    }

    /// Keeps the first `len` entries.
    pub fn truncate(&mut self, len: usize) {
        self.diffuse.truncate(len);
        self.rest_of.truncate(len);
    }

    /// Frees spare capacity, and the search cache (the table is complete).
    pub fn shrink_to_fit(&mut self) {
        self.diffuse.shrink_to_fit();
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
        self.diffuse.capacity() * size_of::<DVec3>()
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
            diffuse: DVec3::new(i as f64 / 7.0, 0.25, -0.0),
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
        }
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
