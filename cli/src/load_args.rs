//! Options of `info` and `render` that decide what geometry a scene lowers to.

use clap::Args;

use gtsphere::error::Error;
use gtsphere::vrml::LoadOptions;

#[derive(Debug, Args, Clone, Default)]
pub struct GeometryArgs {
    /// Radius of the spheres that the points of a PointSet (or of an IndexedFaceSet without
    /// faces) become. Default: half the median distance to the nearest other point of the
    /// set, printed as a note.
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub point_radius: Option<f64>,
    /// Draw only spheres (Spheres, tessellated spheres, points): leave out Box, Cylinder,
    /// Cone and the other faces of IndexedFaceSets (counted under `skipped`).
    #[arg(long)]
    pub spheres_only: bool,
    /// Threads that read a large scene file at once (default: as many as the command uses;
    /// 1: one reader; at most four per core). The scene, its order and its warnings are the
    /// same either way.
    #[arg(long, value_name = "N")]
    pub read_threads: Option<usize>,
    /// How far USE, PROTO and IS copies may multiply the scene: to 4194304 nodes and values
    /// plus K per byte of text read, with gzip data inflating to at most 8 K times its
    /// compressed size (plus 16 MiB). Past it, reading stops with an error at the construct
    /// that went over.
    #[arg(long, value_name = "K", default_value_t = gtsphere::vrml::DEFAULT_MAX_EXPANSION)]
    pub max_expansion: u64,
    /// Read every PROTO instance by replaying its body and every sphere node event by event,
    /// without the reader's fast paths (the same scene, for measuring what they save).
    #[arg(long, hide = true)]
    pub replay_every_instance: bool,
}

impl GeometryArgs {
    /// Reads `scene` with `opts` and these options applied, saying (through `say`) the
    /// warning about lowered threads and the reader's warnings and notes.
    pub fn load(
        &self,
        scene: &std::path::Path,
        opts: LoadOptions,
        say: impl Fn(String),
    ) -> Result<(gtsphere::scene::Scene, gtsphere::vrml::LoadReport), Error> {
        let (load, warning) = self.apply(opts)?;
        if let Some(w) = warning {
            say(w);
        }
        let (scene, report) = gtsphere::vrml::load_path(scene, &load)?;
        for w in report.warnings.iter().chain(&report.notes) {
            say(format!("{w}"));
        }
        Ok((scene, report))
    }

    /// `opts` with these options applied, and a warning when `--read-threads` was lowered
    /// to [`limits::max_threads`].
    pub fn apply(&self, opts: LoadOptions) -> Result<(LoadOptions, Option<String>), Error> {
        if let Some(r) = self.point_radius {
            if !(r > 0.0 && r.is_finite()) {
                return Err(Error::Other(format!(
                    "--point-radius must be a positive number, found {r}"
                )));
            }
        }
        let (read_threads, warning) = match self.read_threads {
            Some(asked) => crate::threads::cap("--read-threads", asked),
            None => (opts.read_threads, None),
        };
        let opts = LoadOptions {
            point_radius: self.point_radius,
            spheres_only: self.spheres_only,
            read_threads,
            max_expansion: self.max_expansion,
            replay_every_instance: self.replay_every_instance,
            ..opts
        };
        Ok((opts, warning))
    }
}
