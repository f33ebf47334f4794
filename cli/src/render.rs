//! `gtsphere render SCENE [-o OUT]`: raw arguments, their validation into
//! [`RenderOptions`], and the run.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, ValueEnum};

use gtsphere::error::Error;
use gtsphere::output::{format_for, write_film, write_part, Format, Placement};
use gtsphere::render::{
    limits, prepare, pymol_export, render_view, Aovs, CameraChoice, FovAcross, Integrator,
    PrepareOptions, Projection, RenderOptions, SamplerKind,
};
use gtsphere::scene::Profile;
use gtsphere::vrml::LoadOptions;

pub(crate) mod ao;
pub(crate) mod progress;
use progress::TileBar;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SamplerArg {
    /// `--spp` stratified samples over each pixel's square: a jittered grid when --spp is a
    /// square number, otherwise Latin hypercube.
    Stratified,
    /// One sample at each pixel's exact centre, for value-by-value comparisons (with
    /// `--integrator mc` on gas, --spp paths through the centre).
    Center,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum AovArg {
    /// Ray parameter (distance) of the first opaque hit through the pixel centre; +inf on a miss.
    Depth,
    /// World-space unit normal there (channels normal.X/Y/Z); 0 on a miss.
    Normal,
    /// Index of the sphere in file order; -1 on a miss (exact up to 2^24 spheres).
    Id,
    /// The pixel's estimated absolute error (exact: mean of its samples' error estimates,
    /// truncation bounds included, an upper estimate; mc, and ao by `--ao-method mc`: standard
    /// error of its mean; exact AO: 0, or among cylinders and cones a bound within --tol; 0
    /// for the other AO approximations, whose error is not estimated).
    Error,
    /// Exact ambient occlusion at the first opaque hit through the pixel centre, with
    /// --ao-reach and --ao-weighting, whatever the integrator draws; NaN on a miss (opaque
    /// spheres, triangles and boxes, and to --tol closed cylinders and cones, as --integrator
    /// ao).
    Ao,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IntegratorArg {
    /// Closed-form emission/absorption, single scattering to --tol (adaptive Gauss-Kronrod
    /// between the shadow-boundary breakpoints).
    Exact,
    /// Fixed-step ray marching with midpoint samples (needs --step): an approximation.
    March,
    /// Unbiased Monte Carlo (scattering sampled at one point per gas segment), --spp samples
    /// per pixel.
    Mc,
    /// Ambient occlusion as the picture: the unoccluded fraction at each visible point,
    /// exact for opaque spheres, triangles and boxes (to --tol among cylinders and cones)
    /// or by a named approximation (see
    /// --ao-method, --ao-reach, --ao-colours).
    Ao,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FovAcrossArg {
    /// The smaller side, as VRML97 defines fieldOfView.
    Smaller,
    /// The image width (what PyMOL's VRML export writes).
    Width,
    /// The image height.
    Height,
}

impl From<FovAcrossArg> for FovAcross {
    fn from(a: FovAcrossArg) -> Self {
        match a {
            FovAcrossArg::Smaller => FovAcross::Smaller,
            FovAcrossArg::Width => FovAcross::Width,
            FovAcrossArg::Height => FovAcross::Height,
        }
    }
}

/// What `info` and `render` say of a scene whose Viewpoint is a PyMOL export's
/// ([`pymol_export`]).
pub const PYMOL_FOV_NOTE: &str = "the Viewpoint \"Z view\" is a PyMOL export's: PyMOL writes \
    fieldOfView as the angle across the image width, gtsphere reads it across the smaller side \
    (VRML97); render --fov-across width frames the scene as PyMOL shows it";

/// Arguments of `gtsphere render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// Scene file (.wrl, .wrz, .wrl.gz; gzip is detected by content).
    pub scene: PathBuf,
    /// Output image: .png (sRGB, 8-bit), .exr (linear float RGBA + AOVs), .pfm (linear RGB) or
    /// .npy (linear RGB as a float64 H x W x 3 NumPy array: the film's values unrounded).
    /// Default: the scene's name with .png, in the current directory.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Image width in pixels (at most 65536; an image whose buffers do not fit in the
    /// memory available is refused before the scene is read).
    #[arg(long, default_value_t = 800)]
    pub width: u32,
    /// Image height in pixels (at most 65536).
    #[arg(long, default_value_t = 600)]
    pub height: u32,
    /// Samples per pixel, placed as --sampler says and averaged (a box filter); with
    /// `--integrator mc`, the paths per pixel. At most 1048576.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Seed of the sample positions; the same seed gives the same image on any thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How samples are placed in a pixel.
    #[arg(long, value_enum, default_value_t = SamplerArg::Stratified)]
    pub sampler: SamplerArg,
    /// Orthographic projection (parallel rays along the view direction).
    #[arg(long)]
    pub ortho: bool,
    /// World size of the smaller image side for --ortho (default: fit the scene's bounds).
    #[arg(long, requires = "ortho")]
    pub ortho_height: Option<f64>,
    /// Use the Viewpoint with this DEF name or description.
    #[arg(long, conflicts_with = "vrml_default_camera")]
    pub viewpoint: Option<String>,
    /// Use VRML's fixed default camera at (0,0,10) looking down -z with fieldOfView pi/4,
    /// whatever Viewpoints the scene has. Without it, a scene without a Viewpoint is seen by a
    /// camera looking down -z that frames the scene's bounds.
    #[arg(long)]
    pub vrml_default_camera: bool,
    /// Read the Viewpoint's fieldOfView as the angle across this side of the image (default:
    /// smaller, as VRML97 defines it). PyMOL's VRML export writes the angle across the width:
    /// `--fov-across width` frames such a file as PyMOL shows it (`info` and `render` say when
    /// a file is one).
    #[arg(
        long,
        value_enum,
        value_name = "SIDE",
        conflicts_with_all = ["ortho", "vrml_default_camera"]
    )]
    pub fov_across: Option<FovAcrossArg>,
    /// Render the headlight as a strict DirectionalLight along the view, casting shadows. By
    /// default it is carried by the viewer, as in VRML browsers: it lights what the camera
    /// sees, through the gas in front, and casts no shadow.
    #[arg(long)]
    pub headlight_shadows: bool,
    /// Worker threads (default: one per core; more than four per core are lowered to that,
    /// with a warning); they also read the scene, unless --read-threads says otherwise.
    #[arg(long)]
    pub threads: Option<usize>,
    /// How camera rays are integrated: gas by exact, march or mc (scenes without gas render
    /// the same with all three), or ambient occlusion as the picture (ao).
    #[arg(long, value_enum, default_value_t = IntegratorArg::Exact)]
    pub integrator: IntegratorArg,
    /// Step length (world units) of `--integrator march`.
    #[arg(long)]
    pub step: Option<f64>,
    #[command(flatten)]
    pub ao: ao::AoArgs,
    /// Target error of `--integrator exact`, relative to the pixel's value (absolute floor
    /// `tol * 1e-3`). What cannot change a ray within it (gas behind a large optical depth,
    /// light paths through it) is bounded instead of computed, and the bound is in the error
    /// AOV. With exact AO (--integrator ao, --aov ao): the largest error of the unoccluded
    /// fraction where cylinders or cones occlude, as an absolute bound.
    #[arg(long, default_value_t = 1e-4)]
    pub tol: f64,
    /// Make every sphere a ball of gas with this extinction (per world unit); emission is the
    /// material's emissiveColor, albedo its diffuseColor.
    #[arg(long)]
    pub as_gas: Option<f64>,
    /// Give every gas sphere (with --as-gas, every sphere) this density profile, whatever the
    /// scene says: constant, linear, quadratic or gaussian, the gaussian's width as
    /// `gaussian:0.25` (in units of the radius, default 1/3).
    #[arg(long, value_name = "NAME[:WIDTH]")]
    pub profile: Option<String>,
    /// Extra channels of an .exr output, comma-separated.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub aov: Vec<AovArg>,
    /// Turn every warning of the reader into an error.
    #[arg(long)]
    pub strict: bool,
    /// Do not read other files (Inline nodes, EXTERNPROTO files).
    #[arg(long)]
    pub no_inline: bool,
    #[command(flatten)]
    pub geometry: crate::load_args::GeometryArgs,
    /// Render only the pixels x0..x1, y0..y1 (columns x0 to x1-1, rows y0 to y1-1, row 0 at
    /// the top), exactly as the whole render would; the output must be .exr and records where
    /// the part goes (`gtsphere merge` assembles parts).
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "X0,Y0,X1,Y1",
        conflicts_with = "tile"
    )]
    pub region: Option<Vec<u32>>,
    /// Render band K of N (K from 1 to N) of the image's rows, for job arrays; as --region.
    #[arg(long, value_name = "K/N")]
    pub tile: Option<String>,
    /// Print work counters and timings.
    #[arg(long)]
    pub stats: bool,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The output path: as given, or `<scene stem>.png` in the current directory.
