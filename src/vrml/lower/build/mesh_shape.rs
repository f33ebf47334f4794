//! What a closed IndexedFaceSet or PointSet becomes ([`MeshParts`], in its own coordinates;
//! the Shape that draws it applies its Material and the Transforms apply as to anything
//! else):
//! - **tessellated spheres**: every connected component of faces whose vertices lie on a
//!   sphere ([`crate::geom::mesh::sphere_fit`]) and whose colour is constant over it is that
//!   sphere, exactly: a Jmol atom, or one of the particles of a VTK/ParaView glyph mesh,
//!   which merges them all into one IndexedFaceSet;
//! - **triangles**: every other component, its polygons triangulated (concave ones too),
//!   `ccw` and `solid` applied, normals from the Normal node or by `creaseAngle`, colours
//!   from the Color node per vertex or per face;
//! - **particles**: the points of a PointSet, or of an IndexedFaceSet with no faces (as
//!   MeshLab writes point clouds), become spheres of radius `--point-radius`, or half the
//!   median nearest-neighbour distance of the points (said in a note).

use glam::DVec3;

use super::meshes::{Grid, MeshKind, MeshParts, MeshState, Meshes};
use super::Builder;
use crate::error::Error;
use crate::geom::mesh::{components, crease_normals, faces, first_bad_index, triangulate};
use crate::geom::sphere_fit;
use crate::scene::Triangle;
use crate::source::{Pos, SourceWindow};
use crate::vrml::lower::context::Ctx;
use crate::vrml::lower::diags::Diags;
use crate::vrml::lower::LoadOptions;

/// The colour (or normal) of the corner at position `pos` of `coord_index`, in face `face`,
/// by VRML97's rules for `colorIndex`/`colorPerVertex` (and the same for normals).
fn corner_value(
    values: &[DVec3],
    index: &[i64],
    coord_index: &[i64],
    per_vertex: bool,
    face: usize,
    pos: usize,
) -> Option<DVec3> {
    if values.is_empty() {
        return None;
    }
    let i = match (per_vertex, index.is_empty()) {
        (true, false) => *index.get(pos)?,
        (true, true) => coord_index[pos],
        (false, false) => *index.get(face)?,
        (false, true) => face as i64,
    };
    usize::try_from(i).ok().and_then(|i| values.get(i)).copied()
}

impl Builder {
    /// What mesh `m` lowers to (see the module documentation).
    pub(in crate::vrml::lower) fn mesh_parts(
        &mut self,
        cx: &mut Ctx,
        src: &SourceWindow,
        m: &MeshState,
        at: Pos,
    ) -> Result<MeshParts, Error> {
        // An Extrusion's points and faces grow as its spine times its cross-section: paid for
        // before they are made. (An ElevationGrid's come from heights in the text.)
        if let MeshKind::Extrusion(e) = &m.kind {
            let points = (e.spine.len() as u64).saturating_mul(e.cross_section.len() as u64);
            cx.spend(points.saturating_mul(2), src, at, "Extrusion")?;
        }
        let mut cx = MeshCtx {
            meshes: &self.meshes,
            opts: &cx.opts,
            diags: &mut cx.diags,
            src,
            at,
        };
        let points = cx.meshes.array(m.coord);
        // An ElevationGrid or Extrusion makes its points and faces, then is drawn as an
        // IndexedFaceSet of them; `Err` says why it cannot be.
        let mut generated = |made: Result<(Vec<DVec3>, Vec<i64>), String>| match made {
            Ok((points, coord_index)) => {
                let mut m = m.clone();
                m.coord_index = coord_index;
                faces_to_parts(&mut cx, &m, &points)
            }
            Err(why) => {
                cx.warn(format!("{}: {why}: not drawn", m.kind.name()));
                MeshParts::default()
            }
        };
        let parts = match &m.kind {
            MeshKind::ElevationGrid(g) => generated(grid_mesh(g).ok_or_else(|| {
                format!(
                    "{} heights for a {} x {} grid, or a size or spacing that is not finite",
                    g.height.len(),
                    g.x_dimension,
                    g.z_dimension
                )
            })),
            MeshKind::Extrusion(e) => {
                generated(crate::geom::mesh::extrusion_mesh(e).ok_or_else(|| {
                    "fewer than two spine or cross-section points, or points that are not finite"
                        .to_string()
                }))
            }
            k @ MeshKind::PointSet => point_cloud(&mut cx, m, points, k.name()),
            k if m.coord_index.iter().all(|&i| i == -1) => {
                point_cloud(&mut cx, m, points, k.name())
            }
            _ => faces_to_parts(&mut cx, m, points),
        };
        self.meshes.spheres += parts.mesh_spheres();
        self.meshes.point_spheres += parts.point_spheres();
        Ok(parts)
    }
}

