//! Every file physlab writes goes through here, so that each is written the same way:
//!
//! - only to a regular file or a new one: a symlink is written through (its target is replaced,
//!   the link kept); a folder, FIFO, device or socket is refused (`-` is standard output);
//! - checked before any work ([`check`]): the folder can be created and written in, the name
//!   fits, and no two outputs of a command, nor an output and an input, are one file
//!   ([`distinct`]);
//! - atomically ([`Partial`]): into a hidden `.NAME.PID.partial` beside the target, created
//!   exclusively (never through a symlink), locked (`flock`) for its life, given the old file's
//!   mode, flushed and fsynced, renamed over the target, the folder fsynced; any failure removes
//!   the hidden file and leaves the old target untouched, and the error names the file and the
//!   cause; an old file its user may not write is refused, not replaced; one replaced is said on
//!   stderr, with where it came from on the next line (`(from … at …)`);
//! - a second SIGINT/SIGTERM/SIGHUP removes the hidden file (`crate::interrupt`), and hidden
//!   files nobody holds locked (their writer is gone, whatever its PID) are removed when their
//!   target is written again;
//! - scratch files ([`TempFile`]) in one private folder per process (mode 0700, a random name),
//!   removed with it on every exit ([`remove_private_temp_dir`]).

use std::ffi::OsString;
use std::io::Write as _;
use std::os::unix::ffi::{OsStrExt as _, OsStringExt as _};
use std::os::unix::fs::{
    FileTypeExt as _, MetadataExt as _, OpenOptionsExt as _, PermissionsExt as _,
};
use std::path::{Path, PathBuf};

use crate::error::Error;

mod temp;
pub use temp::{TempFile, private_temp_dir, remove_private_temp_dir};

/// The longest file name the file systems physlab runs on take, in bytes.
const NAME_MAX: usize = 255;

/// A checked output: the flag that named it, the path as given, and where the bytes go.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    pub flag: String,
    pub given: PathBuf,
    /// The regular file written (symlinks followed); `None` for standard output.
    pub target: Option<PathBuf>,
}

impl Output {
    pub fn is_stdout(&self) -> bool {
        self.target.is_none()
    }

    /// `FLAG PATH`, as errors name it.
    pub fn named(&self) -> String {
        format!("{} {}", self.flag, self.given.display())
    }

    /// Starts writing: a hidden file beside the target (standard output is written directly).
    pub fn create(&self) -> anyhow::Result<Partial> {
        match &self.target {
            None => Ok(Partial {
                named: self.named(),
                sink: Sink::Stdout(std::io::stdout()),
                written: Default::default(),
                done: None,
                describe: None,
            }),
            Some(target) => Partial::beside(self.named(), target),
        }
    }

    /// Writes `bytes` whole or not at all.
    pub fn write(&self, bytes: &[u8]) -> anyhow::Result<()> {
        let mut partial = self.create()?;
        partial.write_all(bytes).map_err(|e| partial.failed(&e))?;
        partial.commit()
    }
}

/// Prints `text` for the reader: on standard error when standard output carries an output
/// (`-`), on standard output otherwise.
pub fn print_beside(stdout_taken: bool, text: &str) {
    if stdout_taken {
        eprint!("{text}");
    } else {
        print!("{text}");
    }
}

/// Standard output as a destination: where `-` makes sense for a flag, and where not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Dash {
    /// Binary data (a recording): refused when standard output is a terminal.
    Binary,
    /// Text (CSV, TOML).
    Text,
    /// `-` makes no sense here (a folder, a file read back): refused.
    Refused(&'static str),
}

/// Checks `-o PATH`, a recording, as [`check`] does, after its extension: `.rrd`, or none (`-o
/// out.png` would write a Rerun file under a picture's name). A usage error (exit 2).
pub fn check_recording(path: &Path, dash: Dash) -> anyhow::Result<Output> {
    if let (false, Some(ext)) = (path.as_os_str() == "-", path.extension())
        && ext != "rrd"
    {
        return Err(Error::Usage(format!(
            "-o {}: the extension .{} is not a recording's; -o writes a Rerun recording: give a \
             name ending in .rrd (or - for standard output)",
            path.display(),
            ext.to_string_lossy()
        ))
        .into());
    }
    check("-o", path, dash)
}

