//! SIGINT and SIGTERM: the command removes the output files it is writing and exits with
//! 128 + the signal's number (130 and 143, as shells report a process a signal stopped).
//!
//! The signals are received by a thread of the command's own (signal-hook's iterator; the
//! handler itself only wakes it), which tells the render to stop, removes the temporary files
//! of unfinished outputs ([`gtsphere::output::remove_unfinished`]) and exits; a write in
//! progress at that moment never reaches its rename. The render stops as soon as a signal was
//! received ([`received`]); `main` then leaves the exit to that thread. Elsewhere than on Unix
//! no handler is installed.

use std::process::ExitCode;
use std::sync::atomic::{AtomicI32, Ordering};

/// The signal received, or 0.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// Whether SIGINT or SIGTERM was received: the render's cancellation flag.
pub fn received() -> bool {
    RECEIVED.load(Ordering::Relaxed) != 0
}

/// Starts the thread that waits for SIGINT and SIGTERM.
#[cfg(unix)]
pub fn install() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                RECEIVED.store(signal, Ordering::Relaxed);
                stop(signal);
            }
        })?;
    Ok(())
}

#[cfg(not(unix))]
pub fn install() -> std::io::Result<()> {
    Ok(())
}

/// Removes the unfinished outputs, says so and exits with 128 + the signal.
fn stop(signal: i32) -> ! {
    gtsphere::output::remove_unfinished();
    let name = match signal {
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "a signal",
    };
    eprintln!("gtsphere: stopped by {name}; no unfinished output is left");
    std::process::exit(128 + signal)
}

/// The exit code `main` returns for an error, 1; except for a render stopped by a signal,
/// whose thread is removing the unfinished outputs and exits the process: this waits for it.
pub fn exit_code_for(e: &gtsphere::error::Error) -> ExitCode {
    if matches!(e, gtsphere::error::Error::Cancelled) && received() {
        loop {
            std::thread::park();
        }
    }
    ExitCode::from(1)
}
