//! A diffuse colour in eight bytes, kept exactly: what a sphere carries beside its centre and
//! radius, so that a million particles of a million colours cost a million words and no
//! search for equal materials.
//!
//! Colours read from text are decimals. A value written with at most six decimals (or all
//! three with seven, below 0.105) is `m / 10^k` for an integer `m < 2^20` and `k <= 7`, and
//! the division of the two (both exact in f64) is correctly rounded: it gives the very bits
//! that reading the text gave. Colours of 8 or 16 bits written in full (`0.403921568627451`,
//! the f64 nearest to 103/255, as `gtsphere convert` and Python's `repr` write them) are
//! `m / 255` or `m / 65535` the same way. A divisor code of 4 bits and three 20-bit `m`s
//! fill the word. Every colour is packed only after its decoding was checked to give back
//! its bits (so `-0.0`, NaN and the values of binary arithmetic, as numpy arrays carry them,
//! are never changed): a colour that does not pack is stored once in [`Colors`]' side list
//! and the word holds its index.
//!
//! Measured 2026-12-05 on 1e7 particles with a 6-decimal colour each (`bench parse`'s
//! `continuous` file, two cores): every colour packs; against a table of whole materials
//! (32 bytes each, shared by hashing) `gtsphere info` reads the file in 1.7-2.0 s instead of
//! 3.6-3.9 s at a peak of 607 MB instead of 1.09 GB, and `render` at 512 x 512 peaks at
//! 0.89-0.96 GB instead of 1.22 GB, with the same pictures bit for bit.

use glam::DVec3;
use hashbrown::HashMap;

/// A diffuse colour: three channels packed as `m / divisor`, or an index into [`Colors`].
/// The default is black.
#[derive(Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Color(u64);

const CHANNEL_BITS: u32 = 20;
const CHANNEL: u64 = (1 << CHANNEL_BITS) - 1;
/// Where the divisor's code is.
const CODE_SHIFT: u32 = 3 * CHANNEL_BITS;
/// The divisor of each code (`10^k` for code `k < 8`).
const DIVISORS: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 255.0, 65535.0];
/// The code of an index into [`Colors`]' side list.
const LISTED: u64 = 15;
/// The codes tried, the common ones first (any value of at most six decimals below 1.048576
/// packs with 6).
const TRIED: [u64; 10] = [6, 8, 7, 3, 5, 4, 2, 1, 0, 9];

impl Color {
    /// Its packed word: equal colours of one table, equal words.
    pub(crate) fn to_bits(self) -> u64 {
        self.0
    }

    fn listed(index: usize) -> Color {
        Color(LISTED << CODE_SHIFT | index as u64)
    }

    /// Its index in the side list, if it is listed.
    #[inline]
    fn index(self) -> Option<usize> {
        (self.0 >> CODE_SHIFT == LISTED).then_some((self.0 & ((1 << CODE_SHIFT) - 1)) as usize)
    }

    /// The packed word of `c`, if every channel is `m / divisor` (one divisor) exactly.
    fn pack(c: DVec3) -> Option<Color> {
        let channels = c.to_array();
        'k: for k in TRIED {
            let p = DIVISORS[k as usize];
            let mut word = k << CODE_SHIFT;
            for (i, v) in channels.into_iter().enumerate() {
                let m = (v * p).round();
                // (Decoded from the integer: -0.0 would round to -0.0 and come back as 0.)
                let fits = m >= 0.0 && m <= CHANNEL as f64;
                if !fits || ((m as u64) as f64 / p).to_bits() != v.to_bits() {
                    if i == 0 && !(0.0..1e7).contains(&v) {
                        return None;
                    }
                    continue 'k;
                }
                word |= (m as u64) << (CHANNEL_BITS * (2 - i as u32));
            }
            return Some(Color(word));
        }
        None
    }

    /// A packed colour's channels (`None`: a listed one).
    #[inline]
    fn unpack(self) -> Option<DVec3> {
        let &p = DIVISORS.get((self.0 >> CODE_SHIFT) as usize)?;
        let m = |i: u32| ((self.0 >> (CHANNEL_BITS * (2 - i))) & CHANNEL) as f64 / p;
        Some(DVec3::new(m(0), m(1), m(2)))
    }
}

