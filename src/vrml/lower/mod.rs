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
//! What becomes of every standard node and field is data beside the node interfaces
//! (`schema::support`, published as docs/vrml.md, checked against this module by
//! `src/vrml/tests/vrml_support.rs`); in short: grouping nodes, Shape with Sphere, Box, Cylinder,
//! Cone and the meshes, the two lights, Viewpoint, NavigationInfo's headlight and
//! Background's first sky colour are used, and everything else is counted and skipped.
//!
//! **Meshes** (see `mesh_shape`). Exporters write particles as tessellated spheres: Jmol
//! one unit-sphere IndexedFaceSet per atom, reused under scaled Transforms; VTK and
//! ParaView all the glyphs of a dataset merged into one IndexedFaceSet. Every connected
//! component of an IndexedFaceSet's faces (faces sharing a point, or a point's coordinates)
//! whose vertices lie on one sphere ([`crate::geom::sphere_fit`]: at least 12 points,
//! all at one distance from the fitted centre within 0.2 %, spread over the whole sphere)
//! and whose Color is the same at every corner is lowered as that sphere, with that colour
//! as its diffuseColor (the Material's otherwise); Transforms apply as for a Sphere (a
//! non-uniform scale gives an ellipsoid). Every other component is lowered as triangles
//! (polygons triangulated, concave ones too). Points without faces (a PointSet, or an
//! IndexedFaceSet with no `coordIndex`, as MeshLab writes point clouds) become spheres of
//! radius `point_radius`, by default half the median distance to the nearest other point,
//! said in a note. `LoadOptions::spheres_only` leaves out everything but spheres. What a
//! DEF'd mesh lowers to is kept at its first USE, so later USEs cost a lookup, not a
//! replay of its events.
//!
//! **Layout.** Two halves, and what they share. The expander ([`expand`]) takes the parser's
//! events and resolves DEF and USE, PROTO and `IS`, EXTERNPROTO, Inline and ROUTE into plain
//! nodes; the scene builder ([`build`]) turns those into the [`Scene`] (the open frames,
//! materials, transforms, meshes, lights and bound nodes), knowing nothing of how VRML builds
//! by reference. The builder imports nothing of the expander; the expander drives it through
//! a concrete `&mut Builder` lent for each call (no trait: one builder), and never touches the
//! `Scene`. Both borrow the [`context`] (options, node count, expansion budget, diagnostics,
//! the file being read). `Lowerer` owns the three and is the parser's sink; `parallel` (one
//! large file read on several threads), `chunk` (a piece of it read on its own, and put in
//! place) and `in_order` (the pieces' results taken in file order) are its. The parser has
//! one sink type, [`expand::Lent`] (the expander lent its builder and context), as a second
//! would be a second copy of the parser.

mod build;
mod chunk;
mod context;
mod diags;
mod expand;
mod in_order;
mod parallel;

use std::collections::BTreeMap;

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use crate::diag::{Diagnostic, Severity};
use crate::error::Error;

use crate::scene::Scene;
use crate::source::SourceWindow;
use crate::vrml::syntax::OwnedEvent;

use build::Builder;
use context::Ctx;
use expand::{Expander, Lent, Rec};

/// The default [`LoadOptions::expansion_base`]: 2^22, room for a small file that builds a
/// lattice of a million nodes by DEF and USE.
pub const DEFAULT_EXPANSION_BASE: u64 = 1 << 22;

/// The default [`LoadOptions::max_expansion`]: a scene may create 16 times its text.
pub const DEFAULT_MAX_EXPANSION: u64 = 16;

/// How to load a scene.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Every warning becomes an error.
    pub strict: bool,
    /// The expansion budget: what USE, PROTO instances, `IS` and generated geometry may
    /// create (nodes, replayed events and their values, the items a reused mesh and an
    /// Extrusion add) is at most `expansion_base` plus this many per byte of scene text read
    /// so far; past it, loading fails at the construct that went over. Text read straight
    /// spends about one per byte, so only copies can exhaust it. It also bounds how far gzip
    /// data may inflate ([`Self::inflate_ratio`]).
    pub max_expansion: u64,
    /// The part of the expansion budget that does not grow with the text.
    pub expansion_base: u64,
    /// Read other files: load `Inline` nodes, and the PROTOs `EXTERNPROTO`s name (local
    /// relative files only).
    pub inline: bool,
    /// How deep Inline files (and files read for EXTERNPROTOs) may nest.
    pub max_inline_depth: usize,
    /// The radius of the spheres that points of a PointSet (or of an IndexedFaceSet without
    /// faces) become; `None`: half the median distance to the nearest other point of the set,
    /// said in a note.
    pub point_radius: Option<f64>,
    /// Lower only spheres (Spheres, tessellated spheres, points): Box, Cylinder, Cone and the
    /// other faces of IndexedFaceSets are skipped, as before they were drawn.
    pub spheres_only: bool,
    /// Threads that read a large file at once (0: as many as rayon's pool has; 1: one
    /// reader). The scene, its order and its warnings are the same either way.
    pub read_threads: usize,
    /// The least text read in one piece (and the least file size read in pieces); tests set it
    /// small.
    pub read_chunk_bytes: u64,
    /// Lower every PROTO instance by replaying its body, never by its compiled sphere
    /// template, and every sphere node event by event, never read whole (the same result,
    /// slower; tests compare the two).
    #[doc(hidden)]
    pub replay_every_instance: bool,
}

