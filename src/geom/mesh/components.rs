//! Connected components of a face set: the particles of a merged mesh (a VTK glyph mesh holds
//! every particle in one IndexedFaceSet).

use std::ops::Range;

use glam::DVec3;
use hashbrown::HashMap;

/// One connected set of faces.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Component {
    /// Indices into the faces list, increasing.
    pub faces: Vec<u32>,
    /// The distinct valid point indices its faces use, sorted.
    pub vertices: Vec<u32>,
}

/// The connected components of `faces` (ranges in `coord_index`, as from
/// [`super::faces()`]). Two faces are connected when they share a point index or use two points
/// with bitwise-identical coordinates (exporters that copy each face's vertices). Components
/// are ordered by their first face; every face is in exactly one, a face without any valid
/// index (out of `0..points.len()`, or a range outside `coord_index`) in one of its own with
/// no vertices. Union-find over the faces plus a hash of the used points' coordinates.
/// The output stores indices as `u32` (truncated beyond 2^32 - 1 faces or points).
pub fn components(points: &[DVec3], coord_index: &[i64], faces: &[Range<usize>]) -> Vec<Component> {
    const NONE: usize = usize::MAX;
    let valid = |v: i64| (v >= 0 && (v as u64) < points.len() as u64).then_some(v as usize);
    let corners = |f: &Range<usize>| {
        coord_index
            .get(f.clone())
            .unwrap_or(&[])
            .iter()
            .filter_map(|&v| valid(v))
    };

    // `canon[i]`: the first used point index with the coordinates of point `i`.
    let mut canon = vec![NONE; points.len()];
    let mut by_bits: HashMap<[u64; 3], usize> = HashMap::new();
    for f in faces {
        for i in corners(f) {
            if canon[i] == NONE {
                let p = points[i];
                let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                canon[i] = *by_bits.entry(key).or_insert(i);
            }
        }
    }
    drop(by_bits);

    // Union-find of faces; `owner[c]`: the first face using canonical point `c`.
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    let mut size = vec![1usize; faces.len()];
    let mut owner = vec![NONE; points.len()];
    for (fi, f) in faces.iter().enumerate() {
        for i in corners(f) {
            let c = canon[i];
            if owner[c] == NONE {
                owner[c] = fi;
            } else {
                union(&mut parent, &mut size, fi, owner[c]);
            }
        }
    }
    drop(owner);

    // Number the roots by first face, then collect.
    let mut id = vec![NONE; faces.len()];
    let mut out: Vec<Component> = Vec::new();
    for (fi, face) in faces.iter().enumerate() {
        let root = find(&mut parent, fi);
        if id[root] == NONE {
            id[root] = out.len();
            out.push(Component {
                faces: Vec::new(),
                vertices: Vec::new(),
            });
        }
        let comp = &mut out[id[root]];
        comp.faces.push(fi as u32);
        comp.vertices.extend(corners(face).map(|i| i as u32));
    }
    for comp in &mut out {
        comp.vertices.sort_unstable();
        comp.vertices.dedup();
    }
    out
}

/// The root of `x`, halving the path on the way.
fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        let up = parent[parent[x]];
        parent[x] = up;
        x = up;
    }
    x
}

