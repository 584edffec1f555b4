//! Where a recording goes (a file, a viewer, standard output) and the recording stream that
//! writes it safely: chunked the same way on every run, renamed into place only when complete.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use super::{Layout, live, sink};

/// Where a recording goes: a file (written beside its target and renamed when complete), a
/// running viewer, a viewer started for it, or any combination.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Destinations {
    pub file: Option<PathBuf>,
    /// A viewer's gRPC proxy URL, e.g. rerun+http://127.0.0.1:9876/proxy.
    pub connect: Option<String>,
    /// Start `rerun` from PATH and stream to it.
    pub spawn: bool,
    /// Write the recording to standard output (`-o -`), e.g. piped into `rerun -`.
    pub stdout: bool,
}

impl Destinations {
    /// `-o PATH`, where `-` means standard output.
    pub fn output(path: &Path) -> Self {
        let stdout = path.as_os_str() == "-";
        Destinations {
            file: (!stdout).then(|| path.to_path_buf()),
            stdout,
            ..Default::default()
        }
    }

    /// The recording as a checked output (`crate::output`): a file or standard output.
    pub fn written(&self) -> anyhow::Result<Option<crate::output::Output>> {
        let path = self.file.as_deref().or(self.stdout.then(|| Path::new("-")));
        (path.map(|p| crate::output::check_recording(p, crate::output::Dash::Binary))).transpose()
    }
}

/// Checks the destinations before anything is simulated: the file can be written
/// (`crate::output::check`), the viewer URL parses, `rerun` is on PATH for --spawn.
pub fn check_destinations(d: &Destinations) -> anyhow::Result<()> {
    d.written()?;
    if let Some(url) = &d.connect {
        parse_proxy_url(url)?;
    }
    if d.spawn && find_on_path("rerun").is_none() {
        anyhow::bail!(
            "--spawn: no `rerun` executable on PATH; install the viewer with `pip install rerun-sdk==0.36.3`, \
             or open the file later"
        );
    }
    Ok(())
}

fn parse_proxy_url(url: &str) -> anyhow::Result<rerun::external::re_uri::ProxyUri> {
    url.parse().map_err(|e| {
        crate::error::Error::Usage(format!(
            "--connect {url}: not a viewer URL ({e}); expected e.g. rerun+http://127.0.0.1:9876/proxy"
        ))
        .into()
    })
}

/// The first executable called `name` on PATH.
pub fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| {
            use std::os::unix::fs::PermissionsExt as _;
            (p.metadata()).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        })
}

/// Chunks cut per entity every 1024 rows, never on a clock, so they depend only on what was
/// logged (Rerun's 200 ms clock cuts identical runs differently). The rows pending at the end are
/// chunked then, one row at a time: 1024 keeps that within a few tenths of a second, so a Ctrl-C
/// is answered within 1 s (4096 took over a second). Rerun's byte count varies between identical
/// runs, so it is off: the scene recorder flushes every [`CHUNK_BYTES`] of its largest 3D entity,
/// counted by itself.
pub const BATCHING: rerun::log::ChunkBatcherConfig = rerun::log::ChunkBatcherConfig {
    flush_tick: std::time::Duration::MAX,
    flush_num_bytes: u64::MAX,
    flush_num_rows: 1024,
    ..rerun::log::ChunkBatcherConfig::DEFAULT
};

/// The chunk size `rerun rrd optimize` compacts to (`ChunkStoreConfig::DEFAULT`: 384 KiB).
pub const CHUNK_BYTES: usize = 12 * 8 * 4096;

/// A recording being written. Its file is a hidden one beside the target (`crate::output`):
/// [`Recording::commit`] finalises it and renames it into place, dropping it uncommitted removes
/// it, so a failed run never leaves a partial file or touches an earlier recording. A write error
/// stops the run at its next check, as a signal would, and `commit` reports it.
pub struct Recording {
    rec: Option<rerun::RecordingStream>,
    file: Option<std::sync::Arc<sink::Shared>>,
    /// Where the file goes, for the size reported.
    target: Option<PathBuf>,
    /// Bytes written to the file so far.
    written: Option<std::sync::Arc<std::sync::atomic::AtomicU64>>,
    /// The live streams to viewers.
    live: Vec<live::Live>,
    /// The plots' value axes, set from the values written when the recording ends.
    axes: Option<(super::axes::LateAxes, super::axes::Extents)>,
}

