//! Ctrl-C, SIGTERM and SIGHUP (a closed terminal, a dropped ssh session): the first one asks the
//! running command to stop at its next check, so what is complete can be finalised and kept; a
//! second one ends the process at once, removing the unfinished output files first so that no
//! hidden partial file is left behind. A write to standard output that blocks (a pipe nobody
//! reads) never reaches the next check, so a watchdog ends the process when a signal finds it
//! blocked there for [`BLOCKED_GRACE`].

use std::ffi::CString;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);
/// A signal (not [`stop`]) asked for the stop.
static SIGNALLED: AtomicBool = AtomicBool::new(false);
/// Standard output's reader left: a write there failed with EPIPE ([`failed_print`],
/// [`note_stdout_error`]).
static READER_GONE: AtomicBool = AtomicBool::new(false);
/// The private temporary folder (a leaked C string), removed by a second signal once the files
/// in it are.
static TEMP_DIR: AtomicPtr<libc::c_char> = AtomicPtr::new(std::ptr::null_mut());
/// A write to standard output is under way ([`writing_stdout`]).
static IN_STDOUT_WRITE: AtomicBool = AtomicBool::new(false);

/// How long a signal waits for a write to standard output that does not return before the
/// process ends without it (well inside the second a stop is promised in).
pub const BLOCKED_GRACE: std::time::Duration = std::time::Duration::from_millis(500);

/// The unfinished output files (leaked C strings), removed by a second signal. A command
/// writes a few at most at once (a recording, a CSV, a diagram).
static PARTIAL: [AtomicPtr<libc::c_char>; 8] = [const { AtomicPtr::new(std::ptr::null_mut()) }; 8];

extern "C" fn on_signal(_: libc::c_int) {
    SIGNALLED.store(true, Ordering::SeqCst);
    if REQUESTED.swap(true, Ordering::SeqCst) {
        // Second signal: the user insists.
        remove_partials_and_exit();
    }
}

/// Removes the unfinished files and ends the process with 130. Only async-signal-safe calls.
fn remove_partials_and_exit() -> ! {
    for slot in &PARTIAL {
        let partial = slot.load(Ordering::SeqCst);
        if !partial.is_null() {
            // SAFETY: a non-null slot holds a C string leaked by `add_partial_file`.
            unsafe { libc::unlink(partial) };
        }
    }
    let dir = TEMP_DIR.load(Ordering::SeqCst);
    if !dir.is_null() {
        // SAFETY: a C string leaked by `set_temp_dir`.
        unsafe { libc::rmdir(dir) };
    }
    // SAFETY: `_exit` ends the process without running anything else.
    unsafe { libc::_exit(130) }
}

/// Runs `write` (a write to standard output), marked as one that may block for ever.
pub fn writing_stdout<T>(write: impl FnOnce() -> T) -> T {
    IN_STDOUT_WRITE.store(true, Ordering::SeqCst);
    let result = write();
    IN_STDOUT_WRITE.store(false, Ordering::SeqCst);
    result
}

/// Ends the process when a signal has found a write to standard output blocked for
/// [`BLOCKED_GRACE`]: the command cannot stop by itself there.
fn watch_blocked_stdout() {
    let tick = std::time::Duration::from_millis(20);
    let mut blocked_for = std::time::Duration::ZERO;
    loop {
        std::thread::sleep(tick);
        if SIGNALLED.load(Ordering::SeqCst) && IN_STDOUT_WRITE.load(Ordering::SeqCst) {
            blocked_for += tick;
        } else {
            blocked_for = std::time::Duration::ZERO;
        }
        if blocked_for >= BLOCKED_GRACE {
            let message = b"physlab: interrupted while standard output was not being read: \
                            stopped without finishing what it was writing there\n";
            // stderr may be an unread pipe too: write only if it has room now (a write of
            // less than PIPE_BUF bytes then does not block).
            let mut stderr = libc::pollfd {
                fd: 2,
                events: libc::POLLOUT,
                revents: 0,
            };
            // SAFETY: one valid pollfd; the write reads `message` only.
            unsafe {
                if libc::poll(&mut stderr, 1, 0) == 1 && stderr.revents & libc::POLLOUT != 0 {
                    libc::write(2, message.as_ptr().cast(), message.len());
                }
            }
            remove_partials_and_exit();
        }
    }
}

/// Installs the handlers for SIGINT, SIGTERM and SIGHUP.
pub fn install() {
    // SAFETY: `on_signal` only touches atomics and calls `unlink` and `_exit`, all
    // async-signal-safe.
    unsafe {
        for signal in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::signal(signal, on_signal as *const () as libc::sighandler_t);
        }
    }
    std::thread::Builder::new()
        .name("stop watchdog".into())
        .spawn(watch_blocked_stdout)
        .ok();
}