/// Joins the sets of `a` and `b`, the smaller under the larger.
fn union(parent: &mut [usize], size: &mut [usize], a: usize, b: usize) {
    let (mut a, mut b) = (find(parent, a), find(parent, b));
    if a == b {
        return;
    }
    if size[a] < size[b] {
        std::mem::swap(&mut a, &mut b);
    }
    parent[b] = a;
    size[a] += size[b];
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::geom::mesh::faces as face_ranges;
    use crate::geom::sphere_fit;
    use crate::testing::Rng;
    use std::f64::consts::{PI, TAU};

    /// A vtkSphereSource-like sphere: both poles and `phi - 2` rings of `theta` points (phi
    /// resolution counts the poles), triangle fans at the poles, band quads split into two
    /// triangles (or, with `split` false, kept as quads). Faces index the returned points.
    pub(crate) fn vtk_sphere(
        c: DVec3,
        r: f64,
        theta: usize,
        phi: usize,
        split: bool,
    ) -> (Vec<DVec3>, Vec<Vec<u32>>) {
        let mut pts = vec![c + r * DVec3::Z, c - r * DVec3::Z];
        for j in 1..phi - 1 {
            let ph = PI * j as f64 / (phi - 1) as f64;
            for i in 0..theta {
                let th = TAU * i as f64 / theta as f64;
                let u = DVec3::new(ph.sin() * th.cos(), ph.sin() * th.sin(), ph.cos());
                pts.push(c + r * u);
            }
        }
        let ring = |j: usize, i: usize| (2 + (j - 1) * theta + i % theta) as u32;
        let last = phi - 2;
        let mut faces = Vec::new();
        for i in 0..theta {
            faces.push(vec![0, ring(1, i), ring(1, i + 1)]);
            faces.push(vec![1, ring(last, i + 1), ring(last, i)]);
            for j in 1..last {
                let (a, b) = (ring(j, i), ring(j + 1, i));
                let (cc, d) = (ring(j + 1, i + 1), ring(j, i + 1));
                if split {
                    faces.push(vec![a, b, cc]);
                    faces.push(vec![a, cc, d]);
                } else {
                    faces.push(vec![a, b, cc, d]);
                }
            }
        }
        (pts, faces)
    }

    pub(crate) fn shuffle<T>(rng: &mut Rng, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            v.swap(i, rng.below(i + 1));
        }
    }

    struct Glyphs {
        spheres: Vec<(DVec3, f64, usize, usize)>,
        points: Vec<DVec3>,
        coord_index: Vec<i64>,
        /// The sphere of each face, in coordIndex order.
        face_sphere: Vec<usize>,
    }

    /// `n` random spheres merged into one point list and one coordIndex, points and faces
    /// in random order, the last `-1` sometimes missing.
    fn glyphs(rng: &mut Rng, n: usize) -> Glyphs {
        let mut spheres = Vec::new();
        let mut all_pts = Vec::new();
        let mut all_faces = Vec::new();
        for s in 0..n {
            let c = DVec3::new(
                rng.range(-1e3, 1e3),
                rng.range(-1e3, 1e3),
                rng.range(-1e3, 1e3),
            );
            let r = rng.log10(-3.0, 1.0);
            let (t, p) = (3 + rng.below(30), 3 + rng.below(30));
            let (pts, faces) = vtk_sphere(c, r, t, p, rng.f() < 0.7);
            let base = all_pts.len() as u32;
            all_pts.extend(pts);
            all_faces.extend(
                faces
                    .into_iter()
                    .map(|f| (s, f.into_iter().map(|i| i + base).collect::<Vec<_>>())),
            );
            spheres.push((c, r, t, p));
        }
        // Random point order: new index of old point i is perm[i].
        let mut perm: Vec<u32> = (0..all_pts.len() as u32).collect();
        shuffle(rng, &mut perm);
        let mut points = vec![DVec3::ZERO; all_pts.len()];
        for (i, &p) in all_pts.iter().enumerate() {
            points[perm[i] as usize] = p;
        }
        shuffle(rng, &mut all_faces);
        let mut coord_index = Vec::new();
        let mut face_sphere = Vec::new();
        for (s, f) in &all_faces {
            coord_index.extend(f.iter().map(|&i| perm[i as usize] as i64));
            coord_index.push(-1);
            face_sphere.push(*s);
        }
        if rng.f() < 0.5 {
            coord_index.pop();
        }
        Glyphs {
            spheres,
            points,
            coord_index,
            face_sphere,
        }
    }

    /// The same mesh with every face given its own copies of its points.
    fn per_face_copies(g: &Glyphs) -> (Vec<DVec3>, Vec<i64>) {
        let (mut points, mut index) = (Vec::new(), Vec::new());
        for f in face_ranges(&g.coord_index) {
            for &i in &g.coord_index[f] {
                index.push(points.len() as i64);
                points.push(g.points[i as usize]);
            }
            index.push(-1);
        }
        (points, index)
    }

    /// `components` partitions the faces exactly as generated, and each component's fit is
    /// its generating sphere (required for theta >= 8 and phi >= 6). Returns how many fitted.
    fn check(g: &Glyphs, points: &[DVec3], index: &[i64]) -> usize {
        let faces = face_ranges(index);
        assert_eq!(faces.len(), g.face_sphere.len());
        let comps = components(points, index, &faces);
        assert_eq!(comps.len(), g.spheres.len());
        let mut seen = vec![false; g.spheres.len()];
        let mut fitted = 0;
        for (k, comp) in comps.iter().enumerate() {
            let s = g.face_sphere[comp.faces[0] as usize];
            assert!(!seen[s], "sphere {s} split");
            seen[s] = true;
            assert!(comp.faces.iter().all(|&f| g.face_sphere[f as usize] == s));
            let want = g.face_sphere.iter().filter(|&&t| t == s).count();
            assert_eq!(comp.faces.len(), want);
            if k > 0 {
                assert!(comps[k - 1].faces[0] < comp.faces[0], "order by first face");
            }
            assert!(comp.vertices.windows(2).all(|w| w[0] < w[1]));
            let mut used: Vec<u32> = comp
                .faces
                .iter()
                .flat_map(|&f| index[faces[f as usize].clone()].iter().map(|&i| i as u32))
                .collect();
            used.sort_unstable();
            used.dedup();
            assert_eq!(used, comp.vertices);

            let (c, r, t, p) = g.spheres[s];
            let pts: Vec<DVec3> = comp.vertices.iter().map(|&i| points[i as usize]).collect();
            match sphere_fit(&pts) {
                Some((c2, r2)) => {
                    fitted += 1;
                    assert!(
                        (c2 - c).length() <= 1e-9 * r,
                        "{t}x{p}: {c2} vs {c} (r {r})"
                    );
                    assert!((r2 - r).abs() <= 1e-9 * r, "{t}x{p}: {r2} vs {r}");
                }
                None => assert!(t < 8 || p < 6, "{t}x{p} rejected"),
            }
        }
        fitted
    }

    #[test]
    fn merged_glyph_mesh_splits_into_its_spheres() {
        let mut rng = Rng::new(0x61f3);
        for _ in 0..3 {
            let g = glyphs(&mut rng, 200);
            let fitted = check(&g, &g.points, &g.coord_index);
            assert!(fitted > 140, "{fitted}");
            let (points, index) = per_face_copies(&g);
            assert_eq!(check(&g, &points, &index), fitted);
        }
    }

    #[test]
    fn shared_indices_and_coordinates_connect() {
        let p = |x: f64| DVec3::new(x, 0.0, 0.0);
        // Points 3 and 4 share coordinates; 5 is -0.0 vs 0.0 (different bits).
        let points = [p(0.0), p(1.0), p(2.0), p(3.0), p(3.0), p(-0.0), p(7.0)];
        let index = [0, 1, -1, 2, 3, -1, 4, 6, -1, 5, -1, 1, 2, -1, 9, -7, -1, 6];
        let faces = face_ranges(&index);
        let comps = components(&points, &index, &faces);
        let got: Vec<(Vec<u32>, Vec<u32>)> =
            comps.into_iter().map(|c| (c.faces, c.vertices)).collect();
        assert_eq!(
            got,
            vec![
                (vec![0, 1, 2, 4, 6], vec![0, 1, 2, 3, 4, 6]),
                (vec![3], vec![5]),
                (vec![5], vec![]),
            ]
        );
    }

    #[test]
    fn bad_input_does_not_panic() {
        assert!(components(&[], &[], &[]).is_empty());
        let points = [DVec3::NAN, DVec3::NAN, DVec3::INFINITY];
        let index = [0, 1, -1, 2, 99, -1];
        let c = components(&points, &index, &[0..2, 3..5, 4..100, 7..9]);
        // Faces out of `coord_index` or without a valid index stand alone, vertex-less.
        assert_eq!(c.len(), 4);
        assert_eq!(c[0].vertices, vec![0, 1]);
        assert_eq!(c[1].vertices, vec![2]);
        assert!(c[2].vertices.is_empty() && c[3].vertices.is_empty());
    }
}
