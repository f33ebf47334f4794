//! The scene's materials, split the way particle files vary them: a sphere or a surface
//! carries its own diffuse colour (a [`Color`], eight bytes beside its centre) and the index
//! of a shared record of everything else. Exporters write a Material per particle that
//! differs from the others in its colour alone, so a file of a million particles in a
//! million colours has one record, found by comparing with the last one, and a million
//! colours, stored where the spheres are and never searched for.

use glam::DVec3;
use hashbrown::HashMap;

use super::color::{Color, Colors};
use super::Material;

/// What a drawn item refers to: a record of [`MaterialTable`] and its own diffuse colour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Paint {
    /// Index of the record (everything but the diffuse colour).
    pub material: u32,
    /// The item's own diffuse colour.
    pub color: Color,
}

/// The records of a scene's materials (each stored with a zero diffuse colour), indexed by
/// `Sphere::material` and `Surface::material`, and the colours that do not pack.
#[derive(Clone, Default)]
pub struct MaterialTable {
    records: Vec<Material>,
    colors: Colors,
    /// Where each record's bits are in `records`: a search aid built on the first miss of
    /// `last` (most files have a handful of records).
    index: Option<HashMap<[u64; 12], u32>>,
    /// The record found or stored last.
    last: u32,
}

/// The bits of everything but the diffuse colour.
fn rest_key(m: &Material) -> [u64; 12] {
    let k = m.key();
    std::array::from_fn(|i| k[i + 3])
}

impl MaterialTable {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records stored: the distinct materials apart from their diffuse colours.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    /// Whether no record is stored.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// The material of an item that refers to record `material` with colour `color`. Panics
    /// when the record is out of range, as indexing a `Vec` would.
    #[inline]
    pub fn get(&self, material: u32, color: Color) -> Material {
        Material {
            diffuse: self.colors.get(color),
            ..self.records[material as usize]
        }
    }

    /// Record `i` (its diffuse colour zero).
    #[inline]
    pub fn record(&self, i: u32) -> &Material {
        &self.records[i as usize]
    }

    /// The records, in the order they were first stored.
    pub fn records(&self) -> &[Material] {
        &self.records
    }

    /// Changes every record by `f` (its diffuse colour stays zero): what every item refers
    /// to changes with it. Records made equal stay apart.
    pub fn edit_records(&mut self, mut f: impl FnMut(&mut Material)) {
        for r in &mut self.records {
            f(r);
            r.diffuse = DVec3::ZERO;
        }
        self.index = None;
        self.last = 0;
    }

    /// The diffuse colour `color` stands for.
    #[inline]
    pub fn diffuse(&self, color: Color) -> DVec3 {
        self.colors.get(color)
    }

    /// The colours that do not pack (see [`Color`]).
    pub fn listed_colors(&self) -> &[DVec3] {
        self.colors.listed()
    }

    /// Whether `c` is a colour of this table (packed, or listed here).
    pub fn holds(&self, c: Color) -> bool {
        self.colors.holds(c)
    }

    /// The word of colour `c`.
    #[inline]
    pub(crate) fn add_color(&mut self, c: DVec3) -> Color {
        self.colors.add(c)
    }

    /// The index of the record equal to `m`'s (all but the diffuse colour), stored if new.
    #[inline]
    pub(crate) fn add_record(&mut self, m: &Material) -> u32 {
        let key = rest_key(m);
        if let Some(l) = self.records.get(self.last as usize) {
            if rest_key(l) == key {
                return self.last;
            }
        }
        self.add_record_slow(m, key)
    }

    #[cold]
    #[inline(never)]
    fn add_record_slow(&mut self, m: &Material, key: [u64; 12]) -> u32 {
        let records = &self.records;
        let index = self.index.get_or_insert_with(|| {
            records
                .iter()
                .enumerate()
                .map(|(i, r)| (rest_key(r), i as u32))
                .collect()
        });
        let next = self.records.len() as u32;
        let r = *index.entry(key).or_insert(next);
        if r == next {
            self.records.push(Material {
                diffuse: DVec3::ZERO,
                ..*m
            });
        }
        self.last = r;
        r
    }

    /// `m` as an item refers to it: its record (shared with equal ones) and its colour.
    #[inline]
    pub fn add(&mut self, m: &Material) -> Paint {
        Paint {
            material: self.add_record(m),
            color: self.add_color(m.diffuse),
        }
    }

