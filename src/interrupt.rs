//! Ctrl-C, SIGTERM and SIGHUP (a closed terminal, a dropped ssh session): the first one asks the
//! running command to stop at its next check, so what is complete can be finalised and kept; a
//! second one ends the process at once, removing the unfinished output files first so that no
//! hidden partial file is left behind.

use std::ffi::CString;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// The unfinished output files (leaked C strings), removed by a second signal. A command
/// writes a few at most at once (a recording, a CSV, a diagram).
static PARTIAL: [AtomicPtr<libc::c_char>; 8] = [const { AtomicPtr::new(std::ptr::null_mut()) }; 8];

extern "C" fn on_signal(_: libc::c_int) {
    if REQUESTED.swap(true, Ordering::SeqCst) {
        // Second signal: the user insists. Only async-signal-safe calls here.
        for slot in &PARTIAL {
            let partial = slot.load(Ordering::SeqCst);
            if !partial.is_null() {
                unsafe { libc::unlink(partial) };
            }
        }
        unsafe { libc::_exit(130) };
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
    for (i, slot) in PARTIAL.iter().enumerate() {
        if slot
            .compare_exchange(
                std::ptr::null_mut(),
                new,
                Ordering::SeqCst,
                Ordering::SeqCst,
            )
            .is_ok()
        {
            return i;
        }
    }
    // SAFETY: `new` came from `CString::into_raw` just above and was stored nowhere.
    drop(unsafe { CString::from_raw(new) });
    usize::MAX
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