impl LoadOptions {
    /// How many times its compressed size gzip data may inflate to (beyond
    /// [`crate::input::INFLATE_BASE`]): 8 times [`Self::max_expansion`], 128 by default.
    pub fn inflate_ratio(&self) -> u64 {
        self.max_expansion.saturating_mul(8)
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            strict: false,
            max_expansion: DEFAULT_MAX_EXPANSION,
            expansion_base: DEFAULT_EXPANSION_BASE,
            inline: true,
            max_inline_depth: 16,
            point_radius: None,
            spheres_only: false,
            read_threads: 0,
            read_chunk_bytes: parallel::CHUNK_BYTES,
            replay_every_instance: false,
        }
    }
}

/// What loading found besides the scene.
#[derive(Clone, Debug, Default)]
pub struct LoadReport {
    /// The warnings met while loading, each with its position.
    pub warnings: Vec<Diagnostic>,
    /// Node types that are not modelled, with the number of instances met.
    pub skipped: BTreeMap<String, u64>,
    /// Source bytes read (decompressed), over all files.
    pub bytes: u64,
    /// Compressed or plain bytes on disk are not tracked; this is wall time of parse + lowering.
    pub seconds: f64,
    /// Nodes lowered (USE and PROTO expansions included).
    pub nodes: u64,
    /// The expansion budget spent (see [`LoadOptions::max_expansion`]).
    pub expansion: u64,
    /// Files read (the scene, its Inlines and the files its EXTERNPROTOs name).
    pub files: Vec<String>,
    /// Bytes held by the recorded DEF/PROTO events at the end.
    pub recorded_bytes: usize,
    /// Spheres found in IndexedFaceSets (USEs included): tessellated spheres such as Jmol's
    /// atoms or the particles of a VTK glyph mesh.
    pub mesh_spheres: u64,
    /// Spheres made of the points of PointSets and face-less IndexedFaceSets.
    pub point_spheres: u64,
    /// What loading chose for the user to know (the radius given to points).
    pub notes: Vec<Diagnostic>,
    /// Pieces the scene file was read in at once (0: read by one reader).
    pub read_pieces: usize,
    /// Why a file started in pieces was read again by one reader.
    pub read_again: Option<String>,
    /// Where and why the main reader read on by itself, after `read_pieces` pieces, when
    /// the file was read in pieces (a piece's guessed end was wrong, the region ended in it,
    /// it warned, ...; the result is the same).
    pub read_on: Option<String>,
    /// PROTO instances lowered by their body's sphere template rather than by replaying it
    /// (the same result; see `template.rs`).
    pub template_instances: u64,
    /// Plain sphere nodes (a Transform holding a Shape with a Sphere) read whole from the
    /// text rather than event by event (the same result; see `vrml::sphere_node`).
    pub whole_sphere_nodes: u64,
}

/// Refuses options no scene can be lowered with.
fn check_options(opts: &LoadOptions) -> Result<(), Error> {
    match opts.point_radius {
        Some(r) if !(r > 0.0 && r.is_finite()) => Err(Error::Invalid(format!(
            "the point radius must be a positive number, found {r}"
        ))),
        _ => Ok(()),
    }
}

/// Loads a scene file (plain or gzip-compressed).
pub fn load_path(path: &Path, opts: &LoadOptions) -> Result<(Scene, LoadReport), Error> {
    let t0 = Instant::now();
    check_options(opts)?;
    let size = std::fs::metadata(path).map_or(0, |m| m.len());
    let name: Arc<str> = Arc::from(path.display().to_string());
    let open = || -> Result<Box<dyn std::io::Read + Send>, Error> {
        let io = |e| Error::Io {
            path: path.display().to_string(),
            source: e,
        };
        crate::input::sniff_bounded(std::fs::File::open(path).map_err(io)?, opts.inflate_ratio())
            .map_err(io)
    };
    load_in_pieces((name, path, true), size, open, opts, t0)
}

/// Reads in pieces when that may pay (see [`parallel`]), else (or when the pieces' result
/// is thrown away) as one stream; `open` gives the decompressed text each time. `on_disk`:
/// the text is the file at `path` (whose pieces its readers may then read themselves).
fn load_in_pieces(
    (name, path, on_disk): (Arc<str>, &Path, bool),
    size: u64,
    open: impl Fn() -> Result<Box<dyn std::io::Read + Send>, Error>,
    opts: &LoadOptions,
    t0: Instant,
) -> Result<(Scene, LoadReport), Error> {
    let threads = match opts.read_threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    let mut again = None;
    if threads > 1 && size >= 2 * opts.read_chunk_bytes {
        let mut low = Lowerer::new(opts.clone());
        match parallel::load(
            &mut low,
            name.clone(),
            path,
            open()?,
            threads,
            (opts.read_chunk_bytes, size),
            on_disk,
        )? {
            parallel::Parallel::Chunks(n, read_on) => {
                let (scene, mut report) = low.finish(t0)?;
                report.read_pieces = n;
                report.read_on = read_on;
                return Ok((scene, report));
            }
            parallel::Parallel::Fallback(why) => again = Some(why),
        }
    }
    let mut low = Lowerer::new(opts.clone());
    low.expand.load_source(
        &mut low.cx,
        &mut low.build,
        SourceWindow::new(name, open()?),
        path,
    )?;
    let (scene, mut report) = low.finish(t0)?;
    report.read_again = again;
    Ok((scene, report))
}

