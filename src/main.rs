//! The `physlab` binary: parse the command line, run, map errors to exit codes.

use std::process::ExitCode;

use physlab::error::Error;

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
    match physlab::app::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            let err = Error::from(err);
            eprintln!("{}", err.report());
            ExitCode::from(err.exit_code())
        }
    }
}