impl std::fmt::Debug for Color {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.unpack() {
            Some(c) => write!(f, "Color({} {} {})", c.x, c.y, c.z),
            None => write!(f, "Color(listed {:?})", self.index()),
        }
    }
}

/// The colours that do not pack, which [`Color`] words index, each listed once.
#[derive(Clone, Debug, Default)]
pub struct Colors {
    listed: Vec<DVec3>,
    /// Where each listed colour's bits are: a search aid, dropped by `shrink_to_fit` and
    /// built again when needed.
    index: Option<HashMap<[u64; 3], u32>>,
}

impl PartialEq for Colors {
    fn eq(&self, other: &Self) -> bool {
        let bits = |c: &DVec3| c.to_array().map(f64::to_bits);
        self.listed.len() == other.listed.len()
            && self
                .listed
                .iter()
                .zip(&other.listed)
                .all(|(a, b)| bits(a) == bits(b))
    }
}

impl Colors {
    /// The word of `c`: packed, or its place in the list (added if new).
    #[inline]
    pub fn add(&mut self, c: DVec3) -> Color {
        Color::pack(c).unwrap_or_else(|| self.list(c))
    }

    #[cold]
    fn list(&mut self, c: DVec3) -> Color {
        let listed = &self.listed;
        let index = self.index.get_or_insert_with(|| {
            (listed.iter().enumerate())
                .map(|(i, c)| (c.to_array().map(f64::to_bits), i as u32))
                .collect()
        });
        let next = listed.len() as u32;
        let i = *index.entry(c.to_array().map(f64::to_bits)).or_insert(next);
        if i == next {
            self.listed.push(c);
        }
        Color::listed(i as usize)
    }

    /// The colour of `c`, bit for bit as it was added.
    #[inline]
    pub fn get(&self, c: Color) -> DVec3 {
        c.unpack()
            .unwrap_or_else(|| self.listed[c.index().unwrap_or(usize::MAX)])
    }

    /// Whether `c` is packed or listed here.
    pub fn holds(&self, c: Color) -> bool {
        match c.index() {
            Some(i) => i < self.listed.len(),
            None => c.unpack().is_some(),
        }
    }

    /// Takes in `other`'s list; returns what `other`'s words become here.
    pub fn append(&mut self, other: &Colors) -> impl Fn(Color) -> Color {
        let moved: Vec<Color> = other.listed.iter().map(|&c| self.list(c)).collect();
        move |c| match c.index() {
            Some(i) => moved[i],
            None => c,
        }
    }

    /// The colours in the list.
    pub fn listed(&self) -> &[DVec3] {
        &self.listed
    }

    /// Frees unused list capacity and the lookup index; adding colours after this rebuilds the
    /// index.
    pub(crate) fn shrink_to_fit(&mut self) {
        self.listed.shrink_to_fit();
        self.index = None;
    }

