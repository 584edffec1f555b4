//! The one error type of physlab's outcomes that are not plain runtime failures, each with its
//! exit code. Bad input names the option (or the file, table and key), the value and what is
//! allowed.

use std::fmt;

#[derive(Debug)]
pub enum Error {
    /// Bad input: a flag, a scene file, a recording that cannot be used. Exit 2.
    Usage(String),
    /// One parameter out of its range, named as its flag, with its value as given and what is
    /// allowed (`--nodes 1: must be between 2 and 10000`). Kept apart so that a value from a
    /// scene file is named as that file's key ([`Error::in_file`]). Exit 2.
    Param {
        option: String,
        value: String,
        rule: String,
    },
    /// Anything else that failed while running (an I/O error, a failed write). Exit 1, or 2 in
    /// `reproduce` and `diff` ([`Error::exit_code_for`]).
    Runtime(anyhow::Error),
    /// `reproduce` or `diff` found a difference (beyond the tolerance). Exit 1.
    Differs(String),
    /// A method diverged, with --fail-on-divergence. Exit 3.
    Diverged(String),
    /// The run was stopped by a signal, after its recording was finalised. Exit 130.
    Interrupted(String),
}

impl Error {
    /// The exit code when standard output's reader left before the command ended (`physlab …
    /// | head -1`): the command stops there quietly, its temporary and partial files removed;
    /// 141 is what a shell reports for a process SIGPIPE ended, and says the output is cut.
    pub const READER_GONE: u8 = 141;

    /// The exit code in a command where 1 says "they differ" (`reproduce`, `diff`): any failure
    /// there is 2, as for diff(1) and cmp(1).
    pub fn exit_code_for(&self, compares: bool) -> u8 {
        match self {
            Error::Runtime(_) if compares => 2,
            _ => self.exit_code(),
        }
    }

    /// A parameter refused as its flag names it.
    pub fn param(option: &str, value: impl fmt::Display, rule: impl Into<String>) -> Self {
        Error::Param {
            option: option.into(),
            value: value.to_string(),
            rule: rule.into(),
        }
    }

    /// This error of a value read from table `[table]` of scene file `file`: a parameter is
    /// named by its key there (`[rope] nodes = 1`, with the key's line when `line` finds it),
    /// anything else is said as it is, after the file and table.
    pub fn in_file(
        self,
        file: &std::path::Path,
        table: &str,
        line: impl Fn(&str) -> Option<usize>,
    ) -> Self {
        let file = file.display();
        match self {
            Error::Param {
                option,
                value,
                rule,
            } => {
                let key = option.trim_start_matches("--").replace('-', "_");
                let at = line(&key).map_or(String::new(), |l| format!("line {l}: "));
                Error::Usage(format!(
                    "--config {file}: {at}[{table}] {key} = {value}: {rule}"
                ))
            }
            Error::Usage(message) => Error::Usage(format!("--config {file}: [{table}]: {message}")),
            other => other,
        }
    }

    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Usage(_) | Error::Param { .. } => 2,
            Error::Runtime(_) | Error::Differs(_) => 1,
            Error::Diverged(_) => 3,
            Error::Interrupted(_) => 130,
        }
    }

    /// The line the binary prints on standard error: failures are marked `error:`, the
    /// outcomes a script asked about (a difference, a divergence, a stop) are stated as they are.
    pub fn report(&self) -> String {
        match self {
            Error::Usage(_) | Error::Param { .. } | Error::Runtime(_) => format!("error: {self}"),
            _ => self.to_string(),
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Usage(m) | Error::Differs(m) | Error::Diverged(m) | Error::Interrupted(m) => {
                f.write_str(m)
            }
            Error::Param {
                option,
                value,
                rule,
            } => write!(f, "{option} {value}: {rule}"),
            Error::Runtime(e) => write!(f, "{e:#}"),
        }
    }
}

impl std::error::Error for Error {}

/// Any failure as physlab's error: one of its own as it is, anything else a runtime failure.
impl From<anyhow::Error> for Error {
    fn from(err: anyhow::Error) -> Self {
        match err.downcast::<Error>() {
            Ok(own) => own,
            Err(other) => Error::Runtime(other),
        }
    }
}
