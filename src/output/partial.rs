//! Writing one output atomically: into a hidden `.NAME.PID.partial` beside the target, created
//! exclusively and locked for its life, then renamed over the target ([`Partial::commit`]); the
//! hidden files of writers that are gone are removed when their target is written again.

use std::ffi::OsString;
use std::io::Write as _;
use std::os::unix::ffi::{OsStrExt as _, OsStringExt as _};
use std::os::unix::fs::{MetadataExt as _, OpenOptionsExt as _, PermissionsExt as _};
use std::path::{Path, PathBuf};

use super::{NAME_MAX, cause, create_new, parent_dir, temp};

/// The hidden file's name for `name` written by process `pid`: `.NAME.PID.partial`, with NAME
/// shortened (bytes from its end dropped) so that the whole fits in [`NAME_MAX`]; with
/// `extension`, the name's extension is appended (`.NAME.PID.partial.png`): the form earlier
/// builds wrote diagrams under, still recognised so that their stale partials are removed.
fn partial_name(name: &[u8], pid: u32, extension: bool) -> OsString {
    let ext = match name.iter().rposition(|&b| b == b'.') {
        Some(dot) if extension && dot > 0 && name.len() - dot <= 16 => &name[dot..],
        _ => &[][..],
    };
    let suffix = format!(".{pid}.partial");
    let room = NAME_MAX - 1 - suffix.len() - ext.len();
    let mut out = vec![b'.'];
    out.extend_from_slice(&name[..name.len().min(room)]);
    out.extend_from_slice(suffix.as_bytes());
    out.extend_from_slice(ext);
    OsString::from_vec(out)
}

/// Removes the hidden files of `target` that nobody holds locked: their writer is gone (killed
/// with SIGKILL, or by a power cut). A live writer holds its lock whatever its PID says here (a
/// process in another PID namespace, on another NFS client).
pub(super) fn remove_stale_partials(target: &Path) {
    let (Some(name), Ok(entries)) = (target.file_name(), std::fs::read_dir(parent_dir(target)))
    else {
        return;
    };
    for entry in entries.flatten() {
        if partial_pid(name.as_bytes(), entry.file_name().as_bytes()).is_some() {
            remove_if_stale(&entry.path());
        }
    }
}

/// The process id in `file` when it is a hidden file of `name`.
fn partial_pid(name: &[u8], file: &[u8]) -> Option<u32> {
    let end = file.windows(8).rposition(|w| w == b".partial")?;
    let rest = file.strip_prefix(b".")?.get(..end - 1)?;
    let dot = rest.iter().rposition(|&b| b == b'.')?;
    let pid: u32 = std::str::from_utf8(&rest[dot + 1..]).ok()?.parse().ok()?;
    [false, true]
        .into_iter()
        .any(|e| partial_name(name, pid, e).as_bytes() == file)
        .then_some(pid)
}

/// Removes the hidden file `path` unless its writer holds it locked; a symlink there is nobody's
/// hidden file (they are created exclusively) and is removed, never followed.
fn remove_if_stale(path: &Path) {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return;
    };
    if !meta.file_type().is_symlink() {
        let open = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
            .open(path);
        // Still the file looked at, and unlocked: its writer is gone.
        let stale = open.is_ok_and(|f| {
            f.try_lock().is_ok() && f.metadata().is_ok_and(|m| m.ino() == meta.ino())
        });
        if !stale {
            return;
        }
    }
    let _ = std::fs::remove_file(path);
}

enum Sink {
    File(std::io::BufWriter<std::fs::File>),
    Stdout(std::io::Stdout),
}

/// An output being written. [`Partial::commit`] puts it in place; dropping it uncommitted
/// removes the hidden file, leaving the target as it was.
pub struct Partial {
    named: String,
    sink: Sink,
    /// Bytes written so far (read while the run goes on, for its size estimate).
    written: std::sync::Arc<std::sync::atomic::AtomicU64>,
    /// The hidden file and the target, and the signal handler's slot for the hidden file.
    done: Option<(PathBuf, PathBuf, usize)>,
    /// Where a replaced file came from (`from … at …`), when it can tell; else its mtime is said.
    describe: Option<fn(&Path) -> Option<String>>,
}

impl Partial {
    /// The count of bytes written so far, which the writer keeps up to date.
    pub fn written(&self) -> std::sync::Arc<std::sync::atomic::AtomicU64> {
        self.written.clone()
    }

    /// Standard output, written directly.
    pub(super) fn stdout(named: String) -> Self {
        Partial {
            named,
            sink: Sink::Stdout(std::io::stdout()),
            written: Default::default(),
            done: None,
            describe: None,
        }
    }