fn output_path(args: &RenderArgs) -> PathBuf {
    args.output.clone().unwrap_or_else(|| {
        let name = args
            .scene
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "render".into());
        // scene.wrl, scene.wrz, scene.wrl.gz -> scene.png
        let stem = name
            .strip_suffix(".gz")
            .unwrap_or(&name)
            .rsplit_once('.')
            .map(|(s, _)| s.to_string())
            .unwrap_or_else(|| name.clone());
        PathBuf::from(format!("{stem}.png"))
    })
}

/// Checks the raw arguments and builds the library's options.
pub fn options(args: &RenderArgs, out: &Path) -> Result<Plan, Error> {
    let bad = |m: String| Error::Other(m);
    let format = format_for(out)?;
    if args.width == 0 || args.height == 0 || args.width > 65_536 || args.height > 65_536 {
        return Err(bad(format!(
            "--width and --height must be between 1 and 65536 (got {}x{})",
            args.width, args.height
        )));
    }
    if args.spp == 0 || args.spp > limits::MAX_SPP {
        return Err(bad(format!(
            "--spp must be between 1 and {} (got {})",
            limits::MAX_SPP,
            args.spp
        )));
    }
    if let Some(h) = args.ortho_height {
        if !(h.is_finite() && h > 0.0) {
            return Err(bad(format!(
                "--ortho-height must be a positive number (got {h})"
            )));
        }
    }
    let (threads, threads_warning) = crate::threads::option(args.threads)?;
    let aovs = Aovs {
        depth: args.aov.contains(&AovArg::Depth),
        normal: args.aov.contains(&AovArg::Normal),
        id: args.aov.contains(&AovArg::Id),
        error: args.aov.contains(&AovArg::Error),
        ao: args.aov.contains(&AovArg::Ao),
    };
    let integrator = match (args.integrator, args.step) {
        (IntegratorArg::March, Some(h)) if h.is_finite() && h > 0.0 => {
            Integrator::March { step: h }
        }
        (IntegratorArg::March, Some(h)) => {
            return Err(bad(format!("--step must be a positive number (got {h})")));
        }
        (IntegratorArg::March, None) => {
            return Err(bad("--integrator march needs --step H (world units)".into()));
        }
        (_, Some(_)) => return Err(bad("--step is only for --integrator march".into())),
        (IntegratorArg::Exact, None) => Integrator::Exact,
        (IntegratorArg::Mc, None) => Integrator::Mc,
        (IntegratorArg::Ao, None) => Integrator::Ao(args.ao.settings().map_err(bad)?),
    };
    if args.integrator != IntegratorArg::Ao {
        args.ao.check_unused(aovs.ao).map_err(bad)?;
    }
    // The ao channel's reach and weighting (its method is the exact one).
    let ao = if aovs.ao {
        args.ao.settings().map_err(bad)?
    } else {
        Default::default()
    };
    if !(args.tol.is_finite() && args.tol > 0.0 && args.tol < 1.0) {
        return Err(bad(format!(
            "--tol must be between 0 and 1 (got {})",
            args.tol
        )));
    }
    if let Some(s) = args.as_gas {
        if !(s.is_finite() && s >= 0.0) {
            return Err(bad(format!(
                "--as-gas must be a finite extinction >= 0 (got {s})"
            )));
        }
    }
    let profile = match &args.profile {
        None => None,
        Some(s) => Some(parse_profile(s).map_err(|e| bad(format!("--profile {s}: {e}")))?),
    };
    if (aovs.any() || aovs.error) && format != Format::Exr {
        return Err(bad(format!(
            "--aov needs an .exr output; {} cannot hold extra channels",
            out.display()
        )));
    }
    let region = match (&args.region, &args.tile) {
        (Some(r), _) => {
            let &[x0, y0, x1, y1] = r.as_slice() else {
                return Err(bad(format!(
                    "--region takes four numbers x0,y0,x1,y1 (got {})",
                    r.len()
                )));
            };
            if !(x0 < x1 && y0 < y1 && x1 <= args.width && y1 <= args.height) {
                return Err(bad(format!(
                    "--region {x0},{y0},{x1},{y1} is empty or outside the {}x{} image",
                    args.width, args.height
                )));
            }
            Some((x0, y0, x1, y1))
        }
        (None, Some(t)) => {
            let parsed = t.split_once('/').and_then(|(k, n)| {
                Some((k.trim().parse::<u32>().ok()?, n.trim().parse::<u32>().ok()?))
            });
            let Some((k, n)) = parsed.filter(|&(k, n)| k >= 1 && k <= n && n <= args.height) else {
                return Err(bad(format!(
                    "--tile must be K/N with 1 <= K <= N <= the image height (got {t})"
                )));
            };
            // Band k of n: rows floor((k-1) H / n) .. floor(k H / n).
            let h = u64::from(args.height);
            let y0 = ((u64::from(k) - 1) * h / u64::from(n)) as u32;
            let y1 = (u64::from(k) * h / u64::from(n)) as u32;
            Some((0, y0, args.width, y1))
        }
        (None, None) => None,
    };
    if region.is_some() && format != Format::Exr {
        return Err(bad(format!(
            "--region and --tile write a part of the picture, which needs an .exr output (got {})",
            out.display()
        )));
    }
    let opts = RenderOptions {
        region,
        width: args.width,
        height: args.height,
        spp: args.spp,
        seed: args.seed,
        sampler: match args.sampler {
            SamplerArg::Stratified => SamplerKind::Stratified,
            SamplerArg::Center => SamplerKind::Center,
        },
        aovs,
        integrator,
        tol: args.tol,
        headlight_shadows: args.headlight_shadows,
        ao,
    };
    // Sizes, samples and the memory they need, before the scene is read: the pool the
    // render runs on has `threads` workers, or one per core.
    let workers = threads.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    opts.validate_on(workers)?;
    Ok(Plan {
        opts,
        threads,
        threads_warning,
        camera: match (&args.viewpoint, args.vrml_default_camera) {
            (Some(n), _) => CameraChoice::Named(n.clone()),
            (None, true) => CameraChoice::VrmlDefault,
            (None, false) => CameraChoice::Auto,
        },
        projection: if args.ortho {
            Projection::Ortho {
                height: args.ortho_height,
            }
        } else {
            Projection::Perspective {
                fov_across: args.fov_across.map_or(FovAcross::Smaller, FovAcross::from),
            }
        },
        prepare: PrepareOptions {
            as_gas: args.as_gas,
            profile,
        },
    })
}

