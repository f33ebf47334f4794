//! The faces of a VRML97 `coordIndex`: runs of point indices separated by `-1` (the last face
//! may lack its `-1`).

use std::ops::Range;

/// Each face's range in `coord_index`, separators excluded, in order; empty faces (`-1 -1`, a
/// leading or trailing `-1`) are dropped. Only `-1` separates: other negative values stay in
/// their face (see [`first_bad_index`]).
pub fn faces(coord_index: &[i64]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &v) in coord_index.iter().enumerate() {
        if v == -1 {
            if i > start {
                out.push(start..i);
            }
            start = i + 1;
        }
    }
    if start < coord_index.len() {
        out.push(start..coord_index.len());
    }
    out
}

/// Position in `coord_index` of the first value that is neither `-1` nor a point index in
/// `0..points`, if any.
pub fn first_bad_index(coord_index: &[i64], points: usize) -> Option<usize> {
    coord_index
        .iter()
        .position(|&v| v != -1 && !(v >= 0 && (v as u64) < points as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separators_and_empty_faces() {
        assert_eq!(faces(&[]), Vec::<Range<usize>>::new());
        assert_eq!(faces(&[-1, -1]), Vec::<Range<usize>>::new());
        assert_eq!(faces(&[0, 1, 2, -1, 2, 3, 0]), vec![0..3, 4..7]);
        assert_eq!(faces(&[0, 1, 2, -1]), vec![0..3]);
        assert_eq!(faces(&[-1, 0, -1, -1, 1, 2, -1, -1]), vec![1..2, 4..6]);
        // -2 is a bad index, not a separator.
        assert_eq!(faces(&[0, -2, 1]), vec![0..3]);
    }

    #[test]
    fn bad_indices() {
        assert_eq!(first_bad_index(&[], 0), None);
        assert_eq!(first_bad_index(&[0, 1, 2, -1, 2], 3), None);
        assert_eq!(first_bad_index(&[0, 1, 3, -1], 3), Some(2));
        assert_eq!(first_bad_index(&[-1, -2], 3), Some(1));
        assert_eq!(first_bad_index(&[0], 0), Some(0));
        assert_eq!(first_bad_index(&[-1, i64::MAX, i64::MIN], 5), Some(1));
        assert_eq!(first_bad_index(&[-1, i64::MIN], 5), Some(1));
    }
}
