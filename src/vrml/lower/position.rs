//! Positions in the files read for their PROTOs: a position recorded from such a file is
//! *tagged* with the file's index in `Scene::files` in its top bits, as
//! [`crate::scene::Origin`] packs them, so that messages and IR items made when its PROTOs
//! are expanded point into that file (see `extern_proto`).

/// How many low bits of a position are its byte offset; the bits above say which file read
/// for its PROTOs it is in (0: the file being read). The layout of [`crate::scene::Origin`].
const OFFSET_BITS: u32 = 44;
const OFFSET_MASK: u64 = (1 << OFFSET_BITS) - 1;
const MAX_TAG: u32 = (1 << (64 - OFFSET_BITS)) - 1;

/// Position `at` of file `file` (its index in `Scene::files`, never 0), tagged with that
/// file; a position already tagged keeps its file (it came from yet another file).
pub(super) fn tag(at: u64, file: u32) -> u64 {
    if tag_of(at).is_some() {
        return at;
    }
    u64::from(file.min(MAX_TAG)) << OFFSET_BITS | at.min(OFFSET_MASK)
}

/// The file a tagged position is in (its index in `Scene::files`); `None`: the file being read.
#[inline(always)]
pub(super) fn tag_of(at: u64) -> Option<u32> {
    let file = (at >> OFFSET_BITS) as u32;
    (file != 0).then_some(file)
}

/// The byte offset of a position in its file, tagged or not.
#[inline(always)]
pub(super) fn offset_of(at: u64) -> u64 {
    at & OFFSET_MASK
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Origin;

    #[test]
    fn tagged_positions_have_the_layout_of_origins() {
        for (file, offset) in [(1, 0), (3, 123_456_789), (MAX_TAG, OFFSET_MASK)] {
            let at = tag(offset, file);
            assert_eq!((tag_of(at), offset_of(at)), (Some(file), offset));
            let o = Origin::new(file, offset);
            assert_eq!((o.file(), o.offset()), (file, offset));
        }
        // Untagged positions are in the file being read; a tag is not replaced.
        assert_eq!(tag_of(12), None);
        assert_eq!(tag_of(tag(tag(5, 2), 7)), Some(2));
    }
}
