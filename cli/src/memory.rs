//! What the process itself uses, for the reports of `info`, `render --stats` and `bench`.

/// Peak resident memory of this process so far (Linux `VmHWM`), in bytes.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Fixes glibc's mmap threshold at 32 MiB. By default glibc raises the threshold to the size
/// of each large block freed (up to 32 MiB), so the BVH build's per-chunk buffers, freed and
/// allocated again for every chunk, end up in each worker thread's heap and stay resident
/// there. Measured 2026-12-02, rendering 1e7 particles on 2 threads: peak 1053 MB by default,
/// 961 MB with this, the build as fast (3.8 s). A lower threshold frees still more but
/// doubles the build (7.4 s at 8 MiB): every chunk then faults its buffers in afresh.
#[allow(unsafe_code)] // the one call into libc; the workspace denies unsafe code elsewhere
pub fn tune_allocator() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets a parameter of the allocator; called once at start-up,
        // before any other thread exists.
        unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        }
    }
}

/// Freed memory kept at the top of each heap while a scene is read (see
/// [`retain_freed_while_reading`]).
const RETAIN_WHILE_READING: i32 = 16 << 20;

/// glibc's own trim threshold, for [`retain_freed_for`] to go back to.
const DEFAULT_TRIM: i32 = 128 << 10;

/// Lets glibc keep up to 16 MiB of freed memory at the top of each heap while a scene is
/// read. Reading on several threads, each piece's tables (its materials, their hashes, its
/// line starts: a few hundred KB) are freed by the main thread into the heap of the thread
/// that made them, which gave the memory back to the system every time (an `madvise` or a
/// `brk` down) and faulted it in afresh for the next piece. Measured 2026-12-05, `info` of the
/// 1e6-particle files of `bench parse` on 2 threads, in turns with the default (21 rounds
/// each): parse time 0.961-0.972 of it at 16 MiB (0.98 at 4 MiB); one reader unchanged.
/// [`retain_freed_for`] sets the threshold for what follows the reading.
#[allow(unsafe_code)] // as tune_allocator
pub fn retain_freed_while_reading() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: as in tune_allocator; glibc serialises mallopt against other threads.
        unsafe {
            libc::mallopt(libc::M_TRIM_THRESHOLD, RETAIN_WHILE_READING);
        }
    }
}

/// Scenes below this many spheres keep freed memory for reuse during the BVH build (see
/// [`retain_freed_for`]).
const RETAIN_BELOW_SPHERES: usize = 4_000_000;

/// Lets glibc keep up to 64 MiB of freed memory at the top of each heap, for scenes of fewer
/// than [`RETAIN_BELOW_SPHERES`] spheres; larger scenes go back to glibc's default (128 KiB),
/// and what the reading kept (see [`retain_freed_while_reading`]) is given back at once.
///
/// With the mmap threshold fixed (see [`tune_allocator`]), glibc returns every freed block
/// above 128 KiB at the top of a heap to the system, so each BVH chunk's temporaries (about
/// 40 MB per 125 000 spheres, below the mmap threshold) are faulted in and zeroed afresh.
/// Measured 2026-12-02 on `benches/tachyon`'s 1e6-sphere scene: the build took 0.40-0.45 s
/// instead of 0.55-0.62 s on one thread (0.30 against 0.41 s on two), and peak memory rose
/// from 101 to 107 MB (145 to 187 MB on two threads). At 1e7 spheres the chunks' large
/// buffers are mapped and unmapped whatever this says, the build was not faster, and keeping
/// 64 MiB per thread raised the peak by 130 MB (to 104 bytes per sphere): hence the bound.
#[allow(unsafe_code)] // as tune_allocator
pub fn retain_freed_for(spheres: usize) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    if spheres < RETAIN_BELOW_SPHERES {
        // SAFETY: as in tune_allocator; glibc serialises mallopt against other threads.
        unsafe {
            libc::mallopt(libc::M_TRIM_THRESHOLD, 64 << 20);
        }
    } else {
        // SAFETY: as above; malloc_trim only gives free memory back to the system.
        unsafe {
            libc::mallopt(libc::M_TRIM_THRESHOLD, DEFAULT_TRIM);
            libc::malloc_trim(0);
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    let _ = spheres;
}
