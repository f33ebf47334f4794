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

use std::collections::BTreeMap;

// hashbrown's default hasher (foldhash), not SipHash: every lookup here is on names and
// offsets from the scene text, hashed once per node or field of each PROTO instance.
use hashbrown::{HashMap, HashSet};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;
use std::time::Instant;

use glam::{DAffine3, DMat3, DQuat, DVec3};

use super::materials::RecentMaterials;
use super::parse::Parser;
use super::schema::{self, Access, FieldType};
use super::syntax::{Event, OwnedEvent, OwnedValue, Sink, Value};
use crate::diag::{Diagnostic, Severity};
use crate::error::Error;
use crate::scene::{
    DirectionalLight, Light, Material, Origin, PointLight, Scene, Sphere, Viewpoint, NO_ELLIPSOID,
};
use crate::source::SourceWindow;

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

// ---------------------------------------------------------------------------------------------
// Recorded events

/// An event in the arena: as written, or a USE already resolved to the recording it names.
#[derive(Clone, Debug)]
enum Rec {
    Ev(OwnedEvent),
    /// A USE resolved when it was recorded (later redefinitions do not change what it means).
    Used {
        range: Range<usize>,
        at: u64,
    },
}

#[derive(Clone, Debug)]
struct DefEntry {
    range: Range<usize>,
    ty: Rc<str>,
}

#[derive(Debug)]
struct InterfaceField {
    access: Access,
    ty: FieldType,
    name: Rc<str>,
    /// The default value's events (one Field event, or NodesStart .. NodesEnd).
    default: Option<Range<usize>>,
}

#[derive(Debug)]
struct ProtoDecl {
    name: Rc<str>,
    fields: Vec<InterfaceField>,
    /// Body events (PROTO only); None for EXTERNPROTO.
    body: Option<Range<usize>>,
    /// A copy of the body's events, replayed for each instance without cloning each event
    /// out of the arena (USEs in it still name arena ranges, which stay pinned).
    body_events: Rc<[Rec]>,
    /// For each body event `field IS target` outside nested PROTO declarations, the index of
    /// `target` among `fields` (`u32::MAX` for other events), so that instances do not look IS
    /// targets up by name.
    body_is: Box<[u32]>,
    /// How many body events an instance replays: up to the end of the body's first node
    /// (earlier PROTO declarations included).
    first_end: usize,
}

impl ProtoDecl {
    fn field(&self, name: &str) -> Option<&InterfaceField> {
        self.fields.iter().find(|f| &*f.name == name)
    }
    /// The index of the first interface field of this name.
    fn field_index(&self, name: &str) -> Option<usize> {
        self.fields.iter().position(|f| &*f.name == name)
    }
    /// Resolves `set_x` and `x_changed` of an exposedField `x`, like the standard tables do.
    fn event(&self, name: &str) -> Option<(&InterfaceField, Access)> {
        if let Some(f) = self.field(name) {
            return Some((f, f.access));
        }
        if let Some(base) = name.strip_prefix("set_") {
            if let Some(f) = self
                .field(base)
                .filter(|f| f.access == Access::ExposedField)
            {
                return Some((f, Access::EventIn));
            }
        }
        if let Some(base) = name.strip_suffix("_changed") {
            if let Some(f) = self
                .field(base)
                .filter(|f| f.access == Access::ExposedField)
            {
                return Some((f, Access::EventOut));
            }
        }
        None
    }
}

/// A DEF and PROTO namespace: one per file, one per PROTO body expansion.
#[derive(Default)]
struct Scope {
    defs: HashMap<Rc<str>, DefEntry>,
    protos: HashMap<Rc<str>, Rc<ProtoDecl>>,
    /// Names whose DEF'd node is still open (a Script may USE itself).
    open_defs: Vec<Rc<str>>,
    /// File scopes stop PROTO lookups from reaching the including file.
    file_root: bool,
}

/// What an active recording is for.
#[derive(Debug)]
enum RecKind {
    Def(Rc<str>),
    ProtoDecl,
    /// A node inside a Switch's `choice`: kept for replay when the Switch closes.
    Choice,
    /// A PROTO instance: expanded when it closes.
    Instance,
    /// The value of one interface field default.
    Default,
}

#[derive(Debug)]
struct Recorder {
    start: usize,
    /// Open nodes (or PROTOs for a ProtoDecl) inside the recording; it ends when this returns to 0.
    depth: u32,
    kind: RecKind,
}

// ---------------------------------------------------------------------------------------------
// Open nodes

#[derive(Clone, Copy, Debug, Default)]
struct Marks {
    spheres: usize,
    lights: usize,
    views: usize,
}

#[derive(Debug)]
struct TransformFields {
    translation: DVec3,
    rotation: [f64; 4],
    scale: DVec3,
    scale_orientation: [f64; 4],
    center: DVec3,
}

impl Default for TransformFields {
    fn default() -> Self {
        TransformFields {
            translation: DVec3::ZERO,
            rotation: [0.0, 0.0, 1.0, 0.0],
            scale: DVec3::ONE,
            scale_orientation: [0.0, 0.0, 1.0, 0.0],
            center: DVec3::ZERO,
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Geom {
    Sphere(f64, u64),
    /// An IndexedFaceSet recognised as a sphere: index into `Lowerer::mesh_fits`, node offset.
    Mesh(u32, u64),
    Other,
}

/// An open IndexedFaceSet (rare: boxed in [`Kind::Mesh`]).
#[derive(Debug, Default)]
struct MeshState {
    /// From the `coord` Coordinate: point count and the sphere through the points, if any.
    coord: Option<CoordFit>,
    /// `coordIndex`, if given as integers.
    index: Option<Vec<f64>>,
    /// A `color` node was given.
    colored: bool,
    /// `Lowerer::nodes` before this node started (to cache the node count of a DEF).
    nodes_before: u64,
}

/// A Coordinate's point count and the sphere through its points (index into
/// `Lowerer::mesh_fits`), if any. Small and `Copy`, so [`Result_`] needs no drop.
#[derive(Clone, Copy, Debug, Default)]
struct CoordFit {
    points: usize,
    sphere: Option<u32>,
}

/// What a DEF'd IndexedFaceSet lowered to, replayed for each USE without its events.
#[derive(Clone, Copy, Debug)]
struct MeshCache {
    geom: Geom,
    /// Nodes its events lower (the IndexedFaceSet and the nodes inside).
    nodes: u64,
}

/// The DirectionalLights among a grouping node's children (indices into the scene's lights).
/// Rare, so boxed: the open-node frames stay small enough to move without a `memcpy` call.
type DirLights = Option<Box<Vec<usize>>>;

/// What an open node is lowered to. Large, rare payloads are boxed and a Material's fields
/// live on `Lowerer::open_materials`, so that a [`Frame`] stays within 128 bytes.
#[derive(Debug)]
enum Kind {
    /// Group, Transform, Anchor, Billboard, Collision, Inline, and each file's root.
    Group {
        transform: Option<Box<TransformFields>>,
        marks: Marks,
        dirlights: DirLights,
        inline_urls: Option<Box<[String]>>,
    },
    Switch {
        which: i64,
        choices: Vec<Range<usize>>,
        marks: Marks,
        dirlights: DirLights,
    },
    Lod {
        levels: u32,
        marks: Marks,
        dirlights: DirLights,
    },
    Shape {
        appearance: Option<Option<u32>>,
        geometry: Option<Geom>,
    },
    Appearance {
        material: Option<u32>,
    },
    /// Its fields are the top of `Lowerer::open_materials`.
    Material,
    Sphere {
        radius: f64,
    },
    /// An IndexedFaceSet (see "Tessellated spheres" above).
    Mesh(Box<MeshState>),
    /// A Coordinate in an IndexedFaceSet's `coord` field.
    Coord(CoordFit),
    PointLight(Box<PointLight>),
    DirectionalLight(Box<DirectionalLight>),
    Viewpoint(Box<Viewpoint>),
    NavigationInfo {
        headlight: Option<bool>,
    },
    Background {
        sky: Option<DVec3>,
    },
    /// Not modelled: its contents are read (DEFs inside stay usable) but not lowered.
    Skip,
    /// Recorded, not lowered (PROTO instance, Switch choice, ignored LOD level or proxy).
    Quiet,
}

/// What a standard node type lowers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lowered {
    Group,
    Transform,
    Inline,
    Switch,
    Lod,
    Shape,
    Appearance,
    Material,
    Sphere,
    IndexedFaceSet,
    Coordinate,
    PointLight,
    DirectionalLight,
    Viewpoint,
    NavigationInfo,
    Background,
    /// Not modelled: counted and skipped.
    Skipped,
}

const fn same_str(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn lowered_as(name: &str) -> Lowered {
    const MODELLED: [(&str, Lowered); 19] = [
        ("Group", Lowered::Group),
        ("Anchor", Lowered::Group),
        ("Billboard", Lowered::Group),
        ("Collision", Lowered::Group),
        ("Transform", Lowered::Transform),
        ("Inline", Lowered::Inline),
        ("Switch", Lowered::Switch),
        ("LOD", Lowered::Lod),
        ("Shape", Lowered::Shape),
        ("Appearance", Lowered::Appearance),
        ("Material", Lowered::Material),
        ("Sphere", Lowered::Sphere),
        ("IndexedFaceSet", Lowered::IndexedFaceSet),
        ("Coordinate", Lowered::Coordinate),
        ("PointLight", Lowered::PointLight),
        ("DirectionalLight", Lowered::DirectionalLight),
        ("Viewpoint", Lowered::Viewpoint),
        ("NavigationInfo", Lowered::NavigationInfo),
        ("Background", Lowered::Background),
    ];
    let mut i = 0;
    while i < MODELLED.len() {
        if same_str(MODELLED[i].0, name) {
            return MODELLED[i].1;
        }
        i += 1;
    }
    Lowered::Skipped
}

/// [`Lowered`] for each entry of [`schema::NODES`], by index (no string matching per node).
static LOWERED: [Lowered; schema::NODES.len()] = {
    let mut t = [Lowered::Skipped; schema::NODES.len()];
    let mut i = 0;
    while i < t.len() {
        t[i] = lowered_as(schema::NODES[i].name);
        i += 1;
    }
    t
};

/// A node type or field name held while its node is open: the standard tables' own string
/// when there is one (no allocation per node), a shared copy otherwise.
#[derive(Clone, Debug)]
enum Name {
    Static(&'static str),
    Shared(Rc<str>),
}

impl std::ops::Deref for Name {
    type Target = str;
    #[inline]
    fn deref(&self) -> &str {
        match self {
            Name::Static(s) => s,
            Name::Shared(s) => s,
        }
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self)
    }
}

#[derive(Debug)]
struct Frame {
    ty: Name,
    spec: Option<&'static schema::NodeSpec>,
    /// The PROTO whose instance this is (interface used for field checks).
    proto: Option<Rc<ProtoDecl>>,
    kind: Kind,
    at: u64,
    /// This frame started a suppression (contents are not lowered).
    quiet: bool,
}

/// What a closed node hands to the field it stands in.
enum Result_ {
    Nothing,
    Material(u32),
    Appearance(Option<u32>),
    Geometry(Geom),
    Coord(CoordFit),
}

/// The node-valued field being filled, with the frame index that owns it.
#[derive(Debug)]
struct FieldCtx {
    name: Name,
    frame: usize,
}

struct Lowerer {
    opts: LoadOptions,
    scene: Scene,
    arena: Vec<Rec>,
    /// Arena entries below this are referenced by DEFs or PROTOs and must stay.
    pinned: usize,
    recorders: Vec<Recorder>,
    scopes: Vec<Scope>,
    frames: Vec<Frame>,
    fields: Vec<FieldCtx>,
    /// Open frames that suppress lowering (Skip / Quiet frames, PROTO declarations).
    quiet: u32,
    /// Open PROTO declarations being recorded (their contents are neither lowered nor checked).
    in_proto_decl: u32,
    /// IS substitutions of the PROTO expansions under way (innermost last).
    substs: Vec<Subst>,
    /// Node type and field names of recorded events, shared (no allocation per recorded event).
    names: HashSet<Rc<str>>,
    /// The last name met in each slot of a small cache in front of `names`.
    recent_names: [Option<Rc<str>>; RECENT_NAMES],
    /// A PROTO was declared with a standard node type's name: standard types must then be
    /// looked up among the PROTOs too (otherwise they cannot name one).
    proto_shadows_standard: bool,
    /// A buffer for the recordings that end at one event (see `end_recorders_slow`).
    done_buf: Vec<(RecKind, Range<usize>)>,
    /// Emptied `Subst::values` of finished expansions, reused (one per nesting level).
    spare_values: Vec<Vec<Option<Range<usize>>>>,
    warnings: Vec<Diagnostic>,
    warn_index: HashMap<(Arc<str>, String), usize>,
    /// The fields of the open Material nodes, innermost last (see [`Kind::Material`]).
    open_materials: Vec<Material>,
    /// The boxes of closed Transforms' fields, reused by the next Transforms.
    #[allow(
        clippy::vec_box,
        reason = "the allocations themselves are what is reused"
    )]
    spare_transforms: Vec<Box<TransformFields>>,
    skipped: BTreeMap<String, u64>,
    /// Recent materials by content (equal ones are shared; see [`super::materials`]).
    materials: RecentMaterials,
    nodes: u64,
    replay_depth: u32,
    file: u32,
    inline_stack: Vec<PathBuf>,
    bytes: u64,
    /// The first NavigationInfo / Background is bound; later ones are ignored.
    nav_bound: bool,
    bg_bound: bool,
    /// Replaying a USE or a Switch choice: DEFs inside were registered when first read.
    reusing: u32,
    /// Spheres through the points of Coordinates in IndexedFaceSets ([`CoordFit`] and
    /// [`Geom::Mesh`] index this).
    mesh_fits: Vec<(DVec3, f64)>,
    /// IndexedFaceSet instances lowered as spheres (USEs included).
    mesh_spheres: u64,
    /// What each DEF'd IndexedFaceSet lowered to, by the start of its recording.
    mesh_cache: HashMap<usize, MeshCache>,
    /// The last IndexedFaceSet closed (for `mesh_cache`).
    last_mesh: Option<MeshCache>,
}

/// The values an instance gives its PROTO's interface fields.
#[derive(Debug)]
struct Subst {
    proto: Rc<ProtoDecl>,
    /// By interface field index (the first field of a name, as [`ProtoDecl::field`] finds).
    values: Vec<Option<Range<usize>>>,
}

const MAX_REPLAY_DEPTH: u32 = 200;

/// Slots of `Lowerer::recent_names`.
const RECENT_NAMES: usize = 16;

fn type_name(v: &Value) -> String {
    match v {
        Value::Numbers { values, .. } => format!("{} number(s)", values.len()),
        Value::Bools { values, .. } => format!("{} boolean(s)", values.len()),
        Value::Strings { values, .. } => format!("{} string(s)", values.len()),
        Value::Empty => "[ ]".into(),
        Value::Is(n) => format!("IS {n}"),
    }
}

/// Checks a generic value against a field type; the error says what was expected.
#[inline(always)]
/// Whether a member with this access takes no value in a node (an eventIn or eventOut).
fn is_event(access: Access) -> bool {
    matches!(access, Access::EventIn | Access::EventOut)
}

#[inline]
fn check_value(ty: FieldType, v: &Value) -> Result<(), String> {
    let ok = match (ty, v) {
        (_, Value::Is(_)) => true,
        (t, Value::Empty) => t.is_mf(),
        (FieldType::SFBool, Value::Bools { values, bracketed }) => values.len() == 1 && !bracketed,
        (FieldType::SFString, Value::Strings { values, bracketed }) => {
            values.len() == 1 && !bracketed
        }
        (FieldType::MFString, Value::Strings { values, bracketed }) => {
            *bracketed || values.len() == 1
        }
        (
            FieldType::SFImage,
            Value::Numbers {
                values, integer, ..
            },
        ) => {
            *integer && values.len() >= 3 && {
                let (w, h) = (values[0], values[1]);
                w >= 0.0 && h >= 0.0 && values.len() as f64 == 3.0 + w * h
            }
        }
        (
            t,
            Value::Numbers {
                values,
                integer,
                bracketed,
            },
        ) => match t.arity() {
            Some(_) if t.is_integer() && !integer => false,
            Some(k) if t.is_mf() => values.len() % k == 0 && (*bracketed || values.len() == k),
            Some(k) => values.len() == k && !bracketed,
            None => false,
        },
        _ => false,
    };
    if ok {
        Ok(())
    } else {
        Err(value_mismatch(ty, v))
    }
}

/// The message of [`check_value`] for a value that does not fit its field's type.
#[cold]
#[inline(never)]
fn value_mismatch(ty: FieldType, v: &Value) -> String {
    let want = match ty.arity() {
        Some(k) if ty.is_integer() => format!("{} ({k} integer(s) per value)", ty.name()),
        Some(k) => format!("{} ({k} number(s) per value)", ty.name()),
        None => ty.name().to_string(),
    };
    format!("expects {want}, found {}", type_name(v))
}

fn nums<'a>(v: &Value<'a>) -> &'a [f64] {
    match *v {
        Value::Numbers { values, .. } => values,
        _ => &[],
    }
}
fn vec3(v: &Value) -> DVec3 {
    let n = nums(v);
    DVec3::new(n[0], n[1], n[2])
}
fn num1(v: &Value) -> f64 {
    nums(v)[0]
}
fn bool1(v: &Value) -> bool {
    matches!(v, Value::Bools { values, .. } if values[0])
}
fn rot4(v: &Value) -> [f64; 4] {
    let n = nums(v);
    [n[0], n[1], n[2], n[3]]
}