/// Loads a scene from bytes in memory (plain or gzip-compressed, any encoding errors
/// reported like a file's); `name` is used in messages and to resolve Inlines.
pub fn load_bytes(
    name: &str,
    bytes: Vec<u8>,
    opts: &LoadOptions,
) -> Result<(Scene, LoadReport), Error> {
    let t0 = Instant::now();
    check_options(opts)?;
    /// The bytes, shared by the readers without a copy.
    struct Shared(Arc<Vec<u8>>);
    impl AsRef<[u8]> for Shared {
        fn as_ref(&self) -> &[u8] {
            &self.0
        }
    }
    let size = bytes.len() as u64;
    let bytes = Arc::new(bytes);
    let open = || -> Result<Box<dyn std::io::Read + Send>, Error> {
        let text = Shared(bytes.clone());
        crate::input::sniff_bounded(std::io::Cursor::new(text), opts.inflate_ratio()).map_err(|e| {
            Error::Io {
                path: name.to_string(),
                source: e,
            }
        })
    };
    load_in_pieces(
        (Arc::from(name), Path::new(name), false),
        size,
        open,
        opts,
        t0,
    )
}

/// Loads scene text held in memory; `name` is used in messages and to resolve Inlines.
/// The text goes through the same streaming reader as a file.
pub fn load_str(name: &str, text: &str, opts: &LoadOptions) -> Result<(Scene, LoadReport), Error> {
    load_bytes(name, text.as_bytes().to_vec(), opts)
}

/// The lowering of one scene (its Inlines included): the two halves and what they share. It
/// lends them to the parser as one sink ([`Self::lent`]) and puts pieces read apart in place
/// (`chunk`).
struct Lowerer {
    /// The options, node count, budget and diagnostics (`context`).
    cx: Ctx,
    /// The scene being built (`build`).
    build: Builder,
    /// DEF, PROTO, Inline and the rest of what VRML builds by reference (`expand`).
    expand: Expander,
}

impl Lowerer {
    /// The expander with the builder and context it drives: the parser's sink. (The one sink
    /// type: the parser is generic over it, and a second type would be a second copy of the
    /// parser.)
    #[inline(always)]
    fn lent(&mut self) -> Lent<'_> {
        Lent {
            x: &mut self.expand,
            cx: &mut self.cx,
            b: &mut self.build,
        }
    }

    fn new(opts: LoadOptions) -> Self {
        Lowerer {
            cx: Ctx::new(opts),
            build: Builder::new(),
            expand: Expander::default(),
        }
    }

    fn finish(mut self, t0: Instant) -> Result<(Scene, LoadReport), Error> {
        if self.cx.opts.strict && !self.cx.diags.warnings.is_empty() {
            let errs = self
                .cx
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
        self.build.scene.spheres.shrink_to_fit();
        self.build.scene.surfaces.shrink_to_fit();
        self.build.scene.materials.shrink_to_fit();
        let report = LoadReport {
            warnings: self.cx.diags.warnings,
            skipped: self.cx.diags.skipped,
            bytes: self.expand.files.bytes,
            seconds: t0.elapsed().as_secs_f64(),
            nodes: self.cx.nodes,
            expansion: self.cx.spent,
            files: self.build.scene.files.clone(),
            recorded_bytes: self.expand.rec.arena.capacity() * std::mem::size_of::<Rec>(),
            mesh_spheres: self.build.meshes.spheres,
            point_spheres: self.build.meshes.point_spheres,
            notes: self.cx.diags.notes,
            read_pieces: 0,
            read_again: None,
            read_on: None,
            template_instances: self.expand.templated,
            whole_sphere_nodes: self.build.whole_nodes,
        };
        Ok((self.build.scene, report))
    }
}

/// What replaying `ev` costs of the expansion budget: one unit, and one per value it carries.
#[inline(always)]
fn event_cost(ev: &OwnedEvent) -> u64 {
    match ev {
        OwnedEvent::Field { value, .. } => 1 + value.len() as u64,
        _ => 1,
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::{Origin, Sphere};

    #[test]
    fn spheres_stay_small() {
        // A million spheres are 56 MB of IR; Origin is packed into one word for this.
        assert_eq!(std::mem::size_of::<Sphere>(), 56);
        let o = Origin::new(3, 123_456_789_012);
        assert_eq!((o.file(), o.offset()), (3, 123_456_789_012));
        let o = Origin::new(u32::MAX, u64::MAX);
        assert_eq!((o.file(), o.offset()), ((1 << 20) - 1, (1 << 44) - 1));
    }
}
