//! Helpers shared by the library's unit tests and the integration tests (`tests/it/`, whose
//! `support` module is this same file): scenes loaded from text, prepared and rendered, the
//! shared corpus, scratch folders, generated pages of docs/, and `Rng`, the one deterministic
//! generator, and a few shapes and scenes both kinds of test build. Built only under
//! `cargo test`. The library is named `gtsphere` here, as the integration tests name it, so
//! the file compiles in both.

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Once;

use glam::DVec3;
use gtsphere::render::{self, Camera, Film, PrepareOptions, Prepared, RenderOptions, View};
use gtsphere::scene::{Material, Scene, Surface, SurfaceShape, Triangle};
// load_str goes through the streaming reader (1 MiB chunks), as files do.
use gtsphere::vrml::{load_str, LoadOptions, LoadReport};

pub fn load(text: &str) -> (Scene, LoadReport) {
    match load_str("test.wrl", text, &LoadOptions::default()) {
        Ok(r) => r,
        Err(e) => panic!("load failed:\n{e}"),
    }
}

/// Loads `#VRML V2.0 utf8` + `body`.
pub fn scene(body: &str) -> (Scene, LoadReport) {
    load(&format!("#VRML V2.0 utf8\n{body}"))
}

/// The error message of a scene that must fail, as printed (`file:line:col: message` ...).
pub fn error_of(text: &str) -> String {
    match load_str("test.wrl", text, &LoadOptions::default()) {
        Ok(_) => panic!("expected an error for:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// `scene` prepared with the default [`PrepareOptions`].
pub fn prepare(scene: Scene) -> Prepared {
    render::prepare(scene, &PrepareOptions::default()).expect("prepare")
}

/// The scene's default camera (its first Viewpoint, or one framing it) at `opts`' size.
pub fn default_camera(prep: &Prepared, opts: &RenderOptions) -> Camera {
    prep.default_camera(opts.width, opts.height)
        .expect("default camera")
}

/// The view `render` traces for `opts` from the scene's default camera (what the integrators
/// take: the lights with the headlight along that camera, the integrator and its tolerance).
pub fn view<'a>(prep: &'a Prepared, opts: &RenderOptions) -> View<'a> {
    prep.view(&default_camera(prep, opts), opts).expect("view")
}

/// `prep` rendered as `opts` say from the scene's default camera.
pub fn render_prepared(prep: &Prepared, opts: &RenderOptions) -> Film {
    render::render(prep, &default_camera(prep, opts), opts, &()).expect("render")
}

/// `scene` prepared with the default [`PrepareOptions`] and rendered as `opts` say from its
/// default camera.
pub fn render_auto(scene: Scene, opts: &RenderOptions) -> Film {
    render_prepared(&prepare(scene), opts)
}

/// A prepared scene with the options it is rendered with, for the tests that call the
/// integrators ray by ray: [`Setup::view`] is the view `render` would trace.
pub struct Setup {
    pub prep: Prepared,
    pub opts: RenderOptions,
}

impl Setup {
    pub fn new(scene: Scene, prepare: &PrepareOptions, opts: RenderOptions) -> Setup {
        Setup {
            prep: render::prepare(scene, prepare).expect("prepare"),
            opts,
        }
    }

    /// The view from the scene's default camera.
    pub fn view(&self) -> View<'_> {
        view(&self.prep, &self.opts)
    }
}

/// `../shared/SUB` beside the checkout (`corpus`, the VRML corpus; `cases/...`, the gas
/// accuracy cases), or `None` when it is not there: the test then returns early, and the
/// first test to find it missing says so once, on the terminal, with where it is expected.
/// When the environment variable `CI` is set (to anything but `false` or `0`), a missing
/// folder fails the test instead, so CI cannot pass without the corpus.
pub fn shared(sub: &str) -> Option<PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    // The checkout's parent, spelt without `..`, for the message.
    let beside = root.parent().unwrap_or(root).join("shared");
    let path = beside.join(sub);
    if path.exists() {
        return Some(path);
    }
    let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
    if ci {
        panic!(
            "{} is missing: the corpus ({}, with corpus/ and cases/) must be beside the \
             checkout, and under CI=true its absence is a failure",
            path.display(),
            beside.display()
        );
    }
    static SAID: Once = Once::new();
    SAID.call_once(|| {
        // Straight to stderr: the test harness captures eprintln! of passing tests.
        let _ = writeln!(
            std::io::stderr(),
            "\nnote: the corpus is absent: {} is not there (expected beside this checkout, \
             holding corpus/ and cases/), so the tests that read it are skipped and pass \
             without checking. Put the shared folder there to run them; with CI=true they \
             fail instead.\n",
            if beside.exists() { &path } else { &beside }.display()
        );
    });
    None
}

