//! Scratch files: one private folder per process, made on first use in TMPDIR (or /tmp) with a
//! random name and mode 0700, so that nobody else can plant or read anything in it; its files
//! created exclusively, removed when dropped, by a second signal, and with the folder on every
//! exit ([`remove_private_temp_dir`]).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use super::{cause, create_new};

/// The private folder once made, or why it could not be.
static DIR: std::sync::OnceLock<Result<PathBuf, String>> = std::sync::OnceLock::new();

/// This process's private temporary folder, made on first use.
pub fn private_temp_dir() -> anyhow::Result<&'static Path> {
    let dir = DIR.get_or_init(|| {
        use std::os::unix::fs::DirBuilderExt as _;
        let mut bytes = [0u8; 8];
        getrandom::fill(&mut bytes).map_err(|e| e.to_string())?;
        let name = format!("physlab-{:016x}", u64::from_ne_bytes(bytes));
        let dir = std::env::temp_dir().join(name);
        // Refused where anything is there already, a planted symlink included.
        (std::fs::DirBuilder::new().mode(0o700).create(&dir))
            .map_err(|e| temp_failed(&e).to_string())?;
        crate::interrupt::set_temp_dir(&dir);
        Ok(dir)
    });
    dir.as_deref().map_err(|e| anyhow::anyhow!("{e}"))
}

/// The error for a temporary folder that cannot be written, named as such (no `-o` was given).
fn temp_failed(e: &std::io::Error) -> anyhow::Error {
    anyhow::anyhow!(
        "the temporary folder {} (TMPDIR, or /tmp when unset) cannot be written: {}; set TMPDIR \
         to a writable folder",
        std::env::temp_dir().display(),
        cause(e)
    )
}

/// Whether `path` is in the private temporary folder.
pub(super) fn is_scratch(path: &Path) -> bool {
    DIR.get()
        .is_some_and(|d| d.as_ref().is_ok_and(|d| path.starts_with(d)))
}

/// Removes the private temporary folder, if it was made, and what is left in it.
pub fn remove_private_temp_dir() {
    if let Some(Ok(dir)) = DIR.get() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// A file in the private temporary folder, removed when dropped (and by a second signal).
pub struct TempFile {
    path: PathBuf,
    slot: usize,
}

impl TempFile {
    /// Writes `bytes` to a new file `name` in the private temporary folder.
    pub fn create(name: &str, bytes: &[u8]) -> anyhow::Result<Self> {
        let path = private_temp_dir()?.join(name);
        let mut file = create_new(&path, 0o600).map_err(|e| temp_failed(&e))?;
        let slot = crate::interrupt::add_partial_file(&path);
        let made = TempFile { path, slot };
        file.write_all(bytes).map_err(|e| temp_failed(&e))?;
        Ok(made)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
        crate::interrupt::remove_partial_file(self.slot);
    }
}
