//! Box crossings by slabs (Kay and Kajiya): the line is inside the box between the last
//! entry into and the first exit from the three slabs `|x_i| <= half_i`.

use glam::DVec3;

use super::Sink;

/// Crossings of the box `|x_i| <= half_i`: entry and exit, or none.
///
/// A line parallel to a face lies inside that slab or misses the box; a line that touches
/// the box along an edge or at a corner only (entry = exit) gives none.
pub(super) fn crossings(half: DVec3, o: DVec3, d: DVec3, sink: &mut Sink) {
    if !(half.min_element() > 0.0 && half.is_finite()) {
        return;
    }
    let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
    let (mut axis_in, mut axis_out) = (0, 0);
    for i in 0..3 {
        if d[i] == 0.0 {
            if o[i].abs() > half[i] {
                return;
            }
            continue;
        }
        // One division per plane, as for the cap planes of the cylinder.
        let (a, b) = ((-half[i] - o[i]) / d[i], (half[i] - o[i]) / d[i]);
        let (lo, hi) = if d[i] > 0.0 { (a, b) } else { (b, a) };
        if lo > t_in {
            (t_in, axis_in) = (lo, i);
        }
        if hi < t_out {
            (t_out, axis_out) = (hi, i);
        }
    }
    // No NaN: finite over finite non-zero. An end at +-inf (overflow) is dropped by the sink.
    if t_in >= t_out {
        return;
    }
    // The entry face's normal is against d, the exit face's along it.
    let face = |axis: usize, sign: f64| {
        let mut n = DVec3::ZERO;
        n[axis] = sign;
        n
    };
    sink.push(t_in, |_| face(axis_in, -d[axis_in].signum()));
    sink.push(t_out, |_| face(axis_out, d[axis_out].signum()));
}
