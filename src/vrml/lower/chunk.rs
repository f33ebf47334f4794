//! A chunk of a file read on its own (see [`super::parallel`]): a worker's lowering of it
//! after the prefix, what it hands back ([`Delta`]), and the main reader's putting it in
//! place; with the two watches that decide whether its result may stand (the DEFs it used,
//! the nodes it counted) and the one on the main reader (the names chunks DEF'd).

use std::collections::BTreeMap;
use std::io::{Cursor, Read};
use std::path::Path;
use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::build::transform::Marks;
use super::context::Headroom;
use super::expand::Watch;
use super::Lowerer;
use crate::error::Error;
use crate::input::FileRange;
use crate::scene::{EllipsoidId, Light, LightScope, MaterialTable, Sphere, Surface, Viewpoint};
use crate::source::SourceWindow;
use crate::vrml::parse::{Parser, Run};

/// What a chunk added, moved to the main thread.
pub(super) struct Delta {
    spheres: Vec<Sphere>,
    ellipsoids: Vec<DAffine3>,
    surfaces: Vec<Surface>,
    /// The worker's materials, which `spheres` and `surfaces` refer to.
    materials: MaterialTable,
    lights: Vec<Light>,
    views: Vec<Viewpoint>,
    /// Where the worker's own counts began: its spheres, surfaces, ellipsoids, lights
    /// before the chunk.
    base: Marks,
    ellipsoid_base: usize,
    /// DirectionalLights among the region's siblings (indices into `lights`): scoped by the
    /// group the region is in, when it closes.
    dirlights: Vec<usize>,
    skipped: BTreeMap<String, u64>,
    nodes: u64,
    spent: u64,
    templated: u64,
    whole_nodes: u64,
    pub(super) excess: i64,
    mesh_spheres: u64,
    point_spheres: u64,
    headlight: Option<bool>,
    background: Option<DVec3>,
    pub(super) exports: Vec<String>,
    pub(super) imports: Vec<String>,
    line_starts: Vec<u64>,
    /// Where the region's list ends, if it ends in the chunk (the chunk's result is what
    /// comes before).
    pub(super) end: Option<u64>,
}

/// What a chunk added, or why it may not stand (then the main reader reads on from its
/// start).
pub(super) type Outcome = Result<Box<Delta>, String>;

/// A chunk's text: handed on by the scan, or left in the file, which the chunk's reader
/// reads itself (see [`crate::vrml::cut_file`]).
pub(super) enum ChunkText {
    Held(Vec<u8>),
    InFile(FileRange),
}

/// Lowers one chunk after its prefix, on a worker thread. Returns its text too when it was
/// handed on, for the main reader (None if it could not be had back: then the file is read
/// again).
pub(super) fn lower_chunk(
    opts: &super::LoadOptions,
    (name, path): (&Arc<str>, &Path),
    prefix: &Arc<[u8]>,
    start: u64,
    text: ChunkText,
    (spheres, window): (Vec<Sphere>, &mut String),
) -> (Outcome, Option<Vec<u8>>) {
    let source = match text {
        ChunkText::Held(text) => match String::from_utf8(text) {
            Ok(t) => Source::Text(t),
            // (Its messages would need the text before it.)
            Err(e) => return (Err("it has invalid UTF-8".into()), Some(e.into_bytes())),
        },
        ChunkText::InFile(range) => Source::Reader(range.into_reader(path)),
    };
    let mut low = Lowerer::new(opts.clone());
    // An earlier chunk's list, emptied: its pages are already mapped.
    debug_assert!(spheres.is_empty());
    low.build.scene.spheres = spheres;
    let mut src = SourceWindow::new(name.clone(), Box::new(Cursor::new(prefix.clone())));
    // The window an earlier chunk's reader read through: its pages are already mapped (a
    // new one for each chunk was faulted in again: about 40 ms of CPU per million particles).
    window.clear();
    src.buf = std::mem::take(window);
    let mut opened = low
        .expand
        .open_file(&mut low.cx, &mut low.build, &src, path);
    let mut parser = Parser::new(src);
    parser.pause_at_end = true;
    let r = parser.begin().and_then(|()| parser.resume(&mut low.lent()));
    let held = matches!(source, Source::Text(_));
    let (d, text) = match r {
        Ok(_) => {
            let d = chunk_delta(&mut low, &mut parser, start, source);
            (
                d,
                if held {
                    parser.src.take_text_back(start)
                } else {
                    None
                },
            )
        }
        Err(e) => (
            Err(format!("its prefix: {}", reason(&e))),
            match source {
                Source::Text(t) => Some(t.into_bytes()),
                Source::Reader(_) => None,
            },
        ),
    };
    low.expand.resume_outside(&mut opened);
    *window = std::mem::take(&mut parser.src.buf);
    (d, text)
}

