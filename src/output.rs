//! Every file physlab writes goes through here, so that each is written the same way: checked
//! before any work ([`check`], [`distinct`]); only to a regular file or a new one (a symlink is
//! written through only onto a recording or a new file; `-` is standard output); whole or not at
//! all, through a hidden partial file renamed over the target ([`Partial`]), so that a failure
//! leaves the old file untouched; scratch files in one private folder per process ([`TempFile`]).

use std::io::Write as _;
use std::os::unix::ffi::OsStrExt as _;
use std::os::unix::fs::{
    FileTypeExt as _, MetadataExt as _, OpenOptionsExt as _, PermissionsExt as _,
};
use std::path::{Path, PathBuf};

use crate::error::Error;

mod partial;
mod temp;
pub use partial::Partial;
use partial::remove_stale_partials;
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
            None => Ok(Partial::stdout(self.named())),
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

/// Whether `path` is a non-empty file that does not start as a Rerun recording does (`RRF2`).
fn holds_other_data(path: &Path) -> bool {
    use std::io::Read as _;
    let mut head = [0u8; 4];
    // A FIFO would block the open; `check` refuses what is not a file.
    std::fs::metadata(path).is_ok_and(|m| m.is_file())
        && std::fs::File::open(path)
            .is_ok_and(|mut f| f.read_exact(&mut head).is_ok() && &head != b"RRF2")
}

/// Checks an output before any work: a regular file this user may replace or a new one (symlinks
/// followed), a name that fits, a folder that can be created and written in (created here).
/// A path that cannot be written is a runtime failure (exit 1); `-` where it makes no sense is
/// a usage error (exit 2).
pub fn check(flag: &str, path: &Path, dash: Dash) -> anyhow::Result<Output> {
    let named = format!("{flag} {}", path.display());
    let output = |flag: &str, target| Output {
        flag: flag.into(),
        given: path.into(),
        target,
    };
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
        return Ok(output(flag, None));
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
            let only = "; physlab writes only regular files (`-` is standard output)";
            let what = match () {
                _ if t.is_dir() => {
                    format!("a folder; give a file path such as {}/out", path.display())
                }
                _ if t.is_fifo() => format!("a FIFO{only}"),
                _ if t.is_socket() => format!("a socket{only}"),
                _ => format!("a device{only}"),
            };
            return Err(Error::Usage(format!("{named}: is {what}")).into());
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
    Ok(output(flag, Some(target)))
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
    // A recording's symlink is written through, but only onto a recording or a new file: the
    // link's name ends in .rrd whatever it leads to (`-o l.rrd` → /etc/passwd, run as root,
    // replaced it). Checked after the outputs' own clashes, which name the case better.
    for o in outputs.iter().filter(|o| o.flag == "-o") {
        if let Some(t) = &o.target
            && std::fs::symlink_metadata(&o.given).is_ok_and(|m| m.file_type().is_symlink())
            && holds_other_data(t)
        {
            return Err(Error::Usage(format!(
                "{}: is a symbolic link to {}, which is not a Rerun recording; physlab replaces \
                 only a recording or writes a new file: give another path",
                o.named(),
                t.display()
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