/// `NAME` or `NAME:WIDTH` as a profile.
pub fn parse_profile(s: &str) -> Result<Profile, String> {
    let (name, width) = match s.split_once(':') {
        None => (s, None),
        Some((name, w)) => {
            let w: f64 = w
                .parse()
                .map_err(|_| format!("the width `{w}` is not a number"))?;
            (name, Some(w))
        }
    };
    Profile::parse(name, width).map_err(|e| e.to_string())
}

/// The validated arguments: how to prepare the scene, which camera, how to render.
pub struct Plan {
    pub opts: RenderOptions,
    pub camera: CameraChoice,
    pub projection: Projection,
    pub prepare: PrepareOptions,
    /// Worker threads (`--threads`, at most [`limits::max_threads`]; `None`: one per core).
    pub threads: Option<usize>,
    /// Why `--threads` was lowered, if it was.
    pub threads_warning: Option<String>,
}

pub fn run(args: &RenderArgs) -> Result<ExitCode, Error> {
    let out = output_path(args);
    let plan = options(args, &out)?;
    let opts = &plan.opts;
    let say = |m: String| {
        if !args.quiet {
            eprintln!("{m}");
        }
    };
    if let Some(w) = &plan.threads_warning {
        say(w.clone());
    }
    // Reading comes before the pool, but --threads bounds it too (unless --read-threads).
    let load = LoadOptions {
        strict: args.strict,
        inline: !args.no_inline,
        read_threads: plan.threads.unwrap_or(0),
        ..LoadOptions::default()
    };
    let (scene, report) = args.geometry.load(&args.scene, load, say)?;
    if plan.camera == CameraChoice::Auto && scene.viewpoints.is_empty() {
        unframable(&scene)?;
    }
    let spheres = scene.spheres.len();
    let surfaces = scene.surfaces.len();
    let scene_counts = scene.surface_counts();
    let headlight = scene.headlight;
    let in_scene = |e: Error| Error::Other(format!("{}: {e}", args.scene.display()));
    // Every stage after reading (the BVH build, the lights' grids, the render) runs on the
    // pool, so that --threads bounds all of them.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(plan.threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::Other(format!("cannot start worker threads: {e}")))?;
    let prep = pool
        .install(|| prepare(scene, &plan.prepare))
        .map_err(in_scene)?;
    let (camera, description) = prep
        .camera(&plan.camera, plan.projection, opts.width, opts.height)
        .map_err(in_scene)?;
    if args.fov_across.is_none()
        && !args.ortho
        && plan.camera != CameraChoice::VrmlDefault
        && pymol_export(&prep.viewpoints)
    {
        say(format!("{}: {PYMOL_FOV_NOTE}", args.scene.display()));
    }
    // The view `render` traces (camera rays, the lights with the headlight along this camera),
    // made once: its lights are counted here.
    let view = pool
        .install(|| prep.view(&camera, opts))
        .map_err(in_scene)?;
    say(format!(
        "{}: {} spheres{}, {} lights{}; camera: {}",
        args.scene.display(),
        spheres,
        if surfaces > 0 {
            format!(", {surfaces} other surfaces")
        } else {
            String::new()
        },
        view.light_count(),
        if headlight {
            " (headlight included)"
        } else {
            ""
        },
        description
    ));
    if let Integrator::Ao(settings) = opts.integrator {
        say(ao::describe(&settings, view.ao_grid()));
    } else if prep.gas_spheres > 0 {
        say(format!(
            "{} gas spheres; integrator {}",
            prep.gas_spheres,
            match opts.integrator {
                Integrator::Exact => format!("exact (tol {:e})", opts.tol),
                Integrator::March { step } => format!("march (step {step}; an approximation)"),
                Integrator::Mc => format!("mc ({} paths per pixel)", opts.spp),
                Integrator::Ao(_) => unreachable!("said above"),
            }
        ));
    }
    let exact_ao = match opts.integrator {
        Integrator::Ao(a) => Some(a).filter(|a| a.method == gtsphere::render::ao::AoMethod::Exact),
        _ => opts.aovs.ao.then_some(opts.ao),
    };
    if let Some(note) = exact_ao.and_then(|a| ao::cost_note(&a, &scene_counts)) {
        say(note);
    }
    if let Some(note) = exact_ao.and_then(|a| ao::gas_note(&a, prep.gas_spheres)) {
        say(note);
    }
    let bar = TileBar::new(!args.quiet);
    let done = pool.install(|| render_view(&view, opts, &bar))?;
    match opts.region {
        Some((x0, y0, _, _)) => write_part(
            &out,
            &done.image(),
            Placement {
                x: x0 as usize,
                y: y0 as usize,
                full_width: opts.width as usize,
                full_height: opts.height as usize,
            },
        )?,
        None => write_film(&out, &done)?,
    }
    say(format!(
        "wrote {} ({}x{}, {} spp) in {:.2} s (load {:.2} s, BVH {:.2} s)",
        out.display(),
        opts.width,
        opts.height,
        if opts.sampler == SamplerKind::Center {
            1
        } else {
            opts.spp
        },
        done.seconds,
        report.seconds,
        prep.prepare_time.as_secs_f64()
    ));
    if args.stats {
        let c = done.counters;
        println!("camera rays        {}", c.camera_rays);
        println!("shadow rays        {}", c.shadow_rays);
        println!("quadrature nodes   {}", c.quadrature_nodes);
        println!("shadowing spheres  {}", c.shadow_candidates);
        println!("max pixel error    {:e}", done.max_error);
        println!(
            "rays per second    {:.0}",
            (c.camera_rays + c.shadow_rays) as f64 / done.seconds.max(1e-9)
        );
        println!("load seconds       {:.3}", report.seconds);
        println!("read pieces        {}", report.read_pieces);
        println!("render seconds     {:.3}", done.seconds);
        println!("prepare seconds    {:.3}", prep.prepare_time.as_secs_f64());
        if let Some((seconds, bytes)) = view.grids() {
            println!("light grids seconds {:.3}", seconds.as_secs_f64());
            println!("light grids bytes  {bytes}");
        }
        println!(
            "BVH build seconds  {:.3}",
            prep.bvh_build_time().as_secs_f64()
        );
        println!("BVH + prims bytes  {}", prep.bvh_bytes());
        if let Some(p) = crate::memory::peak_rss_bytes() {
            println!("peak resident      {p}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// A scene without a Viewpoint that no camera can frame (it reaches near the largest f64):
/// refused before the BVH is built, at the item that reaches farthest.
fn unframable(scene: &gtsphere::scene::Scene) -> Result<(), Error> {
    let Some((c, r)) = scene.bounding_ball() else {
        return Ok(());
    };
    if gtsphere::scene::framing_position(c, r).is_some() {
        return Ok(());
    }
    let reach = |p: glam::DVec3, r: f64| p.abs().max_element() + r;
    let sphere = (scene.spheres.iter()).map(|s| (reach(s.center, s.radius), s.origin));
    let surface = (scene.surfaces.iter()).map(|s| {
        let (p, r) = s.bounding_ball();
        (reach(p, r), s.origin)
    });
    let far = sphere.chain(surface).max_by(|a, b| a.0.total_cmp(&b.0));
    let at = far.map_or(String::new(), |(_, o)| format!("{}: ", scene.position(o)));
    Err(Error::Invalid(format!(
        "{at}the scene reaches this far from the origin: a camera framing it would stand beyond \
         the range of f64; give the scene a Viewpoint"
    )))
}