/// Axis-angle rotation; a zero axis means no rotation.
fn quat(r: [f64; 4]) -> DQuat {
    let axis = DVec3::new(r[0], r[1], r[2]);
    let len = axis.length();
    if len == 0.0 || !len.is_finite() || r[3] == 0.0 {
        DQuat::IDENTITY
    } else {
        DQuat::from_axis_angle(axis / len, r[3])
    }
}

/// For a Transform that only translates (the particle case), the translation of its matrix.
///
/// The full product is then exactly `from_translation(shift)`: its other factors are exact
/// identities, and adding their zero translations turns a -0 component into +0, as `+ 0.0`
/// does.
fn translation_only(t: &TransformFields) -> Option<DVec3> {
    let plain = t.rotation[3] == 0.0
        && t.scale_orientation[3] == 0.0
        && t.scale == DVec3::ONE
        && t.center.to_array().map(f64::to_bits) == [0; 3];
    if !plain {
        return None;
    }
    let shift = t.translation + DVec3::ZERO;
    debug_assert_eq!(
        DAffine3::from_translation(shift)
            .to_cols_array()
            .map(f64::to_bits),
        full_transform_matrix(t).to_cols_array().map(f64::to_bits)
    );
    Some(shift)
}

fn full_transform_matrix(t: &TransformFields) -> DAffine3 {
    // M = T * C * R * SR * S * -SR * -C (VRML97 6.52)
    let sr = quat(t.scale_orientation);
    DAffine3::from_translation(t.translation)
        * DAffine3::from_translation(t.center)
        * DAffine3::from_quat(quat(t.rotation))
        * DAffine3::from_quat(sr)
        * DAffine3::from_scale(t.scale)
        * DAffine3::from_quat(sr.inverse())
        * DAffine3::from_translation(-t.center)
}

/// The uniform scale of a linear map that is a similarity (rotation, reflection, uniform scale).
fn similarity_scale(m: &DMat3) -> Option<f64> {
    let g = m.transpose() * *m;
    let d = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let tol = 1e-12 * d.abs().max(f64::MIN_POSITIVE);
    let off = [g.x_axis.y, g.x_axis.z, g.y_axis.z];
    let diag = [g.x_axis.x, g.y_axis.y, g.z_axis.z];
    if off.iter().all(|o| o.abs() <= tol) && diag.iter().all(|x| (x - d).abs() <= tol) {
        Some(d.sqrt())
    } else {
        None
    }
}

/// The rotation closest to a linear map (for viewpoint orientations under scaled transforms).
fn rotation_part(m: &DMat3) -> DQuat {
    let x = m.x_axis.normalize_or_zero();
    let y0 = m.y_axis - x * x.dot(m.y_axis);
    let y = y0.normalize_or_zero();
    let z = x.cross(y);
    if x == DVec3::ZERO || y == DVec3::ZERO {
        return DQuat::IDENTITY;
    }
    DQuat::from_mat3(&DMat3::from_cols(x, y, z)).normalize()
}

/// A sphere after transforms must still be finite with a positive radius (no overflow to
/// infinity or NaN, no underflow to zero).
fn check_sphere(center: DVec3, radius: f64) -> Result<(), String> {
    if !center.is_finite() {
        return Err(format!("a sphere centre overflow ({center})"));
    }
    if !(radius.is_finite() && radius > 0.0) {
        return Err(format!("a sphere radius overflow or underflow ({radius})"));
    }
    Ok(())
}

/// Reads the fields of an IndexedFaceSet or its Coordinate that decide whether it is a sphere.
/// Leniently: a value of another type makes it no sphere rather than an error (the node was
/// skipped whole before it could be one).
fn mesh_field(kind: &mut Kind, name: &str, value: &Value, fits: &mut Vec<(DVec3, f64)>) {
    match (kind, name, value) {
        (
            Kind::Mesh(m),
            "coordIndex",
            Value::Numbers {
                values,
                integer: true,
                ..
            },
        ) => m.index = Some(values.to_vec()),
        (Kind::Coord(c), "point", Value::Numbers { values, .. }) => {
            let sphere = crate::geom::sphere_through(values).map(|f| {
                fits.push(f);
                fits.len() as u32 - 1
            });
            *c = CoordFit {
                points: values.len() / 3,
                sphere,
            }
        }
        _ => {}
    }
}

/// Whether `coordIndex` refers only to existing points (or is -1, the face separator) and
/// uses every one of them: a mesh over all its vertices, not a piece of the sphere.
fn uses_all(index: &[f64], points: usize) -> bool {
    let mut seen = vec![false; points];
    for &i in index {
        if i == -1.0 {
            continue;
        }
        if !(i >= 0.0 && i < points as f64) {
            return false;
        }
        seen[i as usize] = true;
    }
    seen.iter().all(|&s| s)
}

fn is_local_relative(url: &str) -> bool {
    let lower = url.to_ascii_lowercase();
    let has_scheme = lower.find(':').is_some_and(|k| {
        k > 1
            && lower[..k]
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    });
    !has_scheme && !url.starts_with('/') && !url.starts_with('\\') && !url.is_empty()
}

impl Lowerer {
    fn new(opts: LoadOptions) -> Self {
        let mut low = Lowerer {
            opts,
            scene: Scene::default(),
            arena: Vec::new(),
            pinned: 0,
            recorders: Vec::new(),
            scopes: Vec::new(),
            frames: Vec::new(),
            fields: Vec::new(),
            quiet: 0,
            in_proto_decl: 0,
            substs: Vec::new(),
            names: HashSet::new(),
            recent_names: Default::default(),
            proto_shadows_standard: false,
            done_buf: Vec::new(),
            spare_values: Vec::new(),
            warnings: Vec::new(),
            warn_index: HashMap::new(),
            open_materials: Vec::new(),
            spare_transforms: Vec::new(),
            skipped: BTreeMap::new(),
            materials: RecentMaterials::default(),
            nodes: 0,
            replay_depth: 0,
            file: 0,
            inline_stack: Vec::new(),
            bytes: 0,
            nav_bound: false,
            bg_bound: false,
            reusing: 0,
            mesh_fits: Vec::new(),
            mesh_spheres: 0,
            mesh_cache: HashMap::new(),
            last_mesh: None,
        };
        low.materials
            .index(&Material::unlit(), &mut low.scene.materials);
        low
    }

    fn finish(mut self, t0: Instant) -> Result<(Scene, LoadReport), Error> {
        if self.opts.strict && !self.warnings.is_empty() {
            let errs = self
                .warnings
                .into_iter()
                .map(|mut d| {
                    d.severity = Severity::Error;
                    d
                })
                .collect();
            return Err(Error::Diags(errs));
        }
        std::mem::take(&mut self.materials).finish(&mut self.scene);
        self.scene.spheres.shrink_to_fit();
        self.scene.materials.shrink_to_fit();
        let report = LoadReport {
            warnings: self.warnings,
            skipped: self.skipped,
            bytes: self.bytes,
            seconds: t0.elapsed().as_secs_f64(),
            nodes: self.nodes,
            files: self.scene.files.clone(),
            recorded_bytes: self.arena.capacity() * std::mem::size_of::<Rec>(),
            mesh_spheres: self.mesh_spheres,
        };
        Ok((self.scene, report))
    }

    /// The scene's index of the innermost open Material's fields, which it takes off
    /// `open_materials` (read in place: no copy of the material until it is stored).
    fn close_material(&mut self) -> u32 {
        let m = self.open_materials.last().expect("open Material");
        let i = self.materials.index(m, &mut self.scene.materials);
        self.open_materials.pop();
        if self.materials.wants_merge(&self.scene.materials) {
            return self.merge_materials(i);
        }
        i
    }

