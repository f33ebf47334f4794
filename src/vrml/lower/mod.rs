//! Lowering: the only module that speaks both VRML and the scene IR.
//!
//! It receives parser events in file order and builds the [`Scene`] as nodes complete:
//! - grouping nodes remember where their contents start in the IR and, when they close, apply
//!   their matrix to that range (VRML allows `translation` after `children`); the same range is
//!   the scope of the DirectionalLights among their children;
//! - DEF'd nodes and PROTO declarations are recorded as events in an arena and replayed for
//!   USE and PROTO instances; nothing else is kept, so a million particles never make a tree;
//! - unknown node types, unknown fields and other loosely valid constructs are warnings with
//!   `file:line:col`, and `--strict` turns every warning into an error.
//!
//! Supported nodes (fields with VRML97 defaults; everything else is counted and skipped):
//! | node | fields used |
//! |---|---|
//! | Group, Anchor, Billboard, Collision | `children` (Billboard is not turned to the viewer; Collision's `proxy` is ignored) |
//! | Transform | `children translation rotation scale scaleOrientation center` |
//! | Switch | `choice whichChoice` (default -1: nothing) |
//! | LOD | `level` (the first level only) |
//! | Inline | `url`: local relative VRML97 files only, never a network URL; depth limit 16, cycles refused |
//! | Shape, Appearance, Material | `appearance material geometry`; Material: all six fields |
//! | Sphere | `radius` (default 1, must be > 0) |
//! | IndexedFaceSet | a sphere when its `coord` Coordinate's `point`s lie on one and `coordIndex` uses them all (see below); otherwise skipped |
//! | PointLight | `ambientIntensity attenuation color intensity location on radius` |
//! | DirectionalLight | `ambientIntensity color direction intensity on` |
//! | Viewpoint | `position orientation fieldOfView description` |
//! | NavigationInfo | `headlight` (first one wins) |
//! | Background | `skyColor[0]` (first one wins) |
//!
//! **Tessellated spheres.** Jmol writes every atom as a unit-sphere `IndexedFaceSet` reused
//! under scaled Transforms. An IndexedFaceSet is lowered as the sphere through its vertices
//! when [`crate::geom::sphere_through`] finds one (at least 12 points, all at one distance
//! from their bounding-box centre within 0.2 %, spread over the whole sphere), every point is
//! used by `coordIndex` (all indices valid) and it has no `color` node (per-vertex or
//! per-face colours are not a Material's). The Shape's Material applies as for a Sphere, and
//! Transforms apply as for a Sphere (a non-uniform scale gives an ellipsoid). Other fields
//! (normals, texture coordinates, `ccw`, `solid`, ...) are not read or checked, as for
//! skipped nodes. What a DEF'd IndexedFaceSet lowers to is kept at its first USE, so
//! later USEs cost a lookup, not a replay of its events.
//!
//! **Layout.** [`Lowerer`] holds the scene being built and one part per concern, each owned
//! by the file that works on it: `dispatch` (the one fast path for common events, and the
//! general handler), `record` (the event arena and the recordings under way), `replay` (USE
//! and Switch choices, and the one depth guard), `scope` (DEF and PROTO namespaces),
//! `declare` (PROTO declarations), `expand` (PROTO instances and `IS`), `open` (the stack of
//! open nodes), `start` (the node table and `node_start`), `close` (closing nodes), `fields`
//! (field values), `transform` (the Transform matrix and what it moves), `lights` (light
//! scopes), `material` (open Materials and sharing), `mesh` (tessellated spheres), `inline`
//! (files and Inline) and `route` (ROUTE checks).

mod close;
mod declare;
mod dispatch;
mod expand;
mod fields;
mod inline;
mod lights;
mod material;
mod mesh;
mod open;
mod record;
mod replay;
mod route;
mod scope;
mod start;
mod transform;

use std::collections::BTreeMap;

// hashbrown's default hasher (foldhash), not SipHash: every lookup here is on names and
// offsets from the scene text, hashed once per node or field of each PROTO instance.
use hashbrown::HashMap;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use crate::diag::{Diagnostic, Severity};
use crate::error::Error;
use crate::scene::{Material, Origin, Scene};
use crate::source::SourceWindow;