/// Where a chunk's reader reads the chunk from.
enum Source {
    Text(String),
    Reader(Box<dyn Read>),
}

/// `v[from..]`, taken. When `from` is small (the prefix's few), the head is copied out and
/// the tail moved down in place rather than the tail copied out: a new buffer of a chunk's
/// size would be faulted in page by page.
fn tail<T: Clone>(v: &mut Vec<T>, from: usize) -> Vec<T> {
    if from <= v.len() / 2 {
        let mut t = std::mem::take(v);
        v.extend_from_slice(&t[..from]);
        t.drain(..from);
        t
    } else {
        v.split_off(from)
    }
}

/// What went wrong, without a position (a chunk's reader counts lines from its own start).
fn reason(e: &Error) -> String {
    match e {
        Error::Diag(d) => d.message.clone(),
        e => e.to_string(),
    }
}

/// The number of messages in `d`, repeats included.
fn said(d: &[crate::diag::Diagnostic]) -> u64 {
    d.iter().map(|d| 1 + d.repeats).sum()
}

fn chunk_delta(low: &mut Lowerer, parser: &mut Parser, start: u64, text: Source) -> Outcome {
    let base = Marks::of(&low.build.scene);
    let ellipsoid_base = low.build.scene.ellipsoids.len();
    let said_before = (said(&low.cx.diags.warnings), said(&low.cx.diags.notes));
    let skipped_before = low.cx.diags.skipped.clone();
    let meshes_before = (low.build.meshes.spheres, low.build.meshes.point_spheres);
    let bound_before = (low.build.bound.navigation_info, low.build.bound.background);
    let files_before = low.build.scene.files.len();
    let arena_mark = low.expand.rec.arena.len();
    low.expand.rec.pinned = low.expand.rec.pinned.max(arena_mark);
    low.expand.watch = Some(Watch {
        arena_mark,
        imports: Vec::new(),
        nodes_at_start: low.cx.nodes,
        templated_at_start: low.expand.templated,
        whole_at_start: low.build.whole_nodes,
        declared: false,
    });
    low.cx.headroom = Some(Headroom {
        spent_at_start: low.cx.spent,
        excess: i64::MIN,
    });
    let bad_utf8 = parser.src.bad_utf8;
    match text {
        Source::Text(text) => parser.src.jump_to_string(start, text),
        Source::Reader(r) => parser.src.jump(start, r),
    }
    // The chunk's cuts were guessed (see `split`): it must hold whole siblings of the list
    // the prefix leaves open, no more and no less.
    parser.floor = parser.depth();
    // The list may end in it (the region's last chunk): what comes before the end stands,
    // and the main reader reads on from the end.
    let end = match parser.resume(&mut low.lent()).map_err(|e| reason(&e))? {
        Run::Floor => Some(parser.src.offset()),
        _ if parser.depth() != parser.floor => return Err("it ends inside a node".into()),
        _ => None,
    };
    if parser.src.bad_utf8 != bad_utf8 {
        return Err("it has invalid UTF-8".into());
    }
    if (said(&low.cx.diags.warnings), said(&low.cx.diags.notes)) != said_before {
        return Err("it has warnings or notes".into());
    }
    if low.build.scene.files.len() != files_before {
        return Err("it reads another file".into());
    }
    if let Some(why) = low.expand.fallback.take() {
        return Err(why);
    }
    let watch = low.expand.watch.take().expect("watching the chunk");
    let headroom = low.cx.headroom.take().expect("watching the chunk's budget");
    if watch.declared {
        return Err("it declares a PROTO".into());
    }
    let dirlights = low
        .build
        .open
        .innermost_dirlights()
        .and_then(|d| d.as_deref())
        .map_or_else(Vec::new, |d| {
            d.iter()
                .filter(|&&i| i >= base.lights)
                .map(|&i| i - base.lights)
                .collect()
        });
    let mut skipped = low.cx.diags.skipped.clone();
    for (ty, n) in &skipped_before {
        if let Some(m) = skipped.get_mut(ty) {
            *m -= n;
        }
    }
    skipped.retain(|_, n| *n > 0);
    let scene = &mut low.build.scene;
    Ok(Box::new(Delta {
        spheres: tail(&mut scene.spheres, base.spheres),
        ellipsoids: tail(&mut scene.ellipsoids, ellipsoid_base),
        surfaces: tail(&mut scene.surfaces, base.surfaces),
        materials: std::mem::take(&mut scene.materials),
        lights: tail(&mut scene.lights, base.lights),
        views: tail(&mut scene.viewpoints, base.views),
        base,
        ellipsoid_base,
        dirlights,
        skipped,
        nodes: low.cx.nodes - watch.nodes_at_start,
        spent: low.cx.spent - headroom.spent_at_start,
        templated: low.expand.templated - watch.templated_at_start,
        whole_nodes: low.build.whole_nodes - watch.whole_at_start,
        excess: headroom.excess,
        mesh_spheres: low.build.meshes.spheres - meshes_before.0,
        point_spheres: low.build.meshes.point_spheres - meshes_before.1,
        headlight: (!bound_before.0 && low.build.bound.navigation_info).then_some(scene.headlight),
        background: (!bound_before.1 && low.build.bound.background).then_some(scene.background),
        exports: low.expand.scopes.file_defs_since(arena_mark),
        imports: watch.imports,
        line_starts: (parser.src.lines.starts_after(start))
            .take_while(|&l| end.is_none_or(|e| l <= e))
            .collect(),
        end,
    }))
}

