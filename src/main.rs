//! The `physlab` binary: parse the command line, run, map errors to exit codes.

use std::process::ExitCode;

use physlab::app::{self, Differs, Diverged, UsageError};
use physlab::interrupt::Interrupted;

fn main() -> ExitCode {
    // Like other command-line tools, end quietly when stdout is closed early (`physlab ... | head`)
    // instead of panicking on the failed write. Rust ignores SIGPIPE by default.
    // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // clap prints its own usage errors and exits with code 2.
    let cli = physlab::cli::parse();
    physlab::interrupt::install();
    match app::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            if let Some(usage) = err.downcast_ref::<UsageError>() {
                eprintln!("error: {usage}");
                ExitCode::from(2)
            } else if let Some(stop) = err.downcast_ref::<Interrupted>() {
                eprintln!("{stop}");
                ExitCode::from(130)
            } else if let Some(diverged) = err.downcast_ref::<Diverged>() {
                eprintln!("{diverged}");
                ExitCode::from(3)
            } else if let Some(differs) = err.downcast_ref::<Differs>() {
                eprintln!("{differs}");
                ExitCode::from(1)
            } else {
                eprintln!("error: {err:#}");
                ExitCode::from(1)
            }
        }
    }
}
