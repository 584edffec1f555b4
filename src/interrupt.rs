//! Ctrl-C and SIGTERM: the first one asks the running scene to stop at its next block, so the
//! recording so far can be finalised and kept; a second one ends the process at once, removing
//! the unfinished recording file first so that no hidden partial file is left behind.

use std::ffi::CString;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The unfinished recording file (a leaked C string), removed by a second signal.
static PARTIAL: AtomicPtr<libc::c_char> = AtomicPtr::new(std::ptr::null_mut());

extern "C" fn on_signal(_: libc::c_int) {
    if REQUESTED.swap(true, Ordering::SeqCst) {
        // Second signal: the user insists. Only async-signal-safe calls here.
        let partial = PARTIAL.load(Ordering::SeqCst);
        unsafe {
            if !partial.is_null() {
                libc::unlink(partial);
            }
            libc::_exit(130)
        };
    }
}

/// Installs the handlers for SIGINT and SIGTERM.
pub fn install() {
    // SAFETY: `on_signal` only touches atomics and calls `unlink` and `_exit`, all
    // async-signal-safe.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

/// Names the unfinished file a second signal removes (`None` once it is complete or gone).
pub fn set_partial_file(path: Option<&std::path::Path>) {
    use std::os::unix::ffi::OsStrExt as _;
    let new = path
        .and_then(|p| CString::new(p.as_os_str().as_bytes()).ok())
        .map_or(std::ptr::null_mut(), CString::into_raw);
    let old = PARTIAL.swap(new, Ordering::SeqCst);
    if !old.is_null() {
        // SAFETY: every non-null pointer stored here came from `CString::into_raw` above.
        drop(unsafe { CString::from_raw(old) });
    }
}

/// Whether a stop was asked for. Scene runs check this once per block of steps.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}
