//! Sizes a render cannot hold are refused before anything is allocated, and a cancelled
//! render stops within a tile's time whatever the image size: counted in tiles, not seconds.

use std::sync::atomic::{AtomicU64, Ordering};

use gtsphere::render::{self, limits, Prepared, Progress, RenderOptions};
use gtsphere::Error;

fn spheres() -> Prepared {
    let (scene, _) = crate::support::scene(
        "Shape { geometry Sphere { } }\n\
         Transform { translation 1.5 0 0 children Shape { geometry Sphere { radius 0.5 } } }\n",
    );
    crate::support::prepare(scene)
}

fn invalid(prep: &Prepared, opts: &RenderOptions) -> String {
    let cam = prep.default_camera(64, 48).unwrap();
    match render::render(prep, &cam, opts, &()) {
        Err(Error::Invalid(m)) => m,
        other => panic!("expected Error::Invalid, got {:?}", other.map(|f| f.width)),
    }
}

fn sized(width: u32, height: u32, spp: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        spp,
        ..RenderOptions::default()
    }
}

#[test]
fn samples_per_pixel_beyond_the_bound_are_refused() {
    let prep = spheres();
    let m = invalid(&prep, &sized(4, 4, 1 << 31));
    assert_eq!(m, "spp = 2147483648: at most 1048576 samples per pixel");
    let m = invalid(&prep, &sized(4, 4, limits::MAX_SPP + 1));
    assert!(m.starts_with("spp = 1048577: at most"), "{m}");
}

/// 2^20 x 2^20 pixels need some 70 TB: refused for the memory (or, where the memory
/// available is unknown, when the film cannot be allocated), never an abort.
#[test]
fn an_image_larger_than_the_memory_is_refused() {
    let prep = spheres();
    let m = invalid(&prep, &sized(1 << 20, 1 << 20, 1));
    if limits::available_memory().is_some() {
        assert!(m.starts_with("a 1048576x1048576 image (spp 1, "), "{m}");
        assert!(m.contains(" GB of memory; this machine has "), "{m}");
    }
}

/// (2^31)^2 pixels overflow 32 bits (and their bytes 64): refused, not a panic.
#[test]
fn an_image_whose_size_overflows_is_refused() {
    let prep = spheres();
    let m = invalid(&prep, &sized(1 << 31, 1 << 31, 1));
    assert_eq!(
        m,
        "a 2147483648x2147483648 image (spp 1) needs more memory than can be counted"
    );
}

/// Cancels once `after` tiles are done; counts the tiles done and the tiles that saw the
/// cancel (each stops at the first time it is told).
struct CancelAfter {
    after: u64,
    done: AtomicU64,
    stopped: AtomicU64,
}

impl Progress for CancelAfter {
    fn tile_done(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        let stop = self.done.load(Ordering::Relaxed) >= self.after;
        if stop {
            self.stopped.fetch_add(1, Ordering::Relaxed);
        }
        stop
    }
}

/// After the cancel, only the tiles in flight finish, and a tile that starts later stops at
/// once: of 4096 tiles, a few are done and a few more see the cancel.
#[test]
fn a_cancelled_render_does_no_more_tiles() {
    let prep = spheres();
    let threads = 2;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let opts = sized(1024, 1024, 1);
    let cam = prep.default_camera(1024, 1024).unwrap();
    let stop = CancelAfter {
        after: 3,
        done: AtomicU64::new(0),
        stopped: AtomicU64::new(0),
    };
    let r = pool.install(|| render::render(&prep, &cam, &opts, &stop));
    assert!(matches!(r, Err(Error::Cancelled)));
    let done = stop.done.load(Ordering::Relaxed);
    assert!(done <= 3 + threads as u64, "{done} tiles done");
    // The tiles that started or went on after the cancel: each stopped at its first check
    // (the render itself asks once more at the end).
    let stopped = stop.stopped.load(Ordering::Relaxed);
    assert!(
        stopped <= 16 * threads as u64,
        "{stopped} tiles saw the cancel"
    );
}