use close::Bound;
use expand::Expansions;
use inline::Files;
use material::Materials;
use mesh::Meshes;
use open::Open;
use record::{Rec, Recording};
use replay::Replay;
use scope::Scopes;
use transform::Transforms;

/// How to load a scene.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Every warning becomes an error.
    pub strict: bool,
    /// Refuse scenes that expand (through USE and PROTO instances) to more nodes than this.
    pub max_nodes: u64,
    /// Load `Inline` nodes (local relative files only).
    pub inline: bool,
    /// How deep Inline files may nest.
    pub max_inline_depth: usize,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            strict: false,
            max_nodes: 500_000_000,
            inline: true,
            max_inline_depth: 16,
        }
    }
}

/// What loading found besides the scene.
#[derive(Clone, Debug, Default)]
pub struct LoadReport {
    pub warnings: Vec<Diagnostic>,
    /// Node types that are not modelled, with the number of instances met.
    pub skipped: BTreeMap<String, u64>,
    /// Source bytes read (decompressed), over all files.
    pub bytes: u64,
    /// Compressed or plain bytes on disk are not tracked; this is wall time of parse + lowering.
    pub seconds: f64,
    /// Nodes lowered (USE and PROTO expansions included).
    pub nodes: u64,
    /// Files read (the scene and its Inlines).
    pub files: Vec<String>,
    /// Bytes held by the recorded DEF/PROTO events at the end.
    pub recorded_bytes: usize,
    /// IndexedFaceSet instances (USEs included) lowered as spheres: tessellated spheres such
    /// as Jmol's atoms. Those not recognised are counted in `skipped`.
    pub mesh_spheres: u64,
}

/// Loads a scene file (plain or gzip-compressed).
pub fn load_path(path: &Path, opts: &LoadOptions) -> Result<(Scene, LoadReport), Error> {
    let t0 = Instant::now();
    let mut low = Lowerer::new(opts.clone());
    low.load_file(path)?;
    low.finish(t0)
}

/// Loads a scene from bytes in memory (plain or gzip-compressed, any encoding errors
/// reported like a file's); `name` is used in messages and to resolve Inlines.
pub fn load_bytes(
    name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
) -> Result<(Scene, LoadReport), Error> {
    let t0 = Instant::now();
    let mut low = Lowerer::new(opts.clone());
    let reader = crate::input::sniff(std::io::Cursor::new(bytes)).map_err(|e| Error::Io {
        path: name.to_string(),
        source: e,
    })?;
    let src = SourceWindow::new(Arc::from(name), reader);
    low.load_source(src, Path::new(name))?;
    low.finish(t0)
}

/// Loads scene text held in memory; `name` is used in messages and to resolve Inlines.
/// The text goes through the same streaming reader as a file.
pub fn load_str(name: &str, text: &str, opts: &LoadOptions) -> Result<(Scene, LoadReport), Error> {
    load_bytes(name, text.as_bytes().to_vec(), opts)
}

/// The lowering of one scene (its Inlines included): the scene built so far, and one part
/// per concern, each owned by the file named.
struct Lowerer {
    opts: LoadOptions,
    scene: Scene,
    /// Nodes lowered, USE and PROTO expansions included (bounded by `max_nodes`).
    nodes: u64,
    /// Recorded events and the recordings under way (`record`).
    rec: Recording,
    /// How deep replays nest, and whether DEFs are being read again (`replay`).
    replay: Replay,
    /// DEF and PROTO namespaces (`scope`).
    scopes: Scopes,
    /// The PROTO expansions under way (`expand`).
    expansions: Expansions,
    /// The open nodes and node-valued fields (`open`).
    open: Open,
    /// Open Materials and the materials met recently (`material`).
    materials: Materials,
    /// Transform field boxes for reuse (`transform`).
    transforms: Transforms,
    /// Tessellated spheres (`mesh`).
    meshes: Meshes,
    /// The file being read and the chain of Inlines to it (`inline`).
    files: Files,
    /// The first NavigationInfo and Background are bound (`close`).
    bound: Bound,
    /// Warnings and skipped node types.
    diags: Diags,
}

