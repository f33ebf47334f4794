//! Hand-counted expectations for corpus files (see the comment on each entry for how it was counted).
//!
//! Every number below was derived by reading the VRML text (grep counts, reading the
//! files, and a throwaway Python walker/mesh analyser kept in /tmp, written independently of
//! gtsphere, to double-check the sums); no gtsphere code was run. Counting rules: see the task
//! brief (a renderer's walk of the scene graph: USE = another instance, PROTO instances
//! expanded to their first body node, Switch -> whichChoice only, Collision proxy / LOD levels
//! past the first not walked, local relative Inlines walked, unmodelled nodes go to `skipped`, nodes
//! inside an Appearance other than Material go to `skipped`).
//!
//! Geometry of a Shape: `Sphere` -> a sphere; `Box`, `Cylinder`, `Cone` -> one surface of
//! that kind per instance; `PointSet` -> one sphere per point; `IndexedFaceSet` -> its faces
//! (coordIndex split at -1, faces with an out-of-range index dropped) grouped into connected
//! components (shared point index or bit-identical point); a component whose distinct
//! vertices (>= 12) lie on a sphere (within 0.2 % of the radius, covering the whole sphere)
//! with one colour at every corner is one sphere, any other component gives n - 2 triangles
//! per n-gon (0 for a zero-area face); an IFS with points but no faces gives one sphere per
//! point; an IFS without points or with non-integer indices stays skipped. ElevationGrid and
//! Extrusion give their quads (and an Extrusion's caps) as faces. Other geometry
//! (IndexedLineSet, Text, ...) and IFS/PointSet outside a Shape go to `skipped`.

mod conformance;
use conformance::CONFORMANCE;

/// Every hand-counted file.
pub fn expected() -> impl Iterator<Item = &'static Expected> {
    TOOLS.iter().chain(CONFORMANCE)
}

pub struct Expected {
    pub path: &'static str, // relative to shared/corpus
    pub spheres: usize,     // all sphere instances (opaque + gas)
    pub gas: usize,         // of which gas (Material transparency > 0)
    pub point_lights: usize,
    pub directional_lights: usize,
    pub viewpoints: usize,
    pub boxes: usize,                              // Box surfaces
    pub cylinders: usize,                          // Cylinder surfaces
    pub cones: usize,                              // Cone surfaces
    pub triangles: usize, // triangles from IndexedFaceSet components that are not spheres
    pub skipped: &'static [(&'static str, usize)], // node type -> instance count, sorted by type name
}

