//! Positioned diagnostics: `file:line:col: message`, the offending line and a caret.

use std::fmt;
use std::sync::Arc;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// A problem that stops the command.
    Error,
    /// A problem that is skipped over (an error under `--strict`).
    Warning,
    /// Information about a choice made (not a problem).
    Note,
}

/// One message with its position in a source file (1-based line and column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// How bad it is.
    pub severity: Severity,
    /// The source file's name.
    pub file: Arc<str>,
    /// The 1-based line.
    pub line: u64,
    /// The 1-based column, in bytes (in characters when the line is in `snippet`).
    pub col: u64,
    /// What is wrong, one sentence without the position.
    pub message: String,
    /// The text of the offending line, when it was still in the reading window.
    pub snippet: Option<String>,
    /// How many further occurrences of the same warning were folded into this one.
    pub repeats: u64,
}

impl Diagnostic {
    /// The one-line form, `file:line:col: message` (warnings say `warning:` before the message).
    pub fn headline(&self) -> String {
        let sev = match self.severity {
            Severity::Error => "",
            Severity::Warning => "warning: ",
            Severity::Note => "note: ",
        };
        let more = if self.repeats > 0 {
            format!(" (and {} more like it)", self.repeats)
        } else {
            String::new()
        };
        format!(
            "{}:{}:{}: {}{}{}",
            self.file, self.line, self.col, sev, self.message, more
        )
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.headline())?;
        if let Some(line) = &self.snippet {
            // Tabs would shift the caret; show them as single spaces.
            let shown: String = line
                .chars()
                .map(|c| if c == '\t' { ' ' } else { c })
                .collect();
            let pad = (self.col.saturating_sub(1)) as usize;
            write!(f, "\n  {}\n  {}^", shown, " ".repeat(pad))?;
        }
        Ok(())
    }
}