/// An ElevationGrid's points (`x = i xSpacing`, `y = height[i + j xDimension]`,
/// `z = j zSpacing`) and its quads, row by row (`i` fastest, as its per-face colours and
/// normals are given), each `(i, j), (i, j+1), (i+1, j+1), (i+1, j)`: counter-clockwise seen
/// from +y, the side VRML97 6.18's default `ccw` faces. `None` when the heights are too few
/// or a size or spacing is not finite.
fn grid_mesh(g: &Grid) -> Option<(Vec<DVec3>, Vec<i64>)> {
    let (nx, nz) = (g.x_dimension as usize, g.z_dimension as usize);
    let n = nx.checked_mul(nz)?;
    if g.height.len() < n || !(g.x_spacing.is_finite() && g.z_spacing.is_finite()) {
        return None;
    }
    let mut points = Vec::with_capacity(n);
    for j in 0..nz {
        for i in 0..nx {
            let y = g.height[i + j * nx];
            points.push(DVec3::new(
                i as f64 * g.x_spacing,
                y,
                j as f64 * g.z_spacing,
            ));
        }
    }
    let at = |i: usize, j: usize| (i + j * nx) as i64;
    let mut index = Vec::with_capacity(5 * (nx - 1) * (nz - 1));
    for j in 0..nz - 1 {
        for i in 0..nx - 1 {
            index.extend([at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j), -1]);
        }
    }
    Some((points, index))
}

/// What the functions below read, and where they report: the arrays of the open mesh, the
/// load options, and the diagnostics at the mesh's node.
struct MeshCtx<'a> {
    meshes: &'a Meshes,
    opts: &'a LoadOptions,
    diags: &'a mut Diags,
    src: &'a SourceWindow,
    at: Pos,
}

impl MeshCtx<'_> {
    fn warn(&mut self, msg: impl Into<String>) {
        self.diags.warn(self.src, self.at, msg);
    }
    fn note(&mut self, msg: impl Into<String>) {
        self.diags.note(self.src, self.at, msg);
    }
}

/// Points as particles.
fn point_cloud(cx: &mut MeshCtx, m: &MeshState, points: &[DVec3], ty: &str) -> MeshParts {
    let colors = cx.meshes.array(m.color);
    let finite: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
    if finite.len() < points.len() {
        cx.warn(format!(
            "{ty}: {} points that are not finite are left out",
            points.len() - finite.len()
        ));
    }
    if finite.is_empty() {
        return MeshParts::default();
    }
    let radius = match cx.opts.point_radius {
        Some(r) => r,
        None => {
            let derived = crate::geom::nearest::median_nearest_distance(&finite).map(|d| 0.5 * d);
            let r = derived.unwrap_or(1.0);
            let how = if derived.is_some() {
                "half the median distance to the nearest other point"
            } else {
                "a single position: the default Sphere radius"
            };
            cx.note(format!(
                "{ty}: {} points drawn as spheres of radius {} ({how}; --point-radius sets it)",
                finite.len(),
                crate::vrml::number::format(&mut ryu::Buffer::new(), r)
            ));
            r
        }
    };
    let spheres = points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_finite())
        .map(|(i, &p)| (p, radius, colors.get(i).copied()))
        .collect();
    MeshParts {
        spheres,
        triangles: Vec::new(),
        points: true,
    }
}