/// Warnings (repeats folded) and the node types counted as skipped.
#[derive(Default)]
struct Diags {
    warnings: Vec<Diagnostic>,
    /// Where each (file, message) is in `warnings`.
    index: HashMap<(Arc<str>, String), usize>,
    skipped: BTreeMap<String, u64>,
}

impl Diags {
    /// A warning; repeats of the same message in the same file are folded into the first.
    fn warn(&mut self, src: &SourceWindow, at: u64, msg: impl Into<String>) {
        let msg = msg.into();
        let key = (src.name.clone(), msg);
        if let Some(&i) = self.index.get(&key) {
            self.warnings[i].repeats += 1;
            return;
        }
        let d = src.diagnostic(Severity::Warning, at, key.1.clone());
        self.index.insert(key, self.warnings.len());
        self.warnings.push(d);
    }

    /// Counts one more instance of a node type that is not lowered.
    fn skip(&mut self, ty: &str) {
        *self.skipped.entry(ty.to_string()).or_default() += 1;
    }
}

/// An error at `at` in `src`.
fn error(src: &SourceWindow, at: u64, msg: impl Into<String>) -> Error {
    Error::Diag(Box::new(src.diagnostic(Severity::Error, at, msg.into())))
}

impl Lowerer {
    fn new(opts: LoadOptions) -> Self {
        let mut low = Lowerer {
            opts,
            scene: Scene::default(),
            nodes: 0,
            rec: Recording::default(),
            replay: Replay::default(),
            scopes: Scopes::default(),
            expansions: Expansions::default(),
            open: Open::default(),
            materials: Materials::default(),
            transforms: Transforms::default(),
            meshes: Meshes::default(),
            files: Files::default(),
            bound: Bound::default(),
            diags: Diags::default(),
        };
        let unlit = low
            .materials
            .recent
            .index(&Material::unlit(), &mut low.scene.materials);
        debug_assert_eq!(unlit, material::UNLIT);
        low
    }

    fn finish(mut self, t0: Instant) -> Result<(Scene, LoadReport), Error> {
        if self.opts.strict && !self.diags.warnings.is_empty() {
            let errs = self
                .diags
                .warnings
                .into_iter()
                .map(|mut d| {
                    d.severity = Severity::Error;
                    d
                })
                .collect();
            return Err(Error::Diags(errs));
        }
        std::mem::take(&mut self.materials.recent).finish(&mut self.scene);
        self.scene.spheres.shrink_to_fit();
        self.scene.materials.shrink_to_fit();
        let report = LoadReport {
            warnings: self.diags.warnings,
            skipped: self.diags.skipped,
            bytes: self.files.bytes,
            seconds: t0.elapsed().as_secs_f64(),
            nodes: self.nodes,
            files: self.scene.files.clone(),
            recorded_bytes: self.rec.arena.capacity() * std::mem::size_of::<Rec>(),
            mesh_spheres: self.meshes.spheres,
        };
        Ok((self.scene, report))
    }

    fn origin(&self, at: u64) -> Origin {
        Origin::new(self.files.current, at)
    }

    /// Counts `n` more lowered nodes; an error past `max_nodes`.
    #[inline]
    fn add_nodes(&mut self, n: u64, src: &SourceWindow, at: u64) -> Result<(), Error> {
        self.nodes += n;
        if self.nodes > self.opts.max_nodes {
            return Err(error(
                src,
                at,
                format!(
                    "the scene expands to more than {} nodes (USE/PROTO blow-up?)",
                    self.opts.max_nodes
                ),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::{Origin, Sphere};

    #[test]
    fn spheres_stay_small() {
        // A million spheres are 48 MB of IR; Origin is packed into one word for this.
        assert_eq!(std::mem::size_of::<Sphere>(), 48);
        let o = Origin::new(3, 123_456_789_012);
        assert_eq!((o.file(), o.offset()), (3, 123_456_789_012));
        let o = Origin::new(u32::MAX, u64::MAX);
        assert_eq!((o.file(), o.offset()), ((1 << 20) - 1, (1 << 44) - 1));
    }
}