/// The tools' exports (see `conformance` for the conformance suites' files).
pub const TOOLS: &[Expected] = &[
    // ------------------------------------------------------------------ tools/jmol
    // Jmol writes spheres as a unit-sphere IndexedFaceSet, never as `Sphere`; gtsphere lowers
    // an IFS component whose vertices lie on a sphere as that sphere.
    // WorldInfo, NavigationInfo, Background, Viewpoint at top level; then
    // Transform{Transform{ 1217 x Transform{Shape{...}} }}.
    // Geometry DEF/USE multiplies: `geometry DEF _0 IndexedFaceSet` once + 643 `geometry USE _0`
    // (atoms) = 644, `DEF _6` once + 485 `USE _6` = 486, `DEF _7` once + 86 `USE _7` = 87
    // (bonds) -> 644 + 486 + 87 = 1217 IFS instances = 1217 `Shape{`.
    // _0 is the unit sphere (162 points, `grep -c 'USE _0'` = 643, so 644 spheres: 324 atoms,
    // scales .35/.356/.391/.253/.414 = 29+29+107+157+2, plus 320 bond-end caps at scale
    // .152, counted with `grep -o 'scale [0-9.]* [0-9.]* [0-9.]* children\[ Shape{geometry
    // [A-Z]* _0' | sort | uniq -c`). _6 and _7 are Jmol's bond cylinders (`1 .5 0`, `.985 .5
    // .174`, ...: two rims at y = +-0.5, equidistant from the centre but covering only two
    // circles, not the whole sphere) -> triangles. Both have 74 points and 144 faces, all
    // triangles (`coordIndex` runs of 3 between -1s, counted by the /tmp script; one connected
    // component each, no zero-area face): (486 + 87) x 144 = 573 x 144 = 82512 triangles; no
    // IFS left skipped.
    // The 5 Appearances (DEF _1.._5, USEd 1212 times) hold only Materials with transparency 0.
    Expected {
        path: "tools/jmol/jmol_peptide20_ballstick.wrl",
        spheres: 644,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 82512,
        skipped: &[("WorldInfo", 1)],
    },
    // 20 `Shape{` each with its own inline `geometry IndexedFaceSet` (no geometry DEF/USE;
    // only the 2 Appearances DEF _0/_1 are reused 18 times). WorldInfo 1, Viewpoint 1.
    // The IFS are cartoon ribbons (one connected component each, no Color node; the sphere fit
    // misses by 25-83 % of the radius), so all become triangles. Every face is a triangle
    // (/tmp script: coordIndex split at -1, run lengths all 3); faces per IFS in file order:
    // 248, 236, 16 x 224, 236, 248 = 4552. The 19th IFS (arrow head, 140 points) repeats its
    // tip point `23.398 8.251 -17.083` as points 112..125, so 14 of its faces
    // (`98 113 112`, `99 114 113`, ... `98 112 125`) have two bit-identical corners: zero
    // area, 0 triangles -> 4552 - 14 = 4538. No other face of the file has a zero or
    // near-zero area (checked: area / longest edge^2 >= 1e-3 elsewhere).
    Expected {
        path: "tools/jmol/jmol_peptide20_cartoon.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 4538,
        skipped: &[("WorldInfo", 1)],
    },
    // 324 atoms: `geometry DEF _0 IndexedFaceSet` once + 323 `geometry USE _0` (`grep -c
    // 'USE _0'` = 323) = 324 IFS instances (= 324 `Shape{`), all of the one unit-sphere mesh
    // (162 points, every one at distance 1 +- 5.2e-4 from the origin): 324 spheres, no IFS
    // left skipped. All 5 Materials transparency 0. WorldInfo 1, Viewpoint 1.
    Expected {
        path: "tools/jmol/jmol_peptide20_spacefill.wrl",
        spheres: 324,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("WorldInfo", 1)],
    },
    // ------------------------------------------------------------------ tools/meshlab
    // NavigationInfo + Transform{Shape{geometry IndexedFaceSet (empty `coordIndex [ ]`)}}; no
    // Viewpoint, no lights, no DEF/USE. An IFS with points but no faces -> one sphere per
    // point: `point [...]` holds 1500 numbers = 500 points (all finite), so 500 spheres. The
    // Shape's Material has no transparency (`grep -c transparency` = 0) -> 0 gas. The Color
    // node (500 colours) does not change the count.
    Expected {
        path: "tools/meshlab/meshlab_pointcloud500.wrl",
        spheres: 500,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // NavigationInfo + Transform{Shape{geometry IndexedFaceSet}}: a sphere mesh (pymeshlab
    // `create_sphere(radius=1.0, subdiv=2)`, an icosphere: 162 points on the unit sphere, all
    // used by the 320 faces), lowered as one sphere.
    Expected {
        path: "tools/meshlab/meshlab_sphere_subdiv2.wrl",
        spheres: 1,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // Same as subdiv2 plus a Color node inside the IFS (not walked). The colours differ from
    // corner to corner (per-vertex, no colorIndex: 162 different colour triples over the 162
    // points), so the one component is not a sphere: its 320 faces are all triangles (every
    // coordIndex run has 3 entries) -> 320 triangles; no IFS left skipped.
    Expected {
        path: "tools/meshlab/meshlab_sphere_vertexcolor.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 0,
        viewpoints: 0,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 320,
        skipped: &[],
    },
    // ------------------------------------------------------------------ tools/pymol
    // `grep -c Sphere` = 744 = `Shape {` = `Transform {` = `Material {` count; each top-level
    // Transform holds one Shape with `geometry Sphere`; no DEF/USE, no `transparency`.
    // Header: Viewpoint 1, DirectionalLight 1, NavigationInfo 1.
    Expected {
        path: "tools/pymol/pymol_helix60_spheres.wrl",
        spheres: 744,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // 958 top-level Transforms/Shapes: `grep -c Sphere` = 324, `Cylinder {` = 634
    // (324 + 634 = 958); no DEF/USE, no transparency. Viewpoint 1, DirectionalLight 1.
    // The 634 Cylinders (bonds) are now Cylinder surfaces; nothing skipped.
    Expected {
        path: "tools/pymol/pymol_peptide20_ballstick.wrl",
        spheres: 324,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 634,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // One top-level Shape with an IndexedFaceSet (cartoon mesh). Viewpoint 1, DirectionalLight 1.
    // The IFS has 4824 points (3 per face, shared only through bit-identical coordinates:
    // 806 distinct) and 1608 coordIndex runs, all of length 3; the /tmp script finds one
    // connected component, one colour (`0.2000 1.0000 0.2000` at every corner) but far from a
    // sphere (fit misses by 98 % of the radius) -> 1608 triangles, none of zero area.
    Expected {
        path: "tools/pymol/pymol_peptide20_cartoon.wrl",
        spheres: 0,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 1608,
        skipped: &[],
    },
    // `grep -c Sphere` = 324 = `Shape {` = `Transform {`; no DEF/USE, no transparency.
    Expected {
        path: "tools/pymol/pymol_peptide20_spheres.wrl",
        spheres: 324,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // `grep -c Sphere` = 12960 = `Shape {` = `Transform {` = `Material {` (12,960 atoms);
    // no DEF/USE, no transparency.
    Expected {
        path: "tools/pymol/pymol_peptide800_spheres.wrl",
        spheres: 12960,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // `grep -c Sphere` = 200 = `Shape {` = `Transform {` (200 pseudoatoms); no transparency.
    Expected {
        path: "tools/pymol/pymol_pseudoatom_cloud200.wrl",
        spheres: 200,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // ------------------------------------------------------------------ tools/vtk
    // VTK tessellates spheres: 5 top-level Transforms each with Shape{IndexedFaceSet}
    // (`grep -c 'geometry IndexedFaceSet'` = 5), each a vtkSphereSource (theta 16, phi 12:
    // a UV sphere, every point on it, no Color node) -> lowered as 5 spheres; the MANIFEST
    // recipe scales four of them by (1, 1 + 0.2 i, 1), which makes ellipsoids. One Material
    // has transparency 0.5 (`grep -c 'transparency 0.5'` = 1) -> 1 gas.
    // Header: Background, Viewpoint 1, NavigationInfo, DirectionalLight 1 (ambient),
    // SpotLight 1 (the positional vtkLight) -> skipped. DEF VTKcoordinates/VTKnormals are
    // inside the IFS, never USEd. /tmp script: each IFS = 162 points, 320 triangular faces,
    // one component, local-coordinate sphere fit within 5e-8 of the radius (0.3 .. 0.7),
    // no Color -> 1 sphere each, 0 triangles (the sphere test is on the IFS's own points; the
    // Transform's non-uniform scale is applied afterwards).
    Expected {
        path: "tools/vtk/vtk_5sphere_actors_light.wrl",
        spheres: 5,
        gas: 1,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[("SpotLight", 1)],
    },
    // 300 glyph spheres merged into ONE IndexedFaceSet in one Transform/Shape: 10200 points,
    // 19200 coordIndex runs (all of length 3), 10200 per-vertex colours (no colorIndex).
    // /tmp script: glyph k uses exactly points 34k..34k+33 and faces 64k..64k+63, no point is
    // bit-identical to one of another glyph -> 300 components of 34 points / 64 faces; each
    // fits a sphere of radius 0.04 within 1.3e-6 of the radius, its points reach >= 0.95 r
    // along each of +-x, +-y, +-z (whole sphere), and its 34 corners carry one colour -> 300
    // spheres, 0 triangles. Material transparency 0 -> 0 gas; no IFS left skipped.
    // Background, Viewpoint 1, NavigationInfo, DirectionalLight 1.
    Expected {
        path: "tools/vtk/vtk_glyph300_spheres.wrl",
        spheres: 300,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
    // One Transform/Shape with `geometry PointSet`: `point [...]` spans 300 lines of one
    // `x y z,` triple each (lines 38-337) -> 300 points -> 300 spheres; its Material has
    // `transparency 0` -> 0 gas. Viewpoint 1, DirectionalLight 1.
    Expected {
        path: "tools/vtk/vtk_points300.wrl",
        spheres: 300,
        gas: 0,
        point_lights: 0,
        directional_lights: 1,
        viewpoints: 1,
        boxes: 0,
        cylinders: 0,
        cones: 0,
        triangles: 0,
        skipped: &[],
    },
];