    /// Bytes it holds on the heap, the lookup index's estimated at 32 bytes an entry.
    pub fn heap_bytes(&self) -> usize {
        self.listed.capacity() * std::mem::size_of::<DVec3>()
            + self.index.as_ref().map_or(0, |m| m.capacity() * 32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(c: DVec3) -> (bool, DVec3) {
        let mut colors = Colors::default();
        let w = colors.add(c);
        (colors.listed().is_empty(), colors.get(w))
    }

    fn same(a: DVec3, b: DVec3) -> bool {
        a.to_array()
            .iter()
            .zip(b.to_array())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    }

    #[test]
    fn decimals_as_text_gives_them_pack_and_come_back_exactly() {
        // Values as a reader gets them from text, against the text itself.
        for text in [
            "0 0 0",
            "1 1 1",
            "0.5 0.25 0.125",
            "0.123456 0.654321 0.999999",
            "0.0123457 0.0456789 0.1",
            "0.502 0.8 0.996",
            "1.048575 0 1",
            "0.0000001 0.0000009 0.1048575",
        ] {
            let v: Vec<f64> = text.split(' ').map(|t| t.parse().unwrap()).collect();
            let c = DVec3::new(v[0], v[1], v[2]);
            let (packed, back) = round_trip(c);
            assert!(packed, "{text} should pack");
            assert!(same(back, c), "{text}: {back:?}");
        }
        // Every 8-bit channel value as a /255 quotient printed with six and three decimals.
        for i in 0..=255u32 {
            let text = |x: u32, digits: usize| -> f64 {
                format!("{:.*}", digits, f64::from(x) / 255.0)
                    .parse()
                    .unwrap()
            };
            let c = DVec3::new(text(i, 6), text(255 - i, 6), text(i, 3));
            let (packed, back) = round_trip(c);
            assert!(packed, "{c:?}");
            assert!(same(back, c));
        }
        // 8- and 16-bit colours written in full (shortest round trip), as convert and
        // Python's repr write them.
        for (i, d) in [(0u32, 255u32), (1, 255), (103, 255), (254, 255), (255, 255)]
            .into_iter()
            .chain((0..65535).step_by(257).map(|i| (i, 65535)))
        {
            let text =
                |x: u32| -> f64 { format!("{}", f64::from(x) / f64::from(d)).parse().unwrap() };
            let c = DVec3::new(text(i), text(d - i), text(d / 3));
            let (packed, back) = round_trip(c);
            assert!(packed, "{c:?}");
            assert!(same(back, c));
        }
    }

    #[test]
    fn other_values_are_listed_and_kept_by_their_bits() {
        for c in [
            DVec3::new(1.0 / 11.0, 0.5, 0.5),
            DVec3::new(0.5, 0.1 + 0.2, 0.5),
            DVec3::new(-0.0, 0.0, 0.0),
            DVec3::new(0.0, -0.5, 0.0),
            DVec3::new(f64::NAN, 0.0, 0.0),
            DVec3::new(0.0, 0.0, f64::INFINITY),
            DVec3::new(2.5e7, 0.0, 0.0),
            DVec3::new(0.12345678, 0.0, 0.0),
            DVec3::new(1e-300, 0.0, 0.0),
        ] {
            let (packed, back) = round_trip(c);
            assert!(!packed, "{c:?} should be listed");
            assert!(same(back, c), "{c:?}: {back:?}");
        }
    }

    #[test]
    fn appended_lists_keep_every_colour_once() {
        let third = DVec3::splat(1.0 / 11.0);
        let seventh = DVec3::splat(1.0 / 7.0);
        let mut a = Colors::default();
        let mut b = Colors::default();
        let wa = [a.add(third), a.add(DVec3::splat(0.5)), a.add(third)];
        assert_eq!(wa[0], wa[2]);
        let wb = [b.add(seventh), b.add(DVec3::splat(0.25)), b.add(third)];
        let moved = a.append(&b);
        assert!(same(a.get(wa[0]), third));
        assert!(same(a.get(wa[1]), DVec3::splat(0.5)));
        assert!(same(a.get(moved(wb[0])), seventh));
        assert!(same(a.get(moved(wb[1])), DVec3::splat(0.25)));
        assert_eq!(moved(wb[2]), wa[0]);
        // What adding each of the second list's colours after the first gives.
        let mut whole = Colors::default();
        for c in [
            third,
            DVec3::splat(0.5),
            third,
            seventh,
            DVec3::splat(0.25),
            third,
        ] {
            whole.add(c);
        }
        assert_eq!(a, whole);
        assert_eq!(a.listed().len(), 2);
    }
}