/// Checks an output before any work: see the module documentation. Creates its folder.
/// A path that cannot be written is a runtime failure (exit 1); `-` where it makes no sense is
/// a usage error (exit 2).
pub fn check(flag: &str, path: &Path, dash: Dash) -> anyhow::Result<Output> {
    let named = format!("{flag} {}", path.display());
    if path.as_os_str() == "-" {
        match dash {
            Dash::Refused(why) => {
                return Err(Error::Usage(format!("{flag} -: standard output {why}")).into());
            }
            Dash::Binary => {
                use std::io::IsTerminal as _;
                if std::io::stdout().is_terminal() {
                    return Err(Error::Usage(format!(
                        "{flag} -: standard output is a terminal; pipe it into the viewer, e.g. \
                         `physlab pendulum -o - | rerun -`, or give a file name"
                    ))
                    .into());
                }
            }
            Dash::Text => {}
        }
        return Ok(Output {
            flag: flag.into(),
            given: path.into(),
            target: None,
        });
    }
    let target = follow_links(path).map_err(|e| anyhow::anyhow!("{named}: {}", cause(&e)))?;
    // A scratch file is no file the user named: its errors name the temporary folder.
    let flag = if temp::is_scratch(&target) {
        "the temporary file (TMPDIR, or /tmp when unset)"
    } else {
        flag
    };
    let named = format!("{flag} {}", path.display());
    match std::fs::metadata(&target) {
        Ok(m) if m.is_file() && !may_replace(&target, &m) => {
            return Err(Error::Usage(format!(
                "{named}: is read-only (mode {:o}); physlab does not replace a file you may not \
                 write: make it writable or give another path",
                m.permissions().mode() & 0o777
            ))
            .into());
        }
        Ok(m) if m.is_file() => {}
        Ok(m) => {
            let t = m.file_type();
            // Bad input like any other (exit 2): the path names something that is no file.
            let what = match () {
                _ if t.is_dir() => {
                    format!("a folder; give a file path such as {}/out", path.display())
                }
                _ if t.is_fifo() => "a FIFO".into(),
                _ if t.is_socket() => "a socket".into(),
                _ => "a device".into(),
            };
            let only = if t.is_dir() {
                ""
            } else {
                "; physlab writes only regular files (`-` is standard output)"
            };
            return Err(Error::Usage(format!("{named}: is {what}{only}")).into());
        }
        // Not there (or under a file): making its folder below says why it cannot be.
        Err(_) => {}
    }
    let name = target
        .file_name()
        .ok_or_else(|| anyhow::anyhow!("{named}: names no file"))?;
    if name.len() > NAME_MAX {
        return Err(anyhow::anyhow!(
            "{named}: the file name is {} bytes long; at most {NAME_MAX} are allowed",
            name.len()
        ));
    }
    let dir = parent_dir(&target);
    std::fs::create_dir_all(&dir).map_err(|e| {
        anyhow::anyhow!(
            "{named}: cannot create the folder {}: {}",
            dir.display(),
            cause(&e)
        )
    })?;
    remove_stale_partials(&target);
    // Writable: the hidden file the write will use can be made (and is removed at once).
    drop(Partial::beside(named, &target)?);
    Ok(Output {
        flag: flag.into(),
        given: path.into(),
        target: Some(target),
    })
}

/// Refuses two outputs of one command that are one file (or both standard output), and an
/// output that is one of the command's inputs. Usage errors (exit 2).
pub fn distinct(outputs: &[&Output], inputs: &[(&str, &Path)]) -> Result<(), Error> {
    for (i, a) in outputs.iter().enumerate() {
        for b in &outputs[..i] {
            let same = match (&a.target, &b.target) {
                (None, None) => true,
                (Some(x), Some(y)) => same_file(x, y),
                _ => false,
            };
            if same {
                return Err(Error::Usage(format!(
                    "{} and {}: both write {}; give each its own path",
                    b.named(),
                    a.named(),
                    a.target
                        .as_ref()
                        .map_or("standard output".into(), |t| t.display().to_string())
                )));
            }
        }
        if let Some(t) = &a.target
            && let Some((what, input)) = inputs.iter().find(|(_, p)| same_file(t, p))
        {
            return Err(Error::Usage(format!(
                "{}: is {what} ({}); writing it would replace it; give another path",
                a.named(),
                input.display()
            )));
        }
    }
    Ok(())
}

/// Whether two paths name one file: the same inode when both exist, else the same resolved path.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
        _ => resolved(a) == resolved(b),
    }
}

/// `path` with its folder made absolute and canonical (the file itself may not exist yet).
fn resolved(path: &Path) -> PathBuf {
    let path = follow_links(path).unwrap_or_else(|_| path.to_path_buf());
    let dir = parent_dir(&path);
    let dir = dir.canonicalize().unwrap_or(dir);
    match path.file_name() {
        Some(n) => dir.join(n),
        None => dir,
    }
}

