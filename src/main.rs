//! The `physlab` binary: parse the command line, run, map errors to exit codes.

use std::process::ExitCode;

use physlab::cli::Command;
use physlab::error::Error;
use physlab::shell::escaped;

fn main() -> ExitCode {
    // A closed pipe and a file-size limit become errors of the write (EPIPE, EFBIG) that end the
    // command with its temporary and partial files removed, not deaths that leave them behind.
    // SAFETY: setting dispositions before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_IGN);
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    if let Err(message) = physlab::interrupt::check_process() {
        let err = Error::Usage(message);
        eprintln!("{}", err.report());
        return ExitCode::from(err.exit_code());
    }
    // A failed print panics in std: the message is the error, said once, not a panic.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if physlab::interrupt::failed_print(info.payload_as_str()).is_none() {
            default_hook(info);
        }
    }));
    // clap prints its own usage errors and exits with code 2.
    let cli = physlab::cli::parse();
    physlab::interrupt::install();
    // Where exit 1 says "they differ", every failure is 2 (as for diff(1) and cmp(1)).
    let compares = matches!(cli.command, Command::Reproduce(_) | Command::Diff(_));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| physlab::app::run(cli)));
    physlab::output::remove_private_temp_dir();
    let err = match outcome {
        Ok(Ok(())) => return ExitCode::SUCCESS,
        Ok(Err(err)) => Error::from(err),
        Err(panic) => {
            let message = panic.downcast_ref::<String>().map(String::as_str);
            match physlab::interrupt::failed_print(message) {
                Some(cause) => Error::Runtime(anyhow::anyhow!(cause)),
                None => std::panic::resume_unwind(panic),
            }
        }
    };
    if physlab::interrupt::reader_gone() {
        // The reader of standard output left (`| head`): the output ends there, quietly.
        return ExitCode::from(Error::READER_GONE);
    }
    // Escaped line by line: a file's name or a decoder's words may hold control characters.
    let report: Vec<_> = err
        .report()
        .lines()
        .map(|l| escaped(l).into_owned())
        .collect();
    eprintln!("{}", report.join("\n"));
    ExitCode::from(err.exit_code_for(compares))
}