/// A fresh, empty directory `group/name` under the target dir's test scratch space (cargo
/// names it for integration tests; unit tests use `target/tmp` of the checkout).
pub fn scratch(group: &str, name: &str) -> std::path::PathBuf {
    let root = option_env!("CARGO_TARGET_TMPDIR")
        .unwrap_or(concat!(env!("CARGO_MANIFEST_DIR"), "/target/tmp"));
    let dir = std::path::Path::new(root).join(group).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// SplitMix64: the tests' one deterministic generator, `Rng(seed)` or `Rng::new(seed)`, the
/// same stream on every run (state = seed, then `state += 0x9E37_79B9_7F4A_7C15` and
/// SplitMix64's output mix per draw).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// 64 random bits.
    pub fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 random bits.
    pub fn f(&mut self) -> f64 {
        (self.u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }

    /// `10^x` with `x` uniform in `[lo, hi)`.
    pub fn log10(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.range(lo, hi))
    }

    /// An integer in `0..n` (`n > 0`), as `floor(f() * n)`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.f() * n as f64) as usize
    }
}

/// A page of docs/ (or a part of one) that code makes: `have` as checked in, `want` as made.
/// With `GTSPHERE_WRITE_DOCS` set (and not `0`), a difference is written by `write`;
/// otherwise it fails, showing the first line that differs and the command `remake` that
/// writes the page anew.
pub fn generated_page(page: &str, have: &str, want: &str, write: impl FnOnce(), remake: &str) {
    if have == want {
        return;
    }
    if std::env::var_os("GTSPHERE_WRITE_DOCS").is_some_and(|v| !v.is_empty() && v != "0") {
        write();
        return;
    }
    let first = have
        .lines()
        .zip(want.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
    panic!(
        "{page} is not what the code makes of it (first difference at line {}:\n  page: \
         {:?}\n  made: {:?}).\nDo not edit it by hand: remake it with\n\n    {remake}\n",
        first + 1,
        have.lines().nth(first).unwrap_or("(end of page)"),
        want.lines().nth(first).unwrap_or("(end of page)"),
    );
}

/// `copies` copies of one triangle in front of a sphere (ids after the sphere's).
pub fn triangles(copies: usize) -> Scene {
    let mut scene = Scene::default();
    scene.add_sphere(DVec3::new(0.0, 0.0, -2.0), 1.0, &Material::default());
    let paint = scene.materials.add(&Material {
        diffuse: DVec3::new(0.1, 0.7, 0.2),
        ..Material::default()
    });
    let t = Triangle {
        p: [
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.5),
        ],
        n: None,
        color: None,
        solid: false,
    };
    for _ in 0..copies {
        scene.surfaces.push(Surface {
            shape: SurfaceShape::Triangle(Box::new(t)),
            color: paint.color,
            material: paint.material,
            origin: Default::default(),
        });
    }
    scene
}

/// The 12 vertices of an icosahedron (cyclic permutations of (0, +-1, +-phi)), unit radius.
pub fn icosahedron() -> Vec<DVec3> {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v = Vec::new();
    for a in [-1.0, 1.0] {
        for b in [-phi, phi] {
            v.push(DVec3::new(0.0, a, b));
            v.push(DVec3::new(a, b, 0.0));
            v.push(DVec3::new(b, 0.0, a));
        }
    }
    v.into_iter().map(|p| p.normalize()).collect()
}

/// A unit UV sphere: both poles and `rings` latitudes of `seg` points up to `max_theta`.
pub fn uv_sphere(rings: usize, seg: usize, max_theta: f64) -> Vec<DVec3> {
    let mut v = vec![DVec3::Z];
    for i in 1..=rings {
        let th = max_theta * i as f64 / (rings + 1) as f64;
        for j in 0..seg {
            let ph = std::f64::consts::TAU * j as f64 / seg as f64;
            v.push(DVec3::new(
                th.sin() * ph.cos(),
                th.sin() * ph.sin(),
                th.cos(),
            ));
        }
    }
    if max_theta >= std::f64::consts::PI {
        v.push(-DVec3::Z);
    }
    v
}

/// GasParticle as `convert` and the VRML writer declare it.
pub const GAS_PARTICLE_PROTO: &str = "PROTO GasParticle [
  field SFVec3f position 0 0 0
  field SFFloat radius 1
  field SFColor color 0.8 0.8 0.8
  field SFColor emission 0 0 0
  field SFFloat transparency 0.5
  field SFString profile \"constant\"
  field SFFloat width 0.3333333333333333
] {
  Transform {
    translation IS position
    children Shape {
      appearance Appearance {
        material Material { diffuseColor IS color emissiveColor IS emission transparency IS transparency }
      }
      geometry Sphere { radius IS radius }
    }
  }
}
";
