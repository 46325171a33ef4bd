//! Typed errors. Every error that reaches the user is one line naming the file (when there is one)
//! and the problem; the binary maps [`Error::exit_code`] to the process exit code.

use std::fmt;
use std::path::{Path, PathBuf};

/// Everything that can go wrong between the command line and the report.
#[derive(Debug)]
pub enum Error {
    /// A bad or unreadable input file: missing, wrong format, truncated, NaN coordinates, bad
    /// indices, no triangles, hostile sizes.
    Input {
        /// The file the problem is in.
        path: PathBuf,
        /// What is wrong, one line, no trailing period.
        msg: String,
    },
    /// Writing the report failed.
    Output {
        /// Where the report was going.
        path: PathBuf,
        /// What went wrong.
        msg: String,
    },
    /// Bad arguments or settings.
    Usage(String),
}

impl Error {
    /// A problem with input file `path`.
    pub fn input(path: &Path, msg: impl Into<String>) -> Self {
        Error::Input { path: path.to_path_buf(), msg: msg.into() }
    }

    /// The process exit code for this error (always [`ExitCode::Error`]: bad input, I/O or
    /// usage).
    pub fn exit_code(&self) -> ExitCode {
        ExitCode::Error
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input { path, msg } => write!(f, "{}: {}", path.display(), one_line(msg)),
            Error::Output { path, msg } => {
                write!(f, "{}: cannot write report: {}", path.display(), one_line(msg))
            }
            Error::Usage(msg) => write!(f, "usage: {}", one_line(msg)),
        }
    }
}

impl std::error::Error for Error {}

/// Messages from third-party parsers may span lines; the contract is one line.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The process exit codes, the contract with CI scripts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitCode {
    /// 0: nothing at or above `--fail-on`.
    Ok = 0,
    /// 1: findings at or above `--fail-on`.
    Findings = 1,
    /// 2: bad input, I/O or usage error.
    Error = 2,
}

impl ExitCode {
    /// [`ExitCode::Findings`] if the run failed its `--fail-on`, else [`ExitCode::Ok`].
    pub fn from_failed(failed: bool) -> Self {
        if failed {
            ExitCode::Findings
        } else {
            ExitCode::Ok
        }
    }

    /// The number.
    pub fn code(self) -> u8 {
        self as u8
    }
}

impl From<ExitCode> for std::process::ExitCode {
    fn from(c: ExitCode) -> Self {
        std::process::ExitCode::from(c.code())
    }
}

/// Shorthand for results in this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