    /// Takes in `other`'s records and listed colours; returns what `other`'s paints become
    /// here (for the tables of a file's pieces read on other threads).
    pub fn append(&mut self, other: &MaterialTable) -> impl Fn(Paint) -> Paint {
        let records: Vec<u32> = other.records.iter().map(|m| self.add_record(m)).collect();
        let color = self.colors.append(&other.colors);
        move |p| Paint {
            material: records[p.material as usize],
            color: color(p.color),
        }
    }

    /// Whether some record is gas (`Material::is_gas`, which the diffuse colour does not
    /// change): false means no item is.
    pub(crate) fn may_have_gas(&self) -> bool {
        self.records.iter().any(Material::is_gas)
    }

    /// Whether some gas record has a density profile other than constant.
    pub(crate) fn may_have_profiled_gas(&self) -> bool {
        self.records
            .iter()
            .any(|m| m.is_gas() && m.profile != super::Profile::Constant)
    }

    /// Frees spare capacity and the search aid (a later record rebuilds it).
    pub(crate) fn shrink_to_fit(&mut self) {
        self.records.shrink_to_fit();
        self.colors.shrink_to_fit();
        self.index = None;
    }

    /// Heap bytes held.
    pub fn heap_bytes(&self) -> usize {
        self.records.capacity() * std::mem::size_of::<Material>()
            + self.colors.heap_bytes()
            + self.index.as_ref().map_or(0, |m| m.capacity() * 104)
    }
}

impl PartialEq for MaterialTable {
    /// Equal records and listed colours (the search aid aside).
    fn eq(&self, other: &Self) -> bool {
        self.records == other.records && self.colors == other.colors
    }
}

impl std::fmt::Debug for MaterialTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MaterialTable")
            .field("records", &self.records)
            .field("listed colours", &self.colors.listed().len())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::MaterialTable;
    use crate::scene::Material;
    use glam::DVec3;

    fn material(i: usize) -> Material {
        Material {
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

    /// Every material comes back exactly; records are shared exactly when all but the colour
    /// is equal, in the order first met.
    #[test]
    fn materials_come_back_exactly_and_records_are_shared() {
        let all: Vec<Material> = (0..5000).map(material).collect();
        let mut table = MaterialTable::new();
        let paints: Vec<_> = all.iter().map(|m| table.add(m)).collect();
        for (m, p) in all.iter().zip(&paints) {
            let got = table.get(p.material, p.color);
            assert_eq!(format!("{got:?}"), format!("{m:?}"));
        }
        // Records: transparency (2) x shininess (5) x unlit (2) combinations at most, and
        // two materials share a record exactly when their rests are equal.
        assert!(table.len() <= 20, "{} records", table.len());
        for (i, a) in all.iter().enumerate().step_by(7) {
            for (j, b) in all.iter().enumerate().step_by(13) {
                let same = Material {
                    diffuse: b.diffuse,
                    ..*a
                } == *b;
                assert_eq!(paints[i].material == paints[j].material, same, "{i} {j}");
            }
        }
        // First met, first stored.
        assert_eq!(paints[0].material, 0);
        assert!(paints
            .iter()
            .scan(0, |seen, p| {
                let new = p.material <= *seen + 1;
                *seen = (*seen).max(p.material);
                Some(new)
            })
            .all(|ok| ok));
    }

    /// Appending a table gives what adding its materials one by one gives.
    #[test]
    fn append_is_add_of_each() {
        let a: Vec<Material> = (0..300).map(material).collect();
        let b: Vec<Material> = (300..700).map(material).collect();
        let mut whole = MaterialTable::new();
        let mut want: Vec<_> = a.iter().chain(&b).map(|m| whole.add(m)).collect();
        let mut first = MaterialTable::new();
        let mut got: Vec<_> = a.iter().map(|m| first.add(m)).collect();
        let mut second = MaterialTable::new();
        let moved: Vec<_> = b.iter().map(|m| second.add(m)).collect();
        let to_first = first.append(&second);
        got.extend(moved.into_iter().map(to_first));
        assert_eq!(first, whole);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter_mut().zip(&mut want) {
            assert_eq!(
                first.get(g.material, g.color),
                whole.get(w.material, w.color)
            );
            assert_eq!(g, w);
        }
    }

    #[test]
    fn gas_is_seen_from_the_records() {
        let mut table = MaterialTable::new();
        for m in (0..100).map(material).filter(|m| !m.is_gas()) {
            table.add(&m);
        }
        assert!(!table.may_have_gas());
        table.add(&Material {
            transparency: 0.5,
            ..material(1)
        });
        assert!(table.may_have_gas());
    }
}