    /// Merges the duplicate materials stored so far and renumbers every material index held:
    /// the spheres', the open Appearances' and Shapes', and `i` (returned).
    #[cold]
    #[inline(never)]
    fn merge_materials(&mut self, i: u32) -> u32 {
        let Some(new_index) = self.materials.merge(&mut self.scene.materials) else {
            return i;
        };
        let renumber = |m: &mut u32| *m = new_index[*m as usize];
        self.scene
            .spheres
            .iter_mut()
            .for_each(|s| renumber(&mut s.material));
        for f in &mut self.frames {
            match &mut f.kind {
                Kind::Appearance {
                    material: Some(m), ..
                }
                | Kind::Shape {
                    appearance: Some(Some(m)),
                    ..
                } => renumber(m),
                _ => {}
            }
        }
        new_index[i as usize]
    }

    fn marks(&self) -> Marks {
        Marks {
            spheres: self.scene.spheres.len(),
            lights: self.scene.lights.len(),
            views: self.scene.viewpoints.len(),
        }
    }

    fn origin(&self, at: u64) -> Origin {
        Origin::new(self.file, at)
    }

    // ----- diagnostics

    /// Counts `n` more lowered nodes; an error past `max_nodes`.
    #[inline]
    fn add_nodes(&mut self, n: u64, src: &SourceWindow, at: u64) -> Result<(), Error> {
        self.nodes += n;
        if self.nodes > self.opts.max_nodes {
            return Err(self.error(
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

    fn error(&self, src: &SourceWindow, at: u64, msg: impl Into<String>) -> Error {
        Error::Diag(Box::new(src.diagnostic(Severity::Error, at, msg.into())))
    }

    /// A warning; repeats of the same message in the same file are folded into the first.
    fn warn(&mut self, src: &SourceWindow, at: u64, msg: impl Into<String>) {
        let msg = msg.into();
        let key = (src.name.clone(), msg);
        if let Some(&i) = self.warn_index.get(&key) {
            self.warnings[i].repeats += 1;
            return;
        }
        let d = src.diagnostic(Severity::Warning, at, key.1.clone());
        self.warn_index.insert(key, self.warnings.len());
        self.warnings.push(d);
    }

    // ----- files

    fn load_file(&mut self, path: &Path) -> Result<(), Error> {
        let src = crate::input::open(path)?;
        self.load_source(src, path)
    }

    fn load_source(&mut self, src: SourceWindow, path: &Path) -> Result<(), Error> {
        let saved_file = self.file;
        self.file = self.scene.files.len() as u32;
        self.scene.files.push(src.name.to_string());
        self.inline_stack.push(path.to_path_buf());
        self.scopes.push(Scope {
            file_root: true,
            ..Scope::default()
        });
        // The file's root groups its top-level nodes (scope of top-level DirectionalLights).
        let root = Frame {
            ty: Name::Static("<file>"),
            spec: None,
            proto: None,
            kind: Kind::Group {
                transform: None,
                marks: self.marks(),
                dirlights: None,
                inline_urls: None,
            },
            at: 0,
            quiet: false,
        };
        self.frames.push(root);
        let depth = self.frames.len();
        // A new file is a new namespace, even when reached again through a USE'd Inline.
        let reusing = std::mem::replace(&mut self.reusing, 0);
        let substs = std::mem::take(&mut self.substs);
        let mut parser = Parser::new(src);
        let r = parser.run(self);
        self.reusing = reusing;
        self.substs = substs;
        r?;
        let src = &parser.src;
        if let Some(at) = src.bad_utf8 {
            self.warn(src, at, "invalid UTF-8 (bytes replaced by '?')");
        }
        debug_assert_eq!(self.frames.len(), depth);
        let root = self.frames.pop().expect("file root frame");
        self.close_group_like(src, root.kind, 0)?;
        self.scopes.pop();
        self.inline_stack.pop();
        self.bytes += src.bytes_read;
        self.file = saved_file;
        Ok(())
    }

    fn load_inline(&mut self, src: &SourceWindow, at: u64, urls: &[String]) -> Result<(), Error> {
        if !self.opts.inline {
            return Ok(());
        }
        let base = self
            .inline_stack
            .last()
            .and_then(|p| p.parent().map(Path::to_path_buf))
            .unwrap_or_default();
        let mut tried = Vec::new();
        for url in urls {
            if !is_local_relative(url) {
                tried.push(format!("'{url}' (not a local relative path)"));
                continue;
            }
            let path = base.join(url);
            if !path.is_file() {
                tried.push(format!("'{url}' (no such file)"));
                continue;
            }
            let canon = path.canonicalize().unwrap_or(path.clone());
            if self
                .inline_stack
                .iter()
                .any(|p| p.canonicalize().map(|c| c == canon).unwrap_or(false))
            {
                return Err(self.error(
                    src,
                    at,
                    format!("Inline '{url}' includes itself (a cycle)"),
                ));
            }
            if self.inline_stack.len() > self.opts.max_inline_depth {
                return Err(self.error(
                    src,
                    at,
                    format!(
                        "Inline '{url}' nests deeper than {} files",
                        self.opts.max_inline_depth
                    ),
                ));
            }
            // Only VRML97 is read; other formats (X3D, 3DS, VRML 1.0) are reported, not fatal.
            let mut head = [0u8; 16];
            let n = crate::input::open(&path)
                .ok()
                .map(|mut w| {
                    let _ = w.fill(16);
                    let b = w.rest().as_bytes();
                    let k = b.len().min(16);
                    head[..k].copy_from_slice(&b[..k]);
                    k
                })
                .unwrap_or(0);
            if !head[..n].starts_with(b"#VRML V2.0") {
                tried.push(format!("'{url}' (not a VRML97 file)"));
                continue;
            }
            return self.load_file(&path);
        }
        let what = if tried.is_empty() {
            "no url".to_string()
        } else {
            tried.join(", ")
        };
        self.warn(src, at, format!("Inline not loaded: {what}"));
        Ok(())
    }

    // ----- recording

    fn record(&mut self, ev: &Event) {
        if self.recorders.is_empty() {
            return;
        }
        let owned = match *ev {
            Event::NodeStart { def: None, ty, at } => OwnedEvent::NodeStart {
                def: None,
                ty: self.name_rc(ty),
                at,
            },
            Event::Field { name, at, value } => OwnedEvent::Field {
                name: self.name_rc(name),
                at,
                value: value.to_owned_value(),
            },
            Event::NodesStart { name, at } => OwnedEvent::NodesStart {
                name: self.name_rc(name),
                at,
            },
            _ => ev.to_owned_event(),
        };
        self.arena.push(Rec::Ev(owned));
    }

    /// A shared copy of a node type or field name (DEF names are not kept here).
    fn name_rc(&mut self, name: &str) -> Rc<str> {
        // The same few names come back in turn (one PROTO instance after another): a small
        // direct-mapped cache answers most of them without hashing.
        let b = name.as_bytes();
        let slot = (b.len() ^ (usize::from(b.first().copied().unwrap_or(0)) * 3)) % RECENT_NAMES;
        if let Some(n) = &self.recent_names[slot] {
            if n.as_bytes() == b {
                return n.clone();
            }
        }
        let n = match self.names.get(name) {
            Some(n) => n.clone(),
            None => {
                let n: Rc<str> = Rc::from(name);
                self.names.insert(n.clone());
                n
            }
        };
        self.recent_names[slot] = Some(n.clone());
        n
    }

    fn lookup_def(&self, name: &str) -> Option<&DefEntry> {
        self.scopes.last().and_then(|s| s.defs.get(name))
    }

    fn lookup_proto(&self, name: &str) -> Option<Rc<ProtoDecl>> {
        for s in self.scopes.iter().rev() {
            if let Some(p) = s.protos.get(name) {
                return Some(p.clone());
            }
            if s.file_root {
                break;
            }
        }
        None
    }

    /// Called after an event has been handled: closes recorders whose node (or PROTO) ended.
    #[inline]
    fn end_recorders(&mut self, ev: &Event) -> Vec<(RecKind, Range<usize>)> {
        if self.recorders.is_empty() {
            return Vec::new();
        }
        self.end_recorders_slow(ev)
    }

    fn end_recorders_slow(&mut self, ev: &Event) -> Vec<(RecKind, Range<usize>)> {
        let mut done = Vec::new();
        let (open, close) = match ev {
            Event::NodeStart { .. } => (true, false),
            Event::NodeEnd { .. } => (false, true),
            Event::ProtoStart { .. } => (true, false),
            Event::ProtoEnd { .. } => (false, true),
            _ => (false, false),
        };
        if !open && !close {
            return done;
        }
        for r in self.recorders.iter_mut() {
            if open {
                r.depth += 1;
            } else {
                r.depth -= 1;
            }
        }
        // A recorder that began at this very event started with depth 0 before the increment.
        while let Some(r) = self.recorders.last() {
            if r.depth == 0 {
                let r = self.recorders.pop().expect("recorder");
                if done.capacity() == 0 {
                    // (One per PROTO instance: `node_end` hands the buffer back.)
                    done = std::mem::take(&mut self.done_buf);
                }
                done.push((r.kind, r.start..self.arena.len()));
            } else {
                break;
            }
        }
        done
    }

    /// Drops arena entries that nothing refers to (after a PROTO instance or Switch choice).
    fn release(&mut self, from: usize) {
        if self.recorders.is_empty() {
            let keep = from.max(self.pinned);
            if keep < self.arena.len() {
                self.arena.truncate(keep);
            }
        }
    }

    // ----- replay

    fn replay(&mut self, src: &SourceWindow, range: Range<usize>, at: u64) -> Result<(), Error> {
        if self.replay_depth >= MAX_REPLAY_DEPTH {
            return Err(self.error(
                src,
                at,
                format!("USE and PROTO expansions nest deeper than {MAX_REPLAY_DEPTH}"),
            ));
        }
        self.replay_depth += 1;
        let mut i = range.start;
        while i < range.end {
            let rec = self.arena[i].clone();
            match rec {
                Rec::Ev(ev) => self.handle(src, ev.as_event())?,
                Rec::Used { range, at } => self.use_range(src, range, at)?,
            }
            i += 1;
        }
        self.replay_depth -= 1;
        Ok(())
    }

    /// A resolved USE: recorded as such if recording, replayed if lowering.
    fn use_range(&mut self, src: &SourceWindow, range: Range<usize>, at: u64) -> Result<(), Error> {
        if !self.recorders.is_empty() {
            self.arena.push(Rec::Used {
                range: range.clone(),
                at,
            });
        }
        if self.quiet == 0 {
            // A USE'd IndexedFaceSet as a Shape's geometry: lowered once, then looked up.
            let mesh = self.in_shape_geometry()
                && matches!(&self.arena[range.start],
                    Rec::Ev(OwnedEvent::NodeStart { ty, .. }) if &**ty == "IndexedFaceSet");
            if mesh {
                if let Some(c) = self.mesh_cache.get(&range.start).copied() {
                    self.add_nodes(c.nodes, src, at)?;
                    self.count_mesh(c.geom);
                    return self.deliver(src, Result_::Geometry(c.geom), at);
                }
                self.last_mesh = None;
            }
            // Replaying must not record the replayed events again into the same recorders:
            // they already hold the `Used` entry.
            let saved = std::mem::take(&mut self.recorders);
            self.reusing += 1;
            let r = self.replay(src, range.clone(), at);
            self.reusing -= 1;
            self.recorders = saved;
            r?;
            if mesh {
                if let Some(c) = self.last_mesh.take() {
                    self.mesh_cache.insert(range.start, c);
                }
            }
        } else if let Some(Frame {
            kind: Kind::Switch { choices, .. },
            ..
        }) = self.frames.last_mut()
        {
            // A USE among a Switch's choices is a choice of its own.
            choices.push(range);
        }
        Ok(())
    }

    /// Whether the node starting now stands in a Shape's `geometry` field.
    fn in_shape_geometry(&self) -> bool {
        self.fields.last().is_some_and(|ctx| {
            &*ctx.name == "geometry" && matches!(self.frames[ctx.frame].kind, Kind::Shape { .. })
        })
    }

    // ----- the event handler

    fn handle(&mut self, src: &SourceWindow, ev: Event<'_>) -> Result<(), Error> {
        // IS inside a PROTO expansion is replaced by the instance's value before anything else.
        if let Event::Field {
            name,
            at,
            value: Value::Is(target),
        } = ev
        {
            if self.in_proto_decl == 0 {
                return self.substitute(src, name, target, at);
            }
        }
        if let Event::Use { name, at } = ev {
            if self.in_proto_decl == 0 {
                return self.on_use(src, name, at);
            }
        }
        self.record(&ev);
        match ev {
            Event::NodeStart { def, ty, at } => self.node_start(src, def, ty, at)?,
            Event::NodeEnd { at } => {
                let done = self.end_recorders(&ev);
                if self.in_proto_decl > 0 {
                    // Inside a PROTO declaration nodes are only recorded (no frames were opened).
                    return Ok(());
                }
                self.node_end(src, at, done)?;
                return Ok(());
            }
            Event::Field { name, at, value } => self.field(src, name, at, value)?,
            Event::NodesStart { name, at } => self.nodes_start(src, name, at)?,
            Event::NodesEnd { .. } => {
                self.fields.pop();
            }
            Event::Use { .. } => {}
            Event::Null { .. } => {}
            Event::Decl { access, ty, at, .. } => {
                if self.in_proto_decl == 0 {
                    if schema::Access::from_keyword(access).is_none() {
                        return Err(self.error(src, at, format!("unknown access type '{access}'")));
                    }
                    if FieldType::from_name(ty).is_none() {
                        return Err(self.error(src, at, format!("unknown field type '{ty}'")));
                    }
                    if let Some(f) = self.frames.last() {
                        if &*f.ty == "Script" && access == "exposedField" {
                            self.warn(src, at, "a Script may not declare an exposedField");
                        }
                    }
                }
            }
            Event::ProtoStart { .. } => {
                if self.in_proto_decl == 0 {
                    // Start recording the declaration (including this event).
                    self.recorders.push(Recorder {
                        start: self.arena.len() - usize::from(!self.recorders.is_empty()),
                        depth: 0,
                        kind: RecKind::ProtoDecl,
                    });
                    if self.recorders.len() == 1 {
                        self.arena.push(Rec::Ev(ev.to_owned_event()));
                    }
                }
                self.in_proto_decl += 1;
                self.quiet += 1;
            }
            Event::ProtoBody { .. } => {}
            Event::ProtoEnd { .. } => {
                self.in_proto_decl -= 1;
                self.quiet -= 1;
                let done = self.end_recorders(&ev);
                for (kind, range) in done {
                    if let RecKind::ProtoDecl = kind {
                        self.declare_proto(src, range)?;
                    }
                }
                return Ok(());
            }
            Event::Route {
                from_node,
                from_field,
                to_node,
                to_field,
                at,
            } => {
                if self.in_proto_decl == 0 {
                    self.check_route(src, from_node, from_field, to_node, to_field, at);
                }
            }
        }
        if !self.recorders.is_empty() {
            let done = self.end_recorders_slow(&ev);
            debug_assert!(done.is_empty());
        }
        Ok(())
    }

    fn on_use(&mut self, src: &SourceWindow, name: &str, at: u64) -> Result<(), Error> {
        let Some(d) = self.lookup_def(name) else {
            let open = self
                .scopes
                .last()
                .is_some_and(|s| s.open_defs.iter().any(|n| &**n == name));
            if open && self.quiet > 0 {
                // A Script that refers to itself: fine, it is not lowered.
                if !self.recorders.is_empty() {
                    self.arena.push(Rec::Ev(OwnedEvent::Use {
                        name: name.into(),
                        at,
                    }));
                }
                return Ok(());
            }
            let msg = if open {
                format!("USE of '{name}' inside its own definition")
            } else {
                format!("USE of undefined name '{name}'")
            };
            return Err(self.error(src, at, msg));
        };
        let range = d.range.clone();
        let ty = d.ty.clone();
        self.check_child(src, &ty, at);
        self.use_range(src, range, at)
    }

    /// Replaces `field IS target` by the PROTO instance's value (or the interface default).
    fn substitute(
        &mut self,
        src: &SourceWindow,
        name: &str,
        target: &str,
        at: u64,
    ) -> Result<(), Error> {
        let Some(sub) = self.substs.last() else {
            return Err(self.error(
                src,
                at,
                format!("'{name} IS {target}' outside a PROTO body"),
            ));
        };
        let Some(fi) = sub.proto.field_index(target) else {
            let msg = format!(
                "'IS {target}': PROTO {} has no interface field '{target}'",
                sub.proto.name
            );
            return Err(self.error(src, at, msg));
        };
        self.substitute_field(src, name, fi, at)
    }

    /// [`Self::substitute`] for interface field `fi` of the innermost expansion's PROTO.
    fn substitute_field(
        &mut self,
        src: &SourceWindow,
        name: &str,
        fi: usize,
        at: u64,
    ) -> Result<(), Error> {
        let Some(sub) = self.substs.last() else {
            return Err(Error::Other(
                "internal: IS outside a PROTO expansion".into(),
            ));
        };
        let range = sub.values[fi]
            .clone()
            .or_else(|| sub.proto.fields[fi].default.clone());
        let Some(range) = range else {
            // An event (eventIn/eventOut) has no value to substitute.
            return Ok(());
        };
        // A plain value with nothing recording: lowered at once, as written in scene text.
        if let Rec::Ev(OwnedEvent::Field { value, at: vat, .. }) = &self.arena[range.start] {
            if !matches!(value, OwnedValue::Is(_)) && self.recorders.is_empty() {
                let (v, vat) = (value.clone(), *vat);
                return self.field(src, name, vat, v.as_value());
            }
        }
        // The instance's substitutions are set aside while its value is emitted: the value is
        // resolved in the instance's scope, with the IS substitutions of the next one out.
        let Some(sub) = self.substs.pop() else {
            return Ok(());
        };
        // Emit the value under this field's own name.
        let r = match &self.arena[range.start] {
            Rec::Ev(OwnedEvent::Field { value, at: vat, .. }) => {
                let (v, vat) = (value.clone(), *vat);
                <Self as Sink>::event(
                    self,
                    src,
                    Event::Field {
                        name,
                        at: vat,
                        value: v.as_value(),
                    },
                )
            }
            Rec::Ev(OwnedEvent::NodesStart { at: vat, .. }) => {
                let vat = *vat;
                self.handle(src, Event::NodesStart { name, at: vat })
                    .and_then(|_| self.replay(src, range.start + 1..range.end - 1, at))
                    .and_then(|_| self.handle(src, Event::NodesEnd { at: vat }))
            }
            _ => Ok(()),
        };
        self.substs.push(sub);
        r
    }

    fn node_start(
        &mut self,
        src: &SourceWindow,
        def: Option<&str>,
        ty: &str,
        at: u64,
    ) -> Result<(), Error> {
        let def_rc: Option<Rc<str>> = def.map(Rc::from);
        if self.in_proto_decl > 0 {
            return Ok(());
        }
        if let (Some(d), 0) = (&def_rc, self.reusing) {
            // Record the DEF'd node (this NodeStart was pushed just before, if recording).
            let start = if self.recorders.is_empty() {
                self.arena.push(Rec::Ev(OwnedEvent::NodeStart {
                    def: Some(d.clone()),
                    ty: ty.into(),
                    at,
                }));
                self.arena.len() - 1
            } else {
                self.arena.len() - 1
            };
            self.recorders.push(Recorder {
                start,
                depth: 0,
                kind: RecKind::Def(d.clone()),
            });
            if let Some(s) = self.scopes.last_mut() {
                s.open_defs.push(d.clone());
            }
        }
        self.add_nodes(1, src, at)?;
        let index = schema::node_index(ty);
        let spec = index.map(|i| &schema::NODES[i]);
        // A standard type was found by this very name.
        let ty_rc = match spec {
            Some(s) => Name::Static(s.name),
            None => Name::Shared(self.name_rc(ty)),
        };
        if self.quiet > 0 {
            // Not lowered; a frame keeps the nesting.
            self.frames.push(Frame {
                ty: ty_rc,
                spec: None,
                proto: None,
                kind: Kind::Quiet,
                at,
                quiet: false,
            });
            return Ok(());
        }
        self.check_child(src, ty, at);
        // Where does this node stand? (A Switch choice, an LOD level after the first, or a
        // Collision proxy is recorded or ignored, not lowered.)
        let (in_choice, ignored_level) = match self.fields.last() {
            None => (false, false),
            Some(ctx) => match &mut self.frames[ctx.frame].kind {
                Kind::Switch { .. } => (&*ctx.name == "choice", false),
                Kind::Lod { levels, .. } if &*ctx.name == "level" => {
                    let ignored = *levels > 0;
                    *levels += 1;
                    (false, ignored)
                }
                Kind::Group { .. } => (false, &*ctx.name == "proxy"),
                Kind::Mesh(_) => {
                    self.mesh_child(ty_rc, at);
                    return Ok(());
                }
                _ => (false, false),
            },
        };
        if in_choice || ignored_level {
            if in_choice
                && self
                    .recorders
                    .iter()
                    .all(|r| !matches!(r.kind, RecKind::Choice))
            {
                self.start_recorder_here(&ty_rc, def, at);
                if let Some(r) = self.recorders.last_mut() {
                    r.kind = RecKind::Choice;
                }
            }
            self.push_quiet(ty_rc, at);
            return Ok(());
        }
        let proto = if index.is_none() || self.proto_shadows_standard {
            self.lookup_proto(ty)
        } else {
            None
        };
        if let Some(proto) = proto {
            if proto.body.is_some() {
                // Record the instance, expand it when it closes.
                self.start_recorder_here(&ty_rc, def, at);
                if let Some(r) = self.recorders.last_mut() {
                    r.kind = RecKind::Instance;
                }
            } else {
                *self.skipped.entry(ty.to_string()).or_default() += 1;
                self.warn(
                    src,
                    at,
                    format!("EXTERNPROTO {ty} is not available (external prototypes are not loaded): skipped"),
                );
            }
            self.frames.push(Frame {
                ty: ty_rc,
                spec: None,
                proto: Some(proto),
                kind: Kind::Quiet,
                at,
                quiet: true,
            });
            self.quiet += 1;
            return Ok(());
        }
        let m = self.marks();
        let group = |transform| Kind::Group {
            transform,
            marks: m,
            dirlights: None,
            inline_urls: None,
        };
        let lowered = index.map_or(Lowered::Skipped, |i| LOWERED[i]);
        let kind = match lowered {
            Lowered::Group => group(None),
            Lowered::Transform => group(Some(match self.spare_transforms.pop() {
                Some(mut t) => {
                    *t = TransformFields::default();
                    t
                }
                None => Box::default(),
            })),
            Lowered::Inline => Kind::Group {
                transform: None,
                marks: m,
                dirlights: None,
                inline_urls: Some(Box::default()),
            },
            Lowered::Switch => Kind::Switch {
                which: -1,
                choices: Vec::new(),
                marks: m,
                dirlights: None,
            },
            Lowered::Lod => Kind::Lod {
                levels: 0,
                marks: m,
                dirlights: None,
            },
            Lowered::Shape => Kind::Shape {
                appearance: None,
                geometry: None,
            },
            Lowered::Appearance => Kind::Appearance { material: None },
            Lowered::Material => {
                self.open_materials.push(Material::default());
                Kind::Material
            }
            Lowered::Sphere => Kind::Sphere { radius: 1.0 },
            Lowered::IndexedFaceSet => {
                self.open_mesh(ty_rc, at);
                return Ok(());
            }
            Lowered::PointLight => Kind::PointLight(Box::new(PointLight {
                location: DVec3::ZERO,
                color: DVec3::ONE,
                intensity: 1.0,
                ambient_intensity: 0.0,
                attenuation: DVec3::new(1.0, 0.0, 0.0),
                radius: 100.0,
                on: true,
                origin: self.origin(at),
            })),
            Lowered::DirectionalLight => Kind::DirectionalLight(Box::new(DirectionalLight {
                direction: DVec3::new(0.0, 0.0, -1.0),
                color: DVec3::ONE,
                intensity: 1.0,
                ambient_intensity: 0.0,
                on: true,
                scope: (0, 0),
                origin: self.origin(at),
            })),
            Lowered::Viewpoint => Kind::Viewpoint(Box::new(Viewpoint {
                name: def.map(str::to_string),
                description: String::new(),
                position: DVec3::new(0.0, 0.0, 10.0),
                orientation: DQuat::IDENTITY,
                field_of_view: std::f64::consts::FRAC_PI_4,
                origin: self.origin(at),
            })),
            Lowered::NavigationInfo => Kind::NavigationInfo { headlight: None },
            Lowered::Background => Kind::Background { sky: None },
            // A Coordinate is read only in an IndexedFaceSet's `coord` (see `mesh_child`).
            Lowered::Skipped | Lowered::Coordinate => {
                // Standard nodes we do not model are counted in the report, not warned about:
                // they are valid VRML, and `--strict` is about validity.
                if spec.is_none() {
                    self.warn(src, at, format!("unknown node type '{ty}': skipped"));
                }
                *self.skipped.entry(ty.to_string()).or_default() += 1;
                self.frames.push(Frame {
                    ty: ty_rc,
                    spec,
                    proto: None,
                    kind: Kind::Skip,
                    at,
                    quiet: true,
                });
                self.quiet += 1;
                return Ok(());
            }
        };
        self.frames.push(Frame {
            ty: ty_rc,
            spec,
            proto: None,
            kind,
            at,
            quiet: false,
        });
        Ok(())
    }

    /// An IndexedFaceSet: its fields are read leniently (see `field`), with no table: as for a
    /// skipped node, none of them is checked or warned about.
    #[cold]
    #[inline(never)]
    fn open_mesh(&mut self, ty: Name, at: u64) {
        self.frames.push(Frame {
            ty,
            spec: None,
            proto: None,
            kind: Kind::Mesh(Box::new(MeshState {
                nodes_before: self.nodes - 1,
                ..MeshState::default()
            })),
            at,
            quiet: false,
        });
    }

    /// A node inside an IndexedFaceSet: only the `coord` Coordinate is read; other nodes are
    /// neither lowered nor counted (as when the IndexedFaceSet was skipped whole).
    #[cold]
    #[inline(never)]
    fn mesh_child(&mut self, ty: Name, at: u64) {
        let Some(ctx) = self.fields.last() else {
            return;
        };
        let coord = &*ctx.name == "coord" && &*ty == "Coordinate";
        if let Kind::Mesh(m) = &mut self.frames[ctx.frame].kind {
            m.colored |= &*ctx.name == "color";
        }
        if coord {
            self.frames.push(Frame {
                ty,
                spec: None,
                proto: None,
                kind: Kind::Coord(CoordFit::default()),
                at,
                quiet: false,
            });
        } else {
            self.push_quiet(ty, at);
        }
    }

    /// Starts a recorder whose first event is the NodeStart just handled.
    fn start_recorder_here(&mut self, ty: &Name, def: Option<&str>, at: u64) {
        let start = if self.recorders.is_empty() {
            let ty = match ty {
                Name::Shared(rc) => rc.clone(),
                Name::Static(s) => self.name_rc(s),
            };
            self.arena.push(Rec::Ev(OwnedEvent::NodeStart {
                def: def.map(Rc::from),
                ty,
                at,
            }));
            self.arena.len() - 1
        } else {
            // Already recorded by the enclosing recorder; a DEF recorder may have started here too.
            self.recorders
                .last()
                .filter(|r| r.depth == 0)
                .map(|r| r.start)
                .unwrap_or(self.arena.len() - 1)
        };
        self.recorders.push(Recorder {
            start,
            depth: 0,
            kind: RecKind::Default,
        });
    }

    fn push_quiet(&mut self, ty: Name, at: u64) {
        self.frames.push(Frame {
            ty,
            spec: None,
            proto: None,
            kind: Kind::Quiet,
            at,
            quiet: true,
        });
        self.quiet += 1;
    }

    /// Warns when a node type does not belong in the field it stands in.
    #[inline(always)]
    fn check_child(&mut self, src: &SourceWindow, ty: &str, at: u64) {
        let Some(ctx) = self.fields.last() else {
            return;
        };
        let parent = &self.frames[ctx.frame];
        let allowed: &[&str] = match (&parent.kind, &*ctx.name) {
            (Kind::Shape { .. }, "appearance") => &["Appearance"],
            (Kind::Appearance { .. }, "material") => &["Material"],
            _ => return,
        };
        if !allowed.contains(&ty) && self.lookup_proto(ty).is_none() {
            let msg = format!(
                "{ty} is not allowed in field '{}' of {}: ignored",
                ctx.name, parent.ty
            );
            self.warn(src, at, msg);
        }
    }

    fn field(
        &mut self,
        src: &SourceWindow,
        name: &str,
        at: u64,
        value: Value<'_>,
    ) -> Result<(), Error> {
        if self.quiet > 0 {
            return Ok(());
        }
        let Some((f, access)) = self.field_spec(src, name, at) else {
            // (IndexedFaceSet and Coordinate frames have no table: their fields come here.)
            if let Some(Frame {
                kind: k @ (Kind::Mesh(_) | Kind::Coord(_)),
                ..
            }) = self.frames.last_mut()
            {
                mesh_field(k, name, &value, &mut self.mesh_fits);
            }
            return Ok(());
        };
        if is_event(access) {
            let ty = self.open_type();
            self.warn_if_event(src, name, &ty, access, at);
            return Ok(());
        }
        if f.ty.is_node() {
            if value == Value::Empty {
                return Ok(());
            }
            let ty = self.open_type();
            return Err(self.error(
                src,
                at,
                format!(
                    "field '{name}' of {ty} expects {}, found {}",
                    f.ty.name(),
                    type_name(&value)
                ),
            ));
        }
        if let Err(e) = check_value(f.ty, &value) {
            let ty = self.open_type();
            return Err(self.error(src, at, format!("field '{name}' of {ty} {e}")));
        }
        self.apply_field(src, f.name, at, &value)
    }

    /// The field table entry for `name` in the innermost open standard node, with the access it
    /// was used with. Unknown names are warned about; nodes without a table (PROTO instances,
    /// unknown types) give None silently.
    #[inline(always)]
    fn field_spec(
        &mut self,
        src: &SourceWindow,
        name: &str,
        at: u64,
    ) -> Option<(&'static schema::FieldSpec, Access)> {
        let frame = self.frames.last()?;
        let found = frame.spec?.event(name);
        if found.is_none() {
            let ty = self.open_type();
            self.warn(src, at, format!("unknown field '{name}' of {ty}: ignored"));
        }
        found
    }

    /// The type of the innermost open node (for messages).
    fn open_type(&self) -> Name {
        self.frames
            .last()
            .map_or(Name::Static(""), |f| f.ty.clone())
    }

    /// Warns when a value is given to an eventIn or eventOut; says whether it did.
    fn warn_if_event(
        &mut self,
        src: &SourceWindow,
        name: &str,
        ty: &str,
        access: Access,
        at: u64,
    ) -> bool {
        let event = is_event(access);
        if event {
            let msg = format!(
                "'{name}' of {ty} is an {}, not a field: ignored",
                access.keyword()
            );
            self.warn(src, at, msg);
        }
        event
    }

    #[inline(always)]
    fn apply_field(
        &mut self,
        src: &SourceWindow,
        name: &str,
        at: u64,
        v: &Value<'_>,
    ) -> Result<(), Error> {
        let frame = self.frames.last_mut().expect("open frame");
        let mut problem: Option<String> = None;
        match &mut frame.kind {
            Kind::Group {
                transform: Some(t), ..
            } => match name {
                "translation" => t.translation = vec3(v),
                "rotation" => t.rotation = rot4(v),
                "scale" => t.scale = vec3(v),
                "scaleOrientation" => t.scale_orientation = rot4(v),
                "center" => t.center = vec3(v),
                _ => {}
            },
            Kind::Group {
                inline_urls: Some(u),
                ..
            } if name == "url" => {
                if let Value::Strings { values, .. } = v {
                    *u = Box::from(*values);
                }
            }
            Kind::Switch { which, .. } if name == "whichChoice" => *which = num1(v) as i64,
            Kind::Material => {
                let m = self.open_materials.last_mut().expect("open Material");
                match name {
                    "diffuseColor" => m.diffuse = vec3(v),
                    "emissiveColor" => m.emissive = vec3(v),
                    "specularColor" => m.specular = vec3(v),
                    "shininess" => {
                        let x = num1(v);
                        if !(0.0..=1.0).contains(&x) {
                            // VMD writes its raw Phong exponent (40) here; VRML97 says [0, 1].
                            problem = Some(format!("shininess {x} is outside [0, 1]: clamped"));
                        }
                        m.shininess = x.clamp(0.0, 1.0);
                    }
                    "ambientIntensity" => m.ambient_intensity = num1(v),
                    "transparency" => {
                        let t = num1(v);
                        if !(0.0..=1.0).contains(&t) {
                            problem = Some(format!("transparency {t} is outside [0, 1]: clamped"));
                        }
                        m.transparency = t.clamp(0.0, 1.0);
                    }
                    _ => {}
                }
            }
            Kind::Sphere { radius } if name == "radius" => {
                let r = num1(v);
                if r <= 0.0 || !r.is_finite() {
                    return Err(Error::Diag(Box::new(src.diagnostic(
                        Severity::Error,
                        at,
                        format!("Sphere radius must be positive, found {r}"),
                    ))));
                }
                *radius = r;
            }
            Kind::PointLight(l) => match name {
                "location" => l.location = vec3(v),
                "color" => l.color = vec3(v),
                "intensity" => l.intensity = num1(v),
                "ambientIntensity" => l.ambient_intensity = num1(v),
                "attenuation" => l.attenuation = vec3(v),
                "radius" => {
                    l.radius = num1(v);
                    if l.radius < 0.0 {
                        problem = Some("PointLight radius must not be negative".into());
                    }
                }
                "on" => l.on = bool1(v),
                _ => {}
            },
            Kind::DirectionalLight(l) => match name {
                "direction" => l.direction = vec3(v),
                "color" => l.color = vec3(v),
                "intensity" => l.intensity = num1(v),
                "ambientIntensity" => l.ambient_intensity = num1(v),
                "on" => l.on = bool1(v),
                _ => {}
            },
            Kind::Viewpoint(vp) => match name {
                "position" => vp.position = vec3(v),
                "orientation" => vp.orientation = quat(rot4(v)),
                "fieldOfView" => {
                    let f = num1(v);
                    if !(f > 0.0 && f < std::f64::consts::PI) {
                        problem = Some(format!("fieldOfView {f} is outside (0, pi): using pi/4"));
                        vp.field_of_view = std::f64::consts::FRAC_PI_4;
                    } else {
                        vp.field_of_view = f;
                    }
                }
                "description" => {
                    if let Value::Strings { values, .. } = v {
                        vp.description = values[0].clone();
                    }
                }
                _ => {}
            },
            Kind::NavigationInfo { headlight } if name == "headlight" => {
                *headlight = Some(bool1(v));
            }
            Kind::Background { sky } if name == "skyColor" => {
                let n = nums(v);
                if n.len() >= 3 {
                    *sky = Some(DVec3::new(n[0], n[1], n[2]));
                }
            }
            _ => {}
        }
        if let Some(p) = problem {
            self.warn(src, at, p);
        }
        Ok(())
    }

    fn nodes_start(&mut self, src: &SourceWindow, name: &str, at: u64) -> Result<(), Error> {
        let idx = self.frames.len().saturating_sub(1);
        let mut known = None;
        if self.quiet == 0 {
            if let Some((f, access)) = self.field_spec(src, name, at) {
                known = Some(f.name);
                if !f.ty.is_node() {
                    let ty = self.open_type();
                    return Err(self.error(
                        src,
                        at,
                        format!(
                            "field '{name}' of {ty} expects {}, found a node",
                            f.ty.name()
                        ),
                    ));
                }
                if is_event(access) {
                    let ty = self.open_type();
                    self.warn_if_event(src, name, &ty, access, at);
                }
            }
        }
        // The table's entry is this name unless it was found through a set_/_changed alias
        // (which is longer).
        let name = match known {
            Some(k) if k.len() == name.len() => Name::Static(k),
            _ => Name::Shared(Rc::from(name)),
        };
        self.fields.push(FieldCtx { name, frame: idx });
        Ok(())
    }

    fn node_end(
        &mut self,
        src: &SourceWindow,
        at: u64,
        done: Vec<(RecKind, Range<usize>)>,
    ) -> Result<(), Error> {
        if done.is_empty() && self.quiet == 0 {
            if let Some(result) = self.close_leaf() {
                return self.deliver(src, result, at);
            }
        }
        // Register DEFs first: the node is complete.
        let mut instance = None;
        let mut choice = None;
        let mut done = done;
        for (kind, range) in done.drain(..) {
            match kind {
                RecKind::Def(name) if self.in_proto_decl == 0 => {
                    let ty = match &self.arena[range.start] {
                        Rec::Ev(OwnedEvent::NodeStart { ty, .. }) => ty.clone(),
                        _ => Rc::from("?"),
                    };
                    if let Some(s) = self.scopes.last_mut() {
                        s.open_defs.retain(|n| *n != name);
                        s.defs.insert(
                            name,
                            DefEntry {
                                range: range.clone(),
                                ty,
                            },
                        );
                    }
                    self.pinned = self.pinned.max(range.end);
                }
                RecKind::Instance => instance = Some(range),
                RecKind::Choice => choice = Some(range),
                _ => {}
            }
        }
        if done.capacity() > 0 {
            self.done_buf = done;
        }
        let frame = self.frames.pop().expect("NodeEnd without an open node");
        if frame.quiet {
            self.quiet -= 1;
        }
        if let Some(range) = choice {
            if let Some(Frame {
                kind: Kind::Switch { choices, .. },
                ..
            }) = self.frames.last_mut()
            {
                choices.push(range);
            }
            return Ok(());
        }
        if let Some(range) = instance {
            if let Some(proto) = frame.proto.clone() {
                self.expand(src, proto, range.clone(), frame.at)?;
                // The instance's recording is no longer needed unless a DEF refers into it.
                self.release(range.start);
            }
            return Ok(());
        }
        if self.quiet > 0 || matches!(frame.kind, Kind::Quiet | Kind::Skip) {
            let result = if matches!(frame.kind, Kind::Skip) && self.quiet == 0 {
                Result_::Geometry(Geom::Other)
            } else {
                Result_::Nothing
            };
            return self.deliver(src, result, at);
        }
        let result = self.close(src, frame)?;
        self.deliver(src, result, at)
    }

    /// Hands a closed node's result to the field it stands in.
    fn deliver(&mut self, _src: &SourceWindow, result: Result_, _at: u64) -> Result<(), Error> {
        let Some(ctx) = self.fields.last() else {
            return Ok(());
        };
        let frame = &mut self.frames[ctx.frame];
        match (&mut frame.kind, &*ctx.name, result) {
            (Kind::Shape { appearance, .. }, "appearance", Result_::Appearance(m)) => {
                *appearance = Some(m)
            }
            (Kind::Shape { geometry, .. }, "geometry", Result_::Geometry(g)) => *geometry = Some(g),
            (Kind::Appearance { material }, "material", Result_::Material(m)) => {
                *material = Some(m)
            }
            // (Coordinate frames open only in an IndexedFaceSet's `coord`.)
            (Kind::Mesh(m), _, Result_::Coord(c)) => m.coord = Some(c),
            _ => {}
        }
        Ok(())
    }

    /// A closed Shape: a sphere if its geometry is one, in the object space of its Transforms.
    #[inline(always)]
    fn shape_sphere(&mut self, appearance: Option<Option<u32>>, geometry: Option<Geom>) {
        let (center, radius, sat) = match geometry {
            Some(Geom::Sphere(radius, sat)) => (DVec3::ZERO, radius, sat),
            Some(Geom::Mesh(i, sat)) => {
                let (c, r) = self.mesh_fits[i as usize];
                (c, r, sat)
            }
            _ => return,
        };
        let material = match appearance {
            Some(Some(m)) => m,
            _ => 0, // unlit
        };
        self.scene.spheres.push(Sphere {
            center,
            radius,
            material,
            ellipsoid: NO_ELLIPSOID,
            origin: self.origin(sat),
        });
    }

    /// What a closed IndexedFaceSet is: a sphere (see "Tessellated spheres") or other geometry.
    fn mesh_geom(&mut self, m: &MeshState, at: u64) -> Geom {
        // (Only a Shape's geometry is drawn: elsewhere it counts as skipped.)
        let shape = self.in_shape_geometry();
        let fit = m.coord.and_then(|c| {
            let used = m.index.as_deref().is_some_and(|ix| uses_all(ix, c.points));
            c.sphere.filter(|_| shape && used && !m.colored)
        });
        let geom = match fit {
            Some(i) => Geom::Mesh(i, at),
            None => Geom::Other,
        };
        self.count_mesh(geom);
        geom
    }

    fn count_mesh(&mut self, geom: Geom) {
        if let Geom::Mesh(..) = geom {
            self.mesh_spheres += 1;
        } else {
            *self.skipped.entry("IndexedFaceSet".into()).or_default() += 1;
        }
    }

    /// Closes the innermost node in place if it is a Shape, Appearance, Material or Sphere:
    /// what `close` does for them, without moving the frame out (these are most nodes).
    fn close_leaf(&mut self) -> Option<Result_> {
        enum Leaf {
            Shape(Option<Option<u32>>, Option<Geom>),
            Appearance(Option<u32>),
            /// (Its fields are the top of `open_materials`.)
            Material,
            Sphere(f64),
        }
        let frame = self.frames.last()?;
        let at = frame.at;
        let leaf = match frame.kind {
            Kind::Shape {
                appearance,
                geometry,
            } => Leaf::Shape(appearance, geometry),
            Kind::Appearance { material } => Leaf::Appearance(material),
            Kind::Material => Leaf::Material,
            Kind::Sphere { radius } => Leaf::Sphere(radius),
            _ => return None,
        };
        self.frames.truncate(self.frames.len() - 1);
        Some(match leaf {
            Leaf::Shape(appearance, geometry) => {
                self.shape_sphere(appearance, geometry);
                Result_::Nothing
            }
            Leaf::Appearance(material) => Result_::Appearance(material),
            Leaf::Material => Result_::Material(self.close_material()),
            Leaf::Sphere(radius) => Result_::Geometry(Geom::Sphere(radius, at)),
        })
    }

    fn close(&mut self, src: &SourceWindow, frame: Frame) -> Result<Result_, Error> {
        let at = frame.at;
        Ok(match frame.kind {
            Kind::Group {
                inline_urls: Some(ref urls),
                ..
            } => {
                let urls = urls.clone();
                // Load the inlined file inside this group, then close the group over it.
                self.frames.push(frame);
                self.load_inline(src, at, &urls)?;
                let frame = self.frames.pop().expect("inline frame");
                self.close_group_like(src, frame.kind, at)?;
                Result_::Nothing
            }
            Kind::Switch {
                which, ref choices, ..
            } => {
                let chosen = usize::try_from(which)
                    .ok()
                    .and_then(|w| choices.get(w))
                    .cloned();
                let n = choices.len();
                if let Some(range) = chosen {
                    self.frames.push(frame);
                    let saved = std::mem::take(&mut self.recorders);
                    self.reusing += 1;
                    let r = self.replay(src, range, at);
                    self.reusing -= 1;
                    self.recorders = saved;
                    r?;
                    let frame = self.frames.pop().expect("switch frame");
                    self.close_group_like(src, frame.kind, at)?;
                } else {
                    if which >= 0 && which as usize >= n {
                        self.warn(src, at, format!("Switch whichChoice {which} is out of range (0..{n}): nothing shown"));
                    }
                    self.close_group_like(src, frame.kind, at)?;
                }
                Result_::Nothing
            }
            k @ (Kind::Group { .. } | Kind::Lod { .. }) => {
                self.close_group_like(src, k, at)?;
                Result_::Nothing
            }
            Kind::Shape {
                appearance,
                geometry,
            } => {
                self.shape_sphere(appearance, geometry);
                Result_::Nothing
            }
            Kind::Appearance { material } => Result_::Appearance(material),
            Kind::Material => Result_::Material(self.close_material()),
            Kind::Sphere { radius } => Result_::Geometry(Geom::Sphere(radius, at)),
            Kind::Mesh(m) => {
                let geom = self.mesh_geom(&m, at);
                self.last_mesh = Some(MeshCache {
                    geom,
                    nodes: self.nodes - m.nodes_before,
                });
                Result_::Geometry(geom)
            }
            Kind::Coord(c) => Result_::Coord(c),
            Kind::PointLight(l) => {
                self.scene.lights.push(Light::Point(*l));
                Result_::Nothing
            }
            Kind::DirectionalLight(mut l) => {
                let d = l.direction;
                if d.length_squared() == 0.0 || !d.is_finite() {
                    self.warn(src, at, "DirectionalLight direction is zero: using 0 0 -1");
                    l.direction = DVec3::new(0.0, 0.0, -1.0);
                } else {
                    l.direction = d.normalize();
                }
                let idx = self.scene.lights.len();
                self.scene.lights.push(Light::Directional(*l));
                // Scope: the siblings in the enclosing grouping node (set when it closes).
                if let Some(g) = self.frames.iter_mut().rev().find(|f| {
                    matches!(
                        f.kind,
                        Kind::Group { .. } | Kind::Switch { .. } | Kind::Lod { .. }
                    )
                }) {
                    match &mut g.kind {
                        Kind::Group { dirlights, .. }
                        | Kind::Switch { dirlights, .. }
                        | Kind::Lod { dirlights, .. } => {
                            dirlights.get_or_insert_with(Box::default).push(idx)
                        }
                        _ => {}
                    }
                }
                Result_::Nothing
            }
            Kind::Viewpoint(v) => {
                self.scene.viewpoints.push(*v);
                Result_::Nothing
            }
            Kind::NavigationInfo { headlight } => {
                if !self.nav_bound {
                    self.scene.headlight = headlight.unwrap_or(true);
                    self.nav_bound = true;
                }
                Result_::Nothing
            }
            Kind::Background { sky } => {
                if !self.bg_bound {
                    self.scene.background = sky.unwrap_or(DVec3::ZERO);
                    self.bg_bound = true;
                }
                Result_::Nothing
            }
            Kind::Skip | Kind::Quiet => Result_::Nothing,
        })
    }

    /// Closes a grouping node: its matrix applies to everything lowered since it opened, and
    /// its DirectionalLights light exactly that range.
    fn close_group_like(&mut self, src: &SourceWindow, kind: Kind, at: u64) -> Result<(), Error> {
        let (transform, marks, dirlights) = match kind {
            Kind::Group {
                transform,
                marks,
                dirlights,
                ..
            } => (transform, marks, dirlights),
            Kind::Switch {
                marks, dirlights, ..
            }
            | Kind::Lod {
                marks, dirlights, ..
            } => (None, marks, dirlights),
            _ => return Ok(()),
        };
        let end = self.scene.spheres.len() as u32;
        for i in dirlights.into_iter().flat_map(|d| *d) {
            if let Light::Directional(l) = &mut self.scene.lights[i] {
                l.scope = (marks.spheres as u32, end);
            }
        }
        let Some(t) = transform else {
            return Ok(());
        };
        let result = self.close_transform(src, &t, marks, at);
        // Kept for the next Transform (one allocation per nesting level, not per Transform).
        self.spare_transforms.push(t);
        result
    }

    /// Applies a closing Transform's fields to what was lowered inside it (since `marks`).
    #[inline(always)]
    fn close_transform(
        &mut self,
        src: &SourceWindow,
        t: &TransformFields,
        marks: Marks,
        at: u64,
    ) -> Result<(), Error> {
        let shift = translation_only(t);
        if let Some(d) = shift {
            if d.is_finite() && self.only_plain_spheres_since(marks) {
                // What `apply` does for this case, without building the matrix: see there.
                if d == DVec3::ZERO {
                    return Ok(());
                }
                for s in &mut self.scene.spheres[marks.spheres..] {
                    s.center += d;
                    if let Err(what) = check_sphere(s.center, s.radius) {
                        return Err(self.error(src, at, format!("this Transform makes {what}")));
                    }
                }
                return Ok(());
            }
        }
        let m = match shift {
            Some(s) => DAffine3::from_translation(s),
            None => full_transform_matrix(t),
        };
        if m == DAffine3::IDENTITY {
            return Ok(());
        }
        // (An identity linear part, the translation-only case, has determinant 1.)
        let flat = shift.is_none() && m.matrix3.determinant() == 0.0;
        if !m.is_finite() || flat {
            // A zero scale (or a degenerate scaleOrientation) flattens the contents: not shown.
            self.warn(
                src,
                at,
                "a Transform with a zero or non-finite scale hides its contents",
            );
            self.scene.spheres.truncate(marks.spheres);
            self.scene.lights.truncate(marks.lights);
            self.scene.viewpoints.truncate(marks.views);
            return Ok(());
        }
        // Each matrix is finite, but their product may not be: check what the contents became.
        self.apply(&m, shift.is_some(), marks)
            .map_err(|what| self.error(src, at, format!("this Transform makes {what}")))
    }

    /// Whether everything lowered since `marks` is spheres (no ellipsoids, lights or viewpoints).
    fn only_plain_spheres_since(&self, marks: Marks) -> bool {
        self.scene.lights.len() == marks.lights
            && self.scene.viewpoints.len() == marks.views
            && self.scene.spheres[marks.spheres..]
                .iter()
                .all(|s| s.ellipsoid == NO_ELLIPSOID)
    }

    /// Applies `m` to everything lowered since `marks`; says what went out of range, if anything.
    ///
    /// `translation` says the linear part is exactly the identity; a point then moves by
    /// `p + t`, which is exactly what the affine map computes (`1*x + 0*y + 0*z + t`: the
    /// zero terms can only change the sign of a zero, and adding `t`, which has no -0,
    /// gives the same result either way).
    fn apply(&mut self, m: &DAffine3, translation: bool, marks: Marks) -> Result<(), String> {
        let lin = m.matrix3;
        // similarity_scale of the identity is exactly 1.
        let sim = if translation || lin == DMat3::IDENTITY {
            Some(1.0)
        } else {
            similarity_scale(&lin)
        };
        let max_scale = || {
            lin.x_axis
                .length()
                .max(lin.y_axis.length())
                .max(lin.z_axis.length())
        };
        for i in marks.spheres..self.scene.spheres.len() {
            let s = &mut self.scene.spheres[i];
            if s.ellipsoid == NO_ELLIPSOID {
                if let Some(k) = sim {
                    s.center = if translation {
                        s.center + m.translation
                    } else {
                        m.transform_point3(s.center)
                    };
                    s.radius *= k;
                    check_sphere(s.center, s.radius)?;
                    continue;
                }
                let a = *m
                    * DAffine3::from_scale_rotation_translation(
                        DVec3::splat(s.radius),
                        DQuat::IDENTITY,
                        s.center,
                    );
                s.ellipsoid = self.scene.ellipsoids.len() as u32;
                self.scene.ellipsoids.push(a);
            } else {
                let e = &mut self.scene.ellipsoids[s.ellipsoid as usize];
                *e = *m * *e;
            }
            let e = self.scene.ellipsoids[s.ellipsoid as usize];
            s.center = e.translation;
            let l = e.matrix3;
            // A bounding radius: the half extents' length bounds every point of the ellipsoid.
            s.radius = DVec3::new(l.row(0).length(), l.row(1).length(), l.row(2).length()).length();
            check_sphere(s.center, s.radius)?;
            // Rays are intersected in the ellipsoid's object space: the map must be invertible.
            if !e.is_finite() || l.determinant() == 0.0 || !l.determinant().is_finite() {
                return Err("an ellipsoid too thin or too large to represent in f64".into());
            }
        }
        for l in &mut self.scene.lights[marks.lights..] {
            match l {
                Light::Point(p) => {
                    p.location = m.transform_point3(p.location);
                    p.radius *= sim.unwrap_or_else(max_scale);
                    if !p.location.is_finite() || !p.radius.is_finite() {
                        return Err(format!(
                            "a PointLight overflow (location {}, radius {})",
                            p.location, p.radius
                        ));
                    }
                }
                Light::Directional(d) => {
                    d.direction = m.transform_vector3(d.direction).normalize_or(d.direction);
                }
            }
        }
        let views = &mut self.scene.viewpoints[marks.views..];
        if views.is_empty() {
            return Ok(());
        }
        let rot = rotation_part(&lin);
        for v in views {
            v.position = m.transform_point3(v.position);
            v.orientation = (rot * v.orientation).normalize();
            if !v.position.is_finite() {
                return Err(format!("a Viewpoint position overflow ({})", v.position));
            }
        }
        Ok(())
    }

    // ----- PROTO

    fn declare_proto(&mut self, src: &SourceWindow, range: Range<usize>) -> Result<(), Error> {
        if self.in_proto_decl > 0 {
            // Nested in another declaration: it is declared when that body is expanded.
            return Ok(());
        }
        let (name, external, at) = match &self.arena[range.start] {
            Rec::Ev(OwnedEvent::ProtoStart { name, external, at }) => {
                (name.clone(), *external, *at)
            }
            _ => {
                return Err(Error::Other(
                    "internal: PROTO recording without its start".into(),
                ))
            }
        };
        let mut fields: Vec<InterfaceField> = Vec::new();
        let mut i = range.start + 1;
        let mut body = None;
        while i < range.end {
            match &self.arena[i] {
                Rec::Ev(OwnedEvent::Decl {
                    access,
                    ty,
                    name: fname,
                    at,
                }) => {
                    let access_k = Access::from_keyword(access).ok_or_else(|| {
                        self.error(src, *at, format!("unknown access type '{access}'"))
                    })?;
                    let fty = FieldType::from_name(ty).ok_or_else(|| {
                        self.error(src, *at, format!("unknown field type '{ty}'"))
                    })?;
                    let fname = fname.clone();
                    let dat = *at;
                    if fields.iter().any(|f| f.name == fname) {
                        self.warn(src, dat, format!("PROTO {name} declares '{fname}' twice"));
                    }
                    let mut default = None;
                    if !external && matches!(access_k, Access::Field | Access::ExposedField) {
                        // The value events follow the declaration.
                        let vstart = i + 1;
                        let vend = value_end(&self.arena, vstart);
                        if let Some(Rec::Ev(OwnedEvent::Field { value, at: vat, .. })) =
                            self.arena.get(vstart)
                        {
                            if let Err(e) = check_value(fty, &value.as_value()) {
                                return Err(self.error(
                                    src,
                                    *vat,
                                    format!("default of '{fname}' {e}"),
                                ));
                            }
                        }
                        self.resolve_default_uses(src, vstart..vend)?;
                        default = Some(vstart..vend);
                        i = vend - 1;
                    }
                    fields.push(InterfaceField {
                        access: access_k,
                        ty: fty,
                        name: fname,
                        default,
                    });
                }
                Rec::Ev(OwnedEvent::ProtoBody { .. }) => {
                    body = Some(i + 1..range.end - 1);
                    break;
                }
                _ => {}
            }
            i += 1;
        }
        // exposedField x already defines set_x and x_changed.
        for f in &fields {
            if matches!(f.access, Access::EventIn | Access::EventOut) {
                let base = f
                    .name
                    .strip_prefix("set_")
                    .or_else(|| f.name.strip_suffix("_changed"));
                if let Some(b) = base {
                    if fields
                        .iter()
                        .any(|g| &*g.name == b && g.access == Access::ExposedField)
                    {
                        self.warn(
                            src,
                            at,
                            format!(
                                "PROTO {name}: '{}' conflicts with exposedField '{b}'",
                                f.name
                            ),
                        );
                    }
                }
            }
        }
        let mut decl = ProtoDecl {
            name: name.clone(),
            fields,
            body,
            body_events: Rc::from([]),
            body_is: Box::default(),
            first_end: 0,
        };
        if let Some(b) = decl.body.clone() {
            self.check_body(src, &decl, b.clone())?;
            decl.body_events = self.arena[b].into();
            let mut is = Vec::with_capacity(decl.body_events.len());
            let (mut depth, mut protos) = (0i32, 0i32);
            decl.first_end = decl.body_events.len();
            for (k, r) in decl.body_events.iter().enumerate() {
                let mut first_done = false;
                let mut index = u32::MAX;
                match r {
                    Rec::Ev(OwnedEvent::ProtoStart { .. }) => protos += 1,
                    Rec::Ev(OwnedEvent::ProtoEnd { .. }) => protos -= 1,
                    Rec::Ev(OwnedEvent::NodeStart { .. }) if protos == 0 => depth += 1,
                    Rec::Ev(OwnedEvent::NodeEnd { .. }) if protos == 0 => {
                        depth -= 1;
                        first_done = depth == 0;
                    }
                    Rec::Ev(OwnedEvent::Field {
                        value: OwnedValue::Is(t),
                        ..
                    }) if protos == 0 => {
                        index = decl
                            .field_index(t)
                            .and_then(|i| u32::try_from(i).ok())
                            .unwrap_or(u32::MAX);
                    }
                    // A USE as the body's first node.
                    Rec::Used { .. } => first_done = protos == 0 && depth == 0,
                    _ => {}
                }
                is.push(index);
                if first_done {
                    decl.first_end = k + 1;
                    break;
                }
            }
            decl.body_is = is.into();
        }
        let decl = Rc::new(decl);
        self.pinned = self.pinned.max(range.end);
        self.proto_shadows_standard |= schema::node_index(&name).is_some();
        if let Some(s) = self.scopes.last_mut() {
            s.protos.insert(name, decl);
        }
        Ok(())
    }

    /// Resolves the USEs in an interface default value: a DEF earlier in the same value, or a
    /// DEF of the enclosing file made before the declaration. Each default is a namespace of its
    /// own, so a USE of a DEF in another field's default is an error (OpenVRML's test suite).
    fn resolve_default_uses(
        &mut self,
        src: &SourceWindow,
        range: Range<usize>,
    ) -> Result<(), Error> {
        let mut open: Vec<(Option<Rc<str>>, usize)> = Vec::new();
        let mut local: HashMap<Rc<str>, Range<usize>> = HashMap::new();
        let mut protos = 0;
        for i in range {
            let Rec::Ev(ev) = &self.arena[i] else {
                continue;
            };
            match ev {
                OwnedEvent::ProtoStart { .. } => protos += 1,
                OwnedEvent::ProtoEnd { .. } => protos -= 1,
                _ if protos > 0 => {}
                OwnedEvent::NodeStart { def, .. } => open.push((def.clone(), i)),
                OwnedEvent::NodeEnd { .. } => {
                    if let Some((Some(name), start)) = open.pop() {
                        local.insert(name, start..i + 1);
                    }
                }
                OwnedEvent::Use { name, at } => {
                    let at = *at;
                    let found = local
                        .get(name)
                        .cloned()
                        .or_else(|| self.lookup_def(name).map(|d| d.range.clone()));
                    match found {
                        Some(r) => self.arena[i] = Rec::Used { range: r, at },
                        None => {
                            let msg =
                                format!("USE of undefined name '{name}' in a PROTO field default");
                            return Err(self.error(src, at, msg));
                        }
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Checks every `IS` in a PROTO body: the interface field exists, and its type and access
    /// fit the body field (VRML97 4.8.3, Table 4.4).
    fn check_body(
        &mut self,
        src: &SourceWindow,
        decl: &ProtoDecl,
        body: Range<usize>,
    ) -> Result<(), Error> {
        let mut types: Vec<Rc<str>> = Vec::new();
        let mut proto_depth = 0;
        for i in body {
            let Rec::Ev(ev) = &self.arena[i] else {
                continue;
            };
            match ev {
                OwnedEvent::ProtoStart { .. } => proto_depth += 1,
                OwnedEvent::ProtoEnd { .. } => proto_depth -= 1,
                _ if proto_depth > 0 => {}
                OwnedEvent::NodeStart { ty, .. } => types.push(ty.clone()),
                OwnedEvent::NodeEnd { .. } => {
                    types.pop();
                }
                OwnedEvent::Field {
                    name,
                    at,
                    value: super::syntax::OwnedValue::Is(target),
                } => {
                    let Some(iface) = decl.field(target) else {
                        return Err(self.error(
                            src,
                            *at,
                            format!(
                                "'IS {target}': PROTO {} has no interface field '{target}'",
                                decl.name
                            ),
                        ));
                    };
                    let Some(node_ty) = types.last() else {
                        continue;
                    };
                    let Some(spec) = schema::node_spec(node_ty) else {
                        continue;
                    };
                    let Some((f, access)) = spec.event(name) else {
                        continue;
                    };
                    if f.ty != iface.ty {
                        return Err(self.error(
                            src,
                            *at,
                            format!(
                                "'{name} IS {target}': {node_ty}.{name} is {} but interface field '{target}' is {}",
                                f.ty.name(),
                                iface.ty.name()
                            ),
                        ));
                    }
                    let ok = match (iface.access, access) {
                        (Access::ExposedField, a) => a == Access::ExposedField,
                        (Access::Field, a) => matches!(a, Access::Field | Access::ExposedField),
                        (Access::EventIn, a) => matches!(a, Access::EventIn | Access::ExposedField),
                        (Access::EventOut, a) => {
                            matches!(a, Access::EventOut | Access::ExposedField)
                        }
                    };
                    if !ok {
                        self.warn(
                            src,
                            *at,
                            format!(
                                "'{name} IS {target}': a {} cannot be mapped to an interface {}",
                                access.keyword(),
                                iface.access.keyword()
                            ),
                        );
                    }
                }
                OwnedEvent::Field { name, at, .. } | OwnedEvent::NodesStart { name, at } => {
                    let Some(node_ty) = types.last() else {
                        continue;
                    };
                    let Some(spec) = schema::node_spec(node_ty) else {
                        continue;
                    };
                    if let Some((_, access)) = spec.event(name) {
                        let (name, at) = (name.clone(), *at);
                        self.warn_if_event(src, &name, &node_ty.clone(), access, at);
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Expands a recorded PROTO instance: its field values replace `IS` in the body's first node.
    fn expand(
        &mut self,
        src: &SourceWindow,
        proto: Rc<ProtoDecl>,
        inst: Range<usize>,
        at: u64,
    ) -> Result<(), Error> {
        // The instance's fields (skip its NodeStart and NodeEnd).
        let mut values = self.spare_values.pop().unwrap_or_default();
        values.resize(proto.fields.len(), None);
        let mut i = inst.start + 1;
        while i + 1 < inst.end {
            let end = value_end(&self.arena, i);
            let (fname, fat) = match &self.arena[i] {
                Rec::Ev(OwnedEvent::Field { name, at, .. })
                | Rec::Ev(OwnedEvent::NodesStart { name, at }) => (name.clone(), *at),
                _ => {
                    i = end;
                    continue;
                }
            };
            match proto.field_index(&fname) {
                None => self.warn(
                    src,
                    fat,
                    format!("unknown field '{fname}' of PROTO {}: ignored", proto.name),
                ),
                Some(fi) => {
                    let f = &proto.fields[fi];
                    if let Rec::Ev(OwnedEvent::Field { value, .. }) = &self.arena[i] {
                        if f.ty.is_node() {
                            if *value != super::syntax::OwnedValue::Empty {
                                return Err(self.error(
                                    src,
                                    fat,
                                    format!(
                                        "field '{fname}' of PROTO {} expects {}",
                                        proto.name,
                                        f.ty.name()
                                    ),
                                ));
                            }
                        } else if let Err(e) = check_value(f.ty, &value.as_value()) {
                            return Err(self.error(
                                src,
                                fat,
                                format!("field '{fname}' of PROTO {} {e}", proto.name),
                            ));
                        }
                    } else if !f.ty.is_node() {
                        return Err(self.error(
                            src,
                            fat,
                            format!(
                                "field '{fname}' of PROTO {} expects {}, found a node",
                                proto.name,
                                f.ty.name()
                            ),
                        ));
                    }
                    if matches!(f.access, Access::EventIn | Access::EventOut) {
                        self.warn(
                            src,
                            fat,
                            format!(
                                "'{fname}' of PROTO {} is an {}, not a field: ignored",
                                proto.name,
                                f.access.keyword()
                            ),
                        );
                    } else {
                        values[fi] = Some(i..end);
                    }
                }
            }
            i = end;
        }
        // The body runs in a namespace of its own, with this instance's substitutions.
        self.scopes.push(Scope::default());
        self.substs.push(Subst {
            proto: proto.clone(),
            values,
        });
        let saved = std::mem::take(&mut self.recorders);
        let reusing = std::mem::replace(&mut self.reusing, 0);
        let n = proto.first_end;
        let r = self.replay_first_node(src, &proto.body_events[..n], &proto.body_is[..n], at);
        self.reusing = reusing;
        self.recorders = saved;
        if let Some(mut sub) = self.substs.pop() {
            sub.values.clear();
            self.spare_values.push(sub.values);
        }
        self.scopes.pop();
        r
    }

    /// One recorded event of a PROTO body: the common events take the same direct route as in
    /// scene text ([`Sink::event`]), without building an [`Event`] first.
    #[inline(always)]
    fn replay_event(&mut self, src: &SourceWindow, ev: &OwnedEvent) -> Result<(), Error> {
        if self.recorders.is_empty() && self.in_proto_decl == 0 {
            match ev {
                OwnedEvent::NodeStart { def: None, ty, at } => {
                    self.node_start(src, None, ty, *at)?;
                    // (A Switch choice or PROTO instance starts recording at this event.)
                    if !self.recorders.is_empty() {
                        let done = self.end_recorders_slow(&ev.as_event());
                        debug_assert!(done.is_empty());
                    }
                    return Ok(());
                }
                OwnedEvent::NodeEnd { at } => {
                    if self.quiet == 0 {
                        if let Some(result) = self.close_leaf() {
                            return self.deliver(src, result, *at);
                        }
                    }
                    return self.node_end(src, *at, Vec::new());
                }
                OwnedEvent::Field { name, at, value } if !matches!(value, OwnedValue::Is(_)) => {
                    return self.field(src, name, *at, value.as_value())
                }
                OwnedEvent::NodesStart { name, at } => return self.nodes_start(src, name, *at),
                OwnedEvent::NodesEnd { .. } => {
                    self.fields.pop();
                    return Ok(());
                }
                _ => {}
            }
        }
        self.handle(src, ev.as_event())
    }

    /// Replays a PROTO body up to the end of its first node (earlier PROTO declarations
    /// included): `events` and `is` are cut at [`ProtoDecl::first_end`].
    fn replay_first_node(
        &mut self,
        src: &SourceWindow,
        events: &[Rec],
        is: &[u32],
        at: u64,
    ) -> Result<(), Error> {
        for (rec, &is) in events.iter().zip(is) {
            match rec {
                Rec::Ev(ev) => {
                    self.replay_depth += 1;
                    if self.replay_depth > MAX_REPLAY_DEPTH {
                        return Err(self.error(
                            src,
                            at,
                            format!("PROTO expansions nest deeper than {MAX_REPLAY_DEPTH}"),
                        ));
                    }
                    let r = match ev {
                        // `field IS target` of this body: the instance's value, found by index.
                        OwnedEvent::Field { name, at, .. }
                            if is != u32::MAX && self.in_proto_decl == 0 =>
                        {
                            self.substitute_field(src, name, is as usize, *at)
                        }
                        _ => self.replay_event(src, ev),
                    };
                    self.replay_depth -= 1;
                    r?;
                }
                Rec::Used { range, at } => self.use_range(src, range.clone(), *at)?,
            }
        }
        Ok(())
    }

    // ----- ROUTE

    fn check_route(
        &mut self,
        src: &SourceWindow,
        from: &str,
        ff: &str,
        to: &str,
        tf: &str,
        at: u64,
    ) {
        let end = |this: &mut Self, node: &str, field: &str, want_out: bool| -> Option<FieldType> {
            let Some(d) = this.lookup_def(node) else {
                this.warn(src, at, format!("ROUTE refers to undefined node '{node}'"));
                return None;
            };
            let ty = d.ty.clone();
            let found = if let Some(p) = this.lookup_proto(&ty) {
                p.event(field).map(|(f, a)| (f.ty, a))
            } else if let Some(spec) = schema::node_spec(&ty) {
                if &*ty == "Script" {
                    return None;
                }
                spec.event(field).map(|(f, a)| (f.ty, a))
            } else {
                return None;
            };
            let Some((fty, access)) = found else {
                this.warn(
                    src,
                    at,
                    format!("ROUTE: {ty} '{node}' has no event '{field}'"),
                );
                return None;
            };
            let ok = if want_out {
                matches!(access, Access::EventOut | Access::ExposedField)
            } else {
                matches!(access, Access::EventIn | Access::ExposedField)
            };
            if !ok {
                let want = if want_out {
                    "an eventOut"
                } else {
                    "an eventIn"
                };
                this.warn(src, at, format!("ROUTE: '{node}.{field}' is not {want}"));
                return None;
            }
            Some(fty)
        };
        let a = end(self, from, ff, true);
        let b = end(self, to, tf, false);
        if let (Some(a), Some(b)) = (a, b) {
            if a != b {
                self.warn(
                    src,
                    at,
                    format!("ROUTE from {} to {}: the types differ", a.name(), b.name()),
                );
            }
        }
    }
}

/// The end (exclusive) of the value that starts at `i`: one Field, or NodesStart .. NodesEnd.
fn value_end(arena: &[Rec], i: usize) -> usize {
    match arena.get(i) {
        Some(Rec::Ev(OwnedEvent::NodesStart { .. })) => {
            let mut depth = 0;
            let mut k = i;
            while k < arena.len() {
                match &arena[k] {
                    Rec::Ev(OwnedEvent::NodesStart { .. }) => depth += 1,
                    Rec::Ev(OwnedEvent::NodesEnd { .. }) => {
                        depth -= 1;
                        if depth == 0 {
                            return k + 1;
                        }
                    }
                    _ => {}
                }
                k += 1;
            }
            arena.len()
        }
        _ => i + 1,
    }
}

impl Sink for Lowerer {
    #[inline(always)]
    fn event(&mut self, src: &SourceWindow, ev: Event<'_>) -> Result<(), Error> {
        // The common events of plain scene text (nothing recorded, no PROTO declaration open)
        // go straight to their handlers; this is what `handle` does for them.
        if self.recorders.is_empty() && self.in_proto_decl == 0 {
            match ev {
                Event::NodeStart { def: None, ty, at } => {
                    self.node_start(src, None, ty, at)?;
                    // (A Switch choice or PROTO instance starts recording at this event.)
                    if !self.recorders.is_empty() {
                        let done = self.end_recorders_slow(&ev);
                        debug_assert!(done.is_empty());
                    }
                    return Ok(());
                }
                Event::NodeEnd { at } => {
                    if self.quiet == 0 {
                        if let Some(result) = self.close_leaf() {
                            return self.deliver(src, result, at);
                        }
                    }
                    return self.node_end(src, at, Vec::new());
                }
                Event::Field { name, at, value } if !matches!(value, Value::Is(_)) => {
                    return self.field(src, name, at, value)
                }
                Event::NodesStart { name, at } => return self.nodes_start(src, name, at),
                Event::NodesEnd { .. } => {
                    self.fields.pop();
                    return Ok(());
                }
                _ => {}
            }
        }
        self.handle(src, ev)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spheres_stay_small() {
        // A million spheres are 48 MB of IR; Origin is packed into one word for this.
        assert_eq!(std::mem::size_of::<Sphere>(), 48);
        let o = Origin::new(3, 123_456_789_012);
        assert_eq!((o.file(), o.offset()), (3, 123_456_789_012));
        let o = Origin::new(u32::MAX, u64::MAX);
        assert_eq!((o.file(), o.offset()), ((1 << 20) - 1, (1 << 44) - 1));
    }

    #[test]
    fn open_node_frames_stay_small() {
        // Frames are pushed and popped for every node; up to 128 bytes they are moved inline.
        assert!(std::mem::size_of::<Frame>() <= 128);
    }

    #[test]
    fn every_modelled_type_is_a_standard_node() {
        let modelled: Vec<_> = schema::NODES
            .iter()
            .zip(LOWERED)
            .filter(|(_, l)| *l != Lowered::Skipped)
            .map(|(n, _)| n.name)
            .collect();
        assert_eq!(modelled.len(), 19, "{modelled:?}");
        assert_eq!(LOWERED[schema::node_index("LOD").unwrap()], Lowered::Lod);
        assert_eq!(
            LOWERED[schema::node_index("Box").unwrap()],
            Lowered::Skipped
        );
    }

    #[test]
    fn translation_only_matrix_is_the_full_product() {
        // The translation-only shortcut must agree bit for bit with the full product.
        for t in [
            [0.0, 0.0, 0.0],
            [-0.0, 0.0, -0.0],
            [1.5, -2.25, 1e300],
            [-1e-310, 5e-324, -0.0],
            [f64::MAX, -f64::MAX, 0.1],
        ] {
            let fields = TransformFields {
                translation: DVec3::from_array(t),
                ..TransformFields::default()
            };
            let shift = translation_only(&fields).unwrap();
            let fast = DAffine3::from_translation(shift)
                .to_cols_array()
                .map(f64::to_bits);
            let full = full_transform_matrix(&fields)
                .to_cols_array()
                .map(f64::to_bits);
            assert_eq!(fast, full, "{t:?}");
        }
        let rotated = TransformFields {
            rotation: [0.0, 1.0, 0.0, 0.5],
            ..TransformFields::default()
        };
        assert!(translation_only(&rotated).is_none());
    }

    #[test]
    fn moving_a_point_by_a_translation_is_the_affine_map() {
        // Lowerer::apply moves points by `p + t` when the linear part is the identity.
        let vals = [0.0, -0.0, 1.0, -2.5, 1e-310, -1e300, 0.1];
        for &x in &vals {
            for &y in &vals {
                for &t in &vals {
                    let shift = DVec3::new(t, -t, t) + DVec3::ZERO;
                    let m = DAffine3::from_translation(shift);
                    let p = DVec3::new(x, y, -x);
                    let want = m.transform_point3(p).to_array().map(f64::to_bits);
                    assert_eq!(
                        (p + shift).to_array().map(f64::to_bits),
                        want,
                        "{p} {shift}"
                    );
                }
            }
        }
    }
}