    pub(super) fn beside(named: String, target: &Path) -> anyhow::Result<Self> {
        let name = target.file_name().unwrap_or_default();
        let tmp = parent_dir(target).join(partial_name(name.as_bytes(), std::process::id(), false));
        let failed = |e: std::io::Error| {
            anyhow::anyhow!(
                "{named}: cannot write in its folder {}: {}",
                parent_dir(target).display(),
                cause(&e)
            )
        };
        // The old file's mode is kept (a private recording stays private).
        let old = std::fs::metadata(target)
            .ok()
            .map(|m| m.permissions().mode() & 0o777);
        let mode = old.unwrap_or(0o666);
        let file = loop {
            let file = match create_new(&tmp, mode) {
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    // Ours from a process of the same PID that is gone, or planted: not followed.
                    remove_if_stale(&tmp);
                    create_new(&tmp, mode)
                }
                other => other,
            }
            .map_err(failed)?;
            // Held until the file is renamed or removed: a cleaner that can lock it takes it for
            // a dead writer's. One that removed it before the lock was taken is seen here. (Where
            // the file system has no locks, no cleaner can lock it either, and it is kept.)
            let _ = file.lock();
            if file.metadata().map_err(failed)?.nlink() > 0 {
                // The umask narrowed the mode at creation; the old file's is set whole.
                if old.is_some() {
                    file.set_permissions(std::fs::Permissions::from_mode(mode))
                        .map_err(failed)?;
                }
                break file;
            }
        };
        let slot = crate::interrupt::add_partial_file(&tmp);
        Ok(Partial {
            named,
            sink: Sink::File(std::io::BufWriter::with_capacity(1 << 20, file)),
            written: Default::default(),
            done: Some((tmp, target.to_path_buf(), slot)),
            describe: None,
        })
    }

    /// Says where a file it replaces came from with `describe` (a recording's provenance).
    pub fn describing_old(mut self, describe: fn(&Path) -> Option<String>) -> Self {
        self.describe = Some(describe);
        self
    }

    /// The hidden file, for a writer that takes a path (nothing is buffered for it here).
    pub fn path(&self) -> Option<&Path> {
        self.done.as_ref().map(|d| d.0.as_path())
    }

    /// The error for a failed write: the output, and the cause; the old file is untouched.
    pub fn failed(&self, e: &std::io::Error) -> anyhow::Error {
        let kept = if self.done.is_some() {
            "; the previous file, if any, is unchanged"
        } else {
            ""
        };
        anyhow::anyhow!("{}: cannot write it: {}{kept}", self.named, cause(e))
    }

    /// Flushes, fsyncs and renames the file into place, then fsyncs its folder.
    pub fn commit(mut self) -> anyhow::Result<()> {
        self.flush().map_err(|e| self.failed(&e))?;
        let Some((tmp, target, _)) = &self.done else {
            return Ok(());
        };
        if let Sink::File(w) = &self.sink {
            w.get_ref().sync_all().map_err(|e| self.failed(&e))?;
        }
        // Never replaced without a word: what the old file was, read before it goes (a scratch
        // file of this process's own is not the user's).
        let old = std::fs::metadata(target)
            .ok()
            .filter(|m| m.is_file() && !temp::is_scratch(target))
            .map(|m| {
                (self.describe.and_then(|describe| describe(target)))
                    .unwrap_or_else(|| format!("last written {}", crate::format::utc(m.mtime())))
            });
        std::fs::rename(tmp, target).map_err(|e| self.failed(&e))?;
        let (_, target, slot) = self.done.take().expect("checked above");
        crate::interrupt::remove_partial_file(slot);
        if let Some(old) = old {
            // Its origin on a line of its own: the path may take the width of a terminal.
            eprintln!("replaced {}\n  ({old})", crate::shell::shown(&target));
        }
        // The rename is durable once the folder is.
        if let Ok(dir) = std::fs::File::open(parent_dir(&target)) {
            // `done` is taken: no word of the previous file, which is replaced.
            dir.sync_all().map_err(|e| self.failed(&e))?;
        }
        Ok(())
    }
}

impl std::io::Write for Partial {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = match &mut self.sink {
            Sink::File(w) => w.write(buf),
            Sink::Stdout(w) => crate::interrupt::writing_stdout(|| w.write(buf))
                .inspect_err(crate::interrupt::note_stdout_error),
        }?;
        self.written
            .fetch_add(n as u64, std::sync::atomic::Ordering::Relaxed);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.sink {
            Sink::File(w) => w.flush(),
            Sink::Stdout(w) => crate::interrupt::writing_stdout(|| w.flush()),
        }
    }
}

impl Drop for Partial {
    fn drop(&mut self) {
        if let Some((tmp, _, slot)) = self.done.take() {
            let _ = std::fs::remove_file(&tmp);
            crate::interrupt::remove_partial_file(slot);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partial_names_fit_and_are_recognised() {
        for len in [1usize, 10, 200, 240, 241, 250, 255] {
            let name = vec![b'n'; len];
            for pid in [1u32, 4_194_304, u32::MAX] {
                for ext in [false, true] {
                    let mut name = name.clone();
                    name.splice(len - 4.min(len)..len - 4.min(len), *b".png");
                    let p = partial_name(&name, pid, ext);
                    assert!(p.len() <= NAME_MAX, "{len} {pid}: {}", p.len());
                    assert_eq!(partial_pid(&name, p.as_bytes()), Some(pid));
                    // Another target's hidden files are not this one's.
                    assert_eq!(partial_pid(b"other", p.as_bytes()), None);
                }
            }
        }
        assert_eq!(partial_pid(b"a.rrd", b".a.rrd.x.partial"), None);
        assert_eq!(partial_pid(b"a.rrd", b"a.rrd.12.partial"), None);
    }
}