/// The path a write to `path` replaces: `path` itself, or where its chain of symlinks ends
/// (which may not exist yet).
fn follow_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p)?;
                p = if link.is_absolute() {
                    link
                } else {
                    parent_dir(&p).join(link)
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::from_raw_os_error(libc::ELOOP))
}

/// The folder `target` is in (`.` for a bare name).
pub fn parent_dir(target: &Path) -> PathBuf {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The cause of an I/O error in words (`disk full`, `permission denied`...), with the system's
/// own message.
pub fn cause(e: &std::io::Error) -> String {
    let words = match e.raw_os_error() {
        Some(libc::ENOSPC) => "disk full",
        Some(libc::EDQUOT) => "disk quota exceeded",
        Some(libc::EACCES | libc::EPERM) => "permission denied",
        Some(libc::EROFS) => "read-only file system",
        Some(libc::ENAMETOOLONG) => "file name too long",
        Some(libc::ENOENT) => "no such file or folder",
        Some(libc::ENOTDIR) => "a part of the path is not a folder",
        Some(libc::EIO) => "input/output error",
        Some(libc::EMFILE | libc::ENFILE) => "too many open files (the limit is `ulimit -n`)",
        Some(libc::EAGAIN) => "no threads or processes available (the limit is `ulimit -u`)",
        Some(libc::EFBIG) => {
            let limit = match crate::interrupt::limit(libc::RLIMIT_FSIZE) {
                Some(bytes) => format!("the file-size limit of {bytes} bytes (`ulimit -f`)"),
                None => "the largest file the file system takes".into(),
            };
            return format!("file too large: over {limit} ({e})");
        }
        _ => return e.to_string(),
    };
    format!("{words} ({e})")
}

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
fn remove_stale_partials(target: &Path) {
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

/// Opens a new file at `path` for writing: created exclusively (a file or a symlink already there
/// is an error, `EEXIST`), with `mode`.
fn create_new(path: &Path, mode: u32) -> std::io::Result<std::fs::File> {
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .custom_flags(libc::O_NOFOLLOW)
        .mode(mode)
        .open(path)
}

/// Whether this user may replace the old file `target` (the rename needs only its folder): root,
/// who may write anything, unless nobody may (a read-only file, by its permission bits); anyone
/// else as the kernel's access check says.
fn may_replace(target: &Path, meta: &std::fs::Metadata) -> bool {
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } == 0 {
        return meta.permissions().mode() & 0o222 != 0;
    }
    let Ok(c) = std::ffi::CString::new(target.as_os_str().as_bytes()) else {
        return true;
    };
    // SAFETY: a valid C string, only read.
    let r = unsafe { libc::faccessat(libc::AT_FDCWD, c.as_ptr(), libc::W_OK, libc::AT_EACCESS) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::EACCES)
}

/// Holds the folders `dirs` locked (`flock`) until dropped. The writers of one set of outputs (a
/// study's CSV, diagrams and recording) take it, so that two commands writing the same set at
/// once leave one's set whole, never a mix; the folders are locked in one order (no deadlock),
/// waiting for another holder while answering a stop request.
pub fn lock_folders(dirs: &[PathBuf]) -> anyhow::Result<Vec<std::fs::File>> {
    let mut dirs: Vec<PathBuf> = dirs
        .iter()
        .map(|d| d.canonicalize().unwrap_or(d.clone()))
        .collect();
    dirs.sort();
    dirs.dedup();
    let lock = |dir: &PathBuf| {
        let failed =
            |e| anyhow::anyhow!("{}: cannot lock the folder: {}", dir.display(), cause(&e));
        let folder = std::fs::File::open(dir).map_err(failed)?;
        while let Err(e) = folder.try_lock() {
            match e {
                std::fs::TryLockError::Error(e) => return Err(failed(e)),
                _ if crate::interrupt::requested() => {
                    let message = format!(
                        "interrupted while another physlab was writing to {}; nothing was written",
                        dir.display()
                    );
                    return Err(Error::Interrupted(message).into());
                }
                _ => std::thread::sleep(std::time::Duration::from_millis(20)),
            }
        }
        Ok(folder)
    };
    dirs.iter().map(lock).collect()
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

    fn beside(named: String, target: &Path) -> anyhow::Result<Self> {
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
            eprintln!("replaced {}\n  ({old})", target.display());
        }
        // The rename is durable once the folder is.
        if let Ok(dir) = std::fs::File::open(parent_dir(&target)) {
            dir.sync_all()
                .map_err(|e| anyhow::anyhow!("{}: cannot write it: {}", self.named, cause(&e)))?;
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
