//! The library's error type. `main` prints it and picks the exit code.

use crate::diag::Diagnostic;

/// Everything the library can fail with; its `Display` is the message for the user.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A positioned problem in a scene file (syntax, types, undefined names, bad values).
    #[error("{0}")]
    Diag(Box<Diagnostic>),
    /// Several positioned problems (for example every warning under `--strict`).
    #[error("{}", .0.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("\n"))]
    Diags(Vec<Diagnostic>),
    /// A file or stream that could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file's path as given (or a name such as `<stdin>`).
        path: String,
        /// What the operating system reported.
        #[source]
        source: std::io::Error,
    },
    /// A picture that cannot be written or read: unsupported extension, inconsistent buffers,
    /// a malformed or truncated file. `message` says what is wrong.
    #[error("{path}: {message}")]
    Image {
        /// The picture's path.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// An input array of a scene built in code has a bad value: `array[index] = value:
    /// message`, e.g. `radii[17] = -1: radius must be positive and finite`.
    #[error("{array}[{index}] = {value}: {message}")]
    Array {
        /// The array's name, e.g. `radii`.
        array: String,
        /// The 0-based index of the bad element.
        index: usize,
        /// The bad element, as text.
        value: String,
        /// What is wrong with it.
        message: String,
    },
    /// Options, a camera or a scene built in code that cannot be rendered (the message says
    /// which value and why).
    #[error("{0}")]
    Invalid(String),
    /// A render stopped by its `Progress::cancelled`.
    #[error("cancelled")]
    Cancelled,
    /// An invariant of gtsphere itself did not hold: a bug, whatever the input.
    #[error("internal error (a bug; please report it): {0}")]
    Internal(String),
    /// A failure of the command line's own (starting threads, a bad path in a job array);
    /// the library does not return it.
    #[error("{0}")]
    Other(String),
}

impl Error {
    /// The diagnostics behind this error, if it is positioned.
    pub fn diagnostics(&self) -> Vec<&Diagnostic> {
        match self {
            Error::Diag(d) => vec![d],
            Error::Diags(v) => v.iter().collect(),
            _ => Vec::new(),
        }
    }
}