impl Delta {
    /// The lines that start in the chunk.
    pub(super) fn lines(&self) -> usize {
        self.line_starts.len()
    }
}

impl Lowerer {
    /// Puts a chunk's result in place, as if its text had been lowered here; gives back its
    /// list of spheres, emptied, for another chunk.
    pub(super) fn put_in_place(
        &mut self,
        mut d: Delta,
        src: &mut SourceWindow,
    ) -> Result<Vec<Sphere>, String> {
        let moved = self.build.scene.materials.append(&d.materials);
        let scene = &mut self.build.scene;
        let (s0, f0, l0) = (
            scene.spheres.len(),
            scene.surfaces.len(),
            scene.lights.len(),
        );
        let e0 = scene.ellipsoids.len();
        scene.ellipsoids.extend(d.ellipsoids);
        // One pass that the compiler turns into a plain copy loop (no capacity check or early
        // return per sphere: a million spheres' push loop was 6 % of a two-thread read's CPU).
        let base = d.ellipsoid_base;
        let mut foreign = false;
        scene.spheres.extend(d.spheres.drain(..).map(|mut s| {
            let p = moved(s.paint());
            (s.material, s.color) = (p.material, p.color);
            if let Some(id) = s.ellipsoid {
                let i = id.index();
                foreign |= i < base;
                s.ellipsoid = EllipsoidId::new((i + e0).wrapping_sub(base));
            }
            s
        }));
        if foreign {
            // (The whole file is then read again by one reader: what was put in place goes.)
            return Err("a sphere of the chunk is an ellipsoid of its prefix".into());
        }
        for mut s in d.surfaces {
            let p = moved(s.paint());
            (s.material, s.color) = (p.material, p.color);
            scene.surfaces.push(s);
        }
        let shift = |r: &mut LightScope, from: usize, to: usize| {
            if let LightScope::Range { start, end } = r {
                *start = (*start as usize - from + to) as u32;
                *end = (*end as usize - from + to) as u32;
            }
        };
        for (i, mut l) in d.lights.into_iter().enumerate() {
            // (The scopes of the region's own DirectionalLights are set when its group closes.)
            let pending = d.dirlights.contains(&i);
            if let (Light::Directional(dl), false) = (&mut l, pending) {
                shift(&mut dl.scope, d.base.spheres, s0);
                shift(&mut dl.surface_scope, d.base.surfaces, f0);
            }
            scene.lights.push(l);
        }
        scene.viewpoints.extend(d.views);
        if !d.dirlights.is_empty() {
            if let Some(dirlights) = self.build.open.innermost_dirlights() {
                let list = dirlights.get_or_insert_with(Box::default);
                list.extend(d.dirlights.iter().map(|i| i + l0));
            }
        }
        if let (Some(h), false) = (d.headlight, self.build.bound.navigation_info) {
            self.build.scene.headlight = h;
            self.build.bound.navigation_info = true;
        }
        if let (Some(b), false) = (d.background, self.build.bound.background) {
            self.build.scene.background = b;
            self.build.bound.background = true;
        }
        for (ty, n) in d.skipped {
            *self.cx.diags.skipped.entry(ty).or_default() += n;
        }
        self.cx.nodes += d.nodes;
        self.cx.spent += d.spent;
        self.expand.templated += d.templated;
        self.build.whole_nodes += d.whole_nodes;
        self.build.meshes.spheres += d.mesh_spheres;
        self.build.meshes.point_spheres += d.point_spheres;
        src.lines_skipped(d.line_starts);
        Ok(d.spheres)
    }
}