impl Recording {
    /// Starts a recording with `layout` active, under its own application id (the viewer keys
    /// blueprints by it, so one scene's layout never applies to another's recording). No
    /// wall-clock data: no `log_time` timeline, no start-time property, chunks cut by
    /// [`BATCHING`] except when a viewer streams live.
    pub fn create(
        d: &Destinations,
        application_id: &'static str,
        recording_name: &str,
        layout: Layout,
    ) -> anyhow::Result<Self> {
        check_destinations(d)?;
        let mut sinks: Vec<Box<dyn rerun::sink::LogSink>> = Vec::new();
        let mut file = None;
        let mut target = None;
        let mut written = None;
        if let Some(output) = d.written()? {
            let partial = output.create()?.describing_old(super::provenance::made_by);
            written = Some(partial.written());
            let shared = std::sync::Arc::new(sink::Shared::new(partial)?);
            sinks.push(Box::new(sink::EncodedSink(shared.clone())));
            file = Some(shared);
            target = output.target;
        }
        // The viewers are side channels (`live`): nothing they do reaches the file.
        let mut live = Vec::new();
        if let Some(exe) = d.spawn.then(|| find_on_path("rerun")).flatten() {
            let file = d.file.clone();
            live.push(live::start(
                "--spawn".into(),
                live::Target::Spawn(exe, file),
            ));
        }
        if let Some(url) = &d.connect {
            let uri = parse_proxy_url(url)?;
            if d.file.is_none() && !d.stdout && !d.spawn && !live::answers(&uri) {
                anyhow::bail!(
                    "--connect {url}: no viewer answers there, and --no-save leaves nothing to write \
                     (start `rerun`, or drop --no-save)"
                );
            }
            live.push(live::start(
                format!("--connect {url}"),
                live::Target::Connect(uri),
            ));
        }
        let (live, live_sinks): (Vec<_>, Vec<_>) = live.into_iter().unzip();
        sinks.extend(live_sinks.into_iter().map(|s| Box::new(s) as _));
        let extents = super::axes::Extents::default();
        sinks.push(Box::new(extents.clone()));
        let mut builder = rerun::RecordingStreamBuilder::new(application_id)
            .enabled(true) // the recording is the product: ignore RERUN=off
            .send_properties(false);
        if d.connect.is_none() && !d.spawn {
            builder = builder.batcher_config(BATCHING);
        } // A live viewer needs data as it comes: Rerun's clock-driven default then.
        let rec = builder
            .set_sinks(sinks)
            .context("cannot start the recording")?;
        let axes = Some((layout.send(&rec, application_id)?, extents));
        rec.set_log_time_enabled(false);
        rec.send_recording_name(recording_name)?;
        Ok(Recording {
            rec: Some(rec),
            file,
            target,
            written,
            live,
            axes,
        })
    }

    /// The live streams, for [`live::Live::finish`] once the file is written.
    pub fn take_live(&mut self) -> Vec<live::Live> {
        std::mem::take(&mut self.live)
    }

    /// The count of bytes written to the recording's file so far (none when only streamed).
    pub fn written(&self) -> Option<std::sync::Arc<std::sync::atomic::AtomicU64>> {
        self.written.clone()
    }

    pub fn stream(&self) -> &rerun::RecordingStream {
        self.rec.as_ref().expect("stream is present until commit")
    }

    /// Flushes, writes the footer, fsyncs and renames the file into place. Returns the file's
    /// size.
    pub fn commit(mut self) -> anyhow::Result<Option<u64>> {
        let rec = self.rec.take().expect("commit once");
        let mut flushed = rec.flush_blocking();
        if let (Ok(()), Some((axes, extents))) = (&flushed, self.axes.take()) {
            axes.send(&rec, &extents)?;
            flushed = rec.flush_blocking();
        }
        // Dropping the last handle hands every message still batched to the sinks.
        drop(rec);
        let Some(file) = self.file.take() else {
            flushed.context("cannot flush the recording")?;
            return Ok(None);
        };
        file.finish()?;
        let size = self.target.as_ref().map(std::fs::metadata).transpose()?;
        Ok(size.map(|m| m.len()))
    }
}

impl Drop for Recording {
    fn drop(&mut self) {
        // Uncommitted: the stream is dropped first, then the hidden file with `file`.
        drop(self.rec.take());
    }
}