/// Faces as spheres and triangles.
fn faces_to_parts(cx: &mut MeshCtx, m: &MeshState, points: &[DVec3]) -> MeshParts {
    let ci = &m.coord_index;
    let mut face_list = faces(ci);
    if let Some(k) = first_bad_index(ci, points.len()) {
        cx.warn(format!(
                "IndexedFaceSet coordIndex[{k}] = {} is not one of its {} points: the faces using it are left out",
                ci[k],
                points.len()
            ),
        );
        face_list.retain(|f| {
            ci[f.clone()]
                .iter()
                .all(|&i| i >= 0 && (i as usize) < points.len())
        });
    }
    let colors = cx.meshes.array(m.color);
    let normals = cx.meshes.array(m.normal);
    let color_of = |face: usize, pos: usize| {
        corner_value(colors, &m.color_index, ci, m.color_per_vertex, face, pos)
    };
    let mut parts = MeshParts::default();
    let comps = components(points, ci, &face_list);
    let mut rest: Vec<u32> = Vec::new();
    for c in &comps {
        let verts: Vec<DVec3> = c.vertices.iter().map(|&v| points[v as usize]).collect();
        let fit = sphere_fit(&verts);
        // The component's colour: one for all its corners, or none given.
        let mut colour: Option<Option<DVec3>> = None;
        let mut uniform = true;
        'faces: for &f in &c.faces {
            for pos in face_list[f as usize].clone() {
                let k = color_of(f as usize, pos);
                match colour {
                    None => colour = Some(k),
                    Some(prev) if prev != k => {
                        uniform = false;
                        break 'faces;
                    }
                    _ => {}
                }
            }
        }
        match fit {
            Some((centre, r)) if uniform => parts.spheres.push((centre, r, colour.flatten())),
            _ => rest.extend(c.faces.iter().copied()),
        }
    }
    if rest.is_empty() {
        return parts;
    }
    if cx.opts.spheres_only {
        cx.diags.skip("IndexedFaceSet (faces other than spheres)");
        return parts;
    }
    rest.sort_unstable();
    let polygons: Vec<Vec<u32>> = face_list
        .iter()
        .map(|f| ci[f.clone()].iter().map(|&i| i as u32).collect())
        .collect();
    // Normals by creaseAngle when the file gives none (0: flat faces, the geometric normal).
    let creased = (normals.is_empty() && m.crease_angle > 0.0).then(|| {
        let refs: Vec<&[u32]> = polygons.iter().map(Vec::as_slice).collect();
        crease_normals(points, &refs, m.crease_angle)
    });
    let mut tris = Vec::new();
    let mut short = (false, false);
    for &f in &rest {
        let f = f as usize;
        let poly = &polygons[f];
        let start = face_list[f].start;
        tris.clear();
        triangulate(points, poly, &mut tris);
        for t in &tris {
            let corner = |k: usize| t[k] as usize;
            let p = [0, 1, 2].map(|k| points[poly[corner(k)] as usize]);
            let given = |k: usize| {
                corner_value(
                    normals,
                    &m.normal_index,
                    ci,
                    m.normal_per_vertex,
                    f,
                    start + corner(k),
                )
            };
            let n = if !normals.is_empty() {
                match [given(0), given(1), given(2)] {
                    [Some(a), Some(b), Some(c)] => Some([a, b, c].map(|v| v.normalize_or_zero())),
                    _ => None,
                }
            } else {
                creased.as_ref().map(|cn| {
                    let sign = if m.ccw { 1.0 } else { -1.0 };
                    [0, 1, 2].map(|k| sign * cn[f][corner(k)])
                })
            };
            let c = [0, 1, 2].map(|k| color_of(f, start + corner(k)));
            let color = match c {
                [Some(a), Some(b), Some(c)] => Some([a, b, c]),
                _ => None,
            };
            short.0 |= !colors.is_empty() && color.is_none();
            short.1 |= !normals.is_empty() && n.is_none();
            let mut tri = Triangle {
                p,
                n,
                color,
                solid: m.solid,
            };
            if !m.ccw {
                tri.p.swap(1, 2);
                if let Some(n) = &mut tri.n {
                    n.swap(1, 2);
                }
                if let Some(c) = &mut tri.color {
                    c.swap(1, 2);
                }
            }
            parts.triangles.push(tri);
        }
    }
    for (missing, what, instead) in [
        (short.0, "colour", "the Material's colour"),
        (short.1, "normal", "the face's own normal"),
    ] {
        if missing {
            cx.warn(format!("IndexedFaceSet: some corners have no {what} (their index is past the end of the node): {instead} is used there"),
            );
        }
    }
    parts
}