/// Names an unfinished file a second signal removes; returns its slot for
/// [`remove_partial_file`]. With every slot taken the file is not registered (`usize::MAX`):
/// it is still removed when its writer is dropped.
pub fn add_partial_file(path: &std::path::Path) -> usize {
    use std::os::unix::ffi::OsStrExt as _;
    let Ok(c) = CString::new(path.as_os_str().as_bytes()) else {
        return usize::MAX;
    };
    let new = c.into_raw();
    let null = std::ptr::null_mut();
    let take = |slot: &AtomicPtr<_>| {
        slot.compare_exchange(null, new, Ordering::SeqCst, Ordering::SeqCst)
            .is_ok()
    };
    PARTIAL.iter().position(take).unwrap_or_else(|| {
        // SAFETY: `new` came from `CString::into_raw` just above and was stored nowhere.
        drop(unsafe { CString::from_raw(new) });
        usize::MAX
    })
}

/// The file in `slot` is complete or gone: a second signal leaves it alone.
pub fn remove_partial_file(slot: usize) {
    let Some(slot) = PARTIAL.get(slot) else {
        return;
    };
    let old = slot.swap(std::ptr::null_mut(), Ordering::SeqCst);
    if !old.is_null() {
        // SAFETY: every non-null pointer stored here came from `CString::into_raw`.
        drop(unsafe { CString::from_raw(old) });
    }
}

/// Stops the running command as a signal would, for a reason of its own (an output that can no
/// longer be written): the run ends at its next check and reports that reason.
pub fn stop() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Whether a stop was asked for. Scene runs check this once per block of steps.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// Names the private temporary folder a second signal removes (after the files in it).
pub fn set_temp_dir(path: &std::path::Path) {
    use std::os::unix::ffi::OsStrExt as _;
    if let Ok(c) = CString::new(path.as_os_str().as_bytes()) {
        TEMP_DIR.store(c.into_raw(), Ordering::SeqCst);
    }
}

/// Notes a failed write to standard output: EPIPE means its reader left.
pub fn note_stdout_error(e: &std::io::Error) {
    if e.raw_os_error() == Some(libc::EPIPE) {
        READER_GONE.store(true, Ordering::SeqCst);
    }
}

/// Whether standard output's reader left (the command's output ends there).
pub fn reader_gone() -> bool {
    READER_GONE.load(Ordering::SeqCst)
}

/// The error, when `message` is std's panic for a failed `print!`/`eprint!` (`failed printing
/// to stdout: …`), noting a reader that left.
pub fn failed_print(message: Option<&str>) -> Option<String> {
    let cause = message?.strip_prefix("failed printing to std")?;
    if cause.ends_with(&std::io::Error::from_raw_os_error(libc::EPIPE).to_string()) {
        READER_GONE.store(true, Ordering::SeqCst);
    }
    Some(format!("cannot print to std{cause}"))
}

/// A resource limit's soft value (`None`: unlimited or unknown).
pub fn limit(resource: libc::__rlimit_resource_t) -> Option<u64> {
    let mut r = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: one valid rlimit to fill.
    let ok = unsafe { libc::getrlimit(resource, &mut r) } == 0;
    (ok && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur)
}

/// Open files physlab may need at once: its inputs, outputs and their locks, Rerun's handles.
pub const MIN_OPEN_FILES: u64 = 16;

/// Refuses to start where the process cannot work: standard output closed (what is printed
/// there would be lost), too few open files allowed.
pub fn check_process() -> Result<(), String> {
    // Before `main`, std puts /dev/null opened read-write in place of a closed standard
    // descriptor; a shell's `>/dev/null` opens it write-only.
    // SAFETY: fcntl and fstat on descriptor 1 into a zeroed stat.
    let closed = unsafe {
        let mut st: libc::stat = std::mem::zeroed();
        libc::fcntl(1, libc::F_GETFL) & libc::O_ACCMODE == libc::O_RDWR
            && libc::fstat(1, &mut st) == 0
            && st.st_mode & libc::S_IFMT == libc::S_IFCHR
            && st.st_rdev == libc::makedev(1, 3)
    };
    if closed {
        return Err(
            "standard output is closed: physlab prints its summary and reports there; \
                    give it somewhere to go (e.g. `>/dev/null`)"
                .into(),
        );
    }
    match limit(libc::RLIMIT_NOFILE) {
        Some(n) if n < MIN_OPEN_FILES => Err(format!(
            "too many open files: the limit of open files (`ulimit -n`) is {n}; physlab needs \
             {MIN_OPEN_FILES}"
        )),
        _ => Ok(()),
    }
}
