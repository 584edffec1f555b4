//! The live stream to a viewer (`--connect`, `--spawn`), a side channel the file never waits
//! for: [`LiveSink`] queues every message for a thread of its own, which connects (or starts the
//! viewer) and feeds Rerun's gRPC sink, so that sink's waits (for ever, on a connection that
//! never answers) are that thread's alone. Any failure ends the stream with one warning; the
//! run, its summary and its file go on.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use rerun::external::re_uri::ProxyUri;
use rerun::log::LogMsg;
use rerun::sink::{GrpcSink, GrpcSinkConnectionState, LogSink, SinkFlushError};

/// A viewer that takes no data for this long while data waits for it is dropped.
pub const STALL: Duration = Duration::from_secs(3);
/// How long a viewer physlab starts has to listen (a real one may take several seconds).
const SPAWN_WAIT: Duration = Duration::from_secs(10);
/// Messages waiting for the viewer at most, in bytes of their Arrow buffers.
const BACKLOG_BYTES: usize = 128 << 20;

/// Where the stream goes: a viewer's URL, or a `rerun` executable to start (and the file the
/// run writes, for a viewer still starting when the run ends).
pub enum Target {
    Connect(ProxyUri),
    Spawn(PathBuf, Option<PathBuf>),
}

struct State {
    queue: VecDeque<LogMsg>,
    bytes: usize,
    /// When the viewer last took a message (or the stream started).
    progress: Instant,
    /// While a started viewer is not yet listening: until when it may take.
    starting: Option<Instant>,
    /// The run is over: no more messages come.
    closed: bool,
    /// The stream is over: everything delivered, or dropped.
    ended: bool,
    /// The viewer thread is handing a message (or the final flush) to Rerun's sink.
    busy: bool,
}

struct Shared {
    state: Mutex<State>,
    changed: Condvar,
    /// The option as given, for the warning: `--connect URL`, `--spawn`.
    option: String,
    /// The viewer physlab started, until it listens.
    child: Mutex<Option<Child>>,
    /// `rerun` and the run's file, for [`Live::finish`] to hand a viewer still starting.
    hand_off: Option<(PathBuf, PathBuf)>,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Ends the stream, with one warning when `why` is given (none for a second reason); a
    /// viewer physlab started that never listened is ended too.
    fn drop_stream(&self, state: &mut State, why: Option<&str>) {
        if let (false, Some(why)) = (state.ended, why) {
            eprintln!(
                "warning: {}: {why}; streaming stopped, the run and its recording go on",
                self.option
            );
        }
        state.ended = true;
        state.queue.clear();
        state.bytes = 0;
        self.changed.notify_all();
        if let Some(mut child) = self.child().take() {
            // Its whole process group (pip's `rerun` is a script running the viewer as its child),
            // while its id is still its own: not reaped yet.
            if let Ok(None) = child.try_wait() {
                // SAFETY: kill has no preconditions; the group is the child's own (`viewer`).
                unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
            }
        }
    }

    fn child(&self) -> MutexGuard<'_, Option<Child>> {
        self.child.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits for a change for at most 50 ms.
    fn wait<'a>(&self, s: MutexGuard<'a, State>) -> MutexGuard<'a, State> {
        let waited = self.changed.wait_timeout(s, Duration::from_millis(50));
        waited.unwrap_or_else(|e| e.into_inner()).0
    }

    /// Why the stream should be dropped now, if it should; `waiting`: the run's thread waits
    /// for the viewer, which a signal ends.
    fn stalled(&self, s: &State, waiting: bool) -> Option<String> {
        if waiting && crate::interrupt::requested() {
            return Some("stopped by a signal before the viewer took all the data".into());
        }
        match s.starting {
            Some(deadline) => (Instant::now() > deadline).then(|| {
                format!(
                    "the viewer started did not listen within {} s",
                    SPAWN_WAIT.as_secs()
                )
            }),
            None => ((!s.queue.is_empty() || s.busy) && s.progress.elapsed() > STALL)
                .then(|| format!("the viewer took no data for {} s", STALL.as_secs())),
        }
    }
}

/// The stream's handle for the run; dropping it leaves the viewer thread to itself.
pub struct Live(Arc<Shared>);

/// The sink the recording stream is given: it queues messages for the viewer thread.
pub struct LiveSink(Arc<Shared>);

/// Starts the stream's thread and returns the handle and the sink for the recording stream.
pub fn start(option: String, target: Target) -> (Live, LiveSink) {
    let starting = matches!(target, Target::Spawn(..)).then(|| Instant::now() + SPAWN_WAIT);
    let hand_off = match &target {
        Target::Spawn(exe, Some(file)) => Some((exe.clone(), file.clone())),
        _ => None,
    };
    let shared = Arc::new(Shared {
        state: Mutex::new(State {
            queue: VecDeque::new(),
            bytes: 0,
            progress: Instant::now(),
            starting,
            closed: false,
            ended: false,
            busy: false,
        }),
        changed: Condvar::new(),
        option,
        child: Mutex::new(None),
        hand_off,
    });
    let feeding = shared.clone();
    let spawned = std::thread::Builder::new()
        .name("physlab-viewer".into())
        .spawn(move || feed(&feeding, target));
    if let Err(e) = spawned {
        shared.drop_stream(
            &mut shared.lock(),
            Some(&format!("cannot start a thread ({e})")),
        );
    }
    (Live(shared.clone()), LiveSink(shared))
}

impl Live {
    /// After the run: waits while the viewer takes the queued messages, until all are taken,
    /// it stalls, or a signal comes. A viewer physlab started that does not listen yet is not
    /// waited for: it is ended, and one opening the run's file is started instead, if any.
    pub fn finish(self) {
        let mut s = self.0.lock();
        s.closed = true;
        self.0.changed.notify_all();
        if s.starting.is_some() && !s.ended {
            if let Some((exe, file)) = &self.0.hand_off {
                self.0.drop_stream(&mut s, None);
                return open_later(exe, file);
            }
            let why = "the viewer started was not listening when the run ended, and no file was \
                       written for it to open";
            return self.0.drop_stream(&mut s, Some(why));
        }
        while !s.ended {
            if let Some(why) = self.0.stalled(&s, true) {
                self.0.drop_stream(&mut s, Some(&why));
                break;
            }
            s = self.0.wait(s);
        }
    }
}

impl Drop for Live {
    /// After a failed run too: the thread stops, and a viewer that never listened is ended.
    fn drop(&mut self) {
        self.0.drop_stream(&mut self.0.lock(), None);
    }
}

impl LogSink for LiveSink {
    fn send(&self, msg: LogMsg) {
        let size = size(&msg);
        let shared = &self.0;
        let mut s = shared.lock();
        loop {
            if s.ended {
                return;
            }
            let full = !s.queue.is_empty() && s.bytes + size > BACKLOG_BYTES;
            if let Some(why) = shared.stalled(&s, full) {
                shared.drop_stream(&mut s, Some(&why));
                return;
            }
            if !full {
                break;
            }
            // A full backlog waits for the viewer while it takes data (within the stall rule).
            s = shared.wait(s);
        }
        if s.queue.is_empty() {
            s.progress = Instant::now(); // the wait for the viewer starts now
        }
        s.bytes += size;
        s.queue.push_back(msg);
        shared.changed.notify_all();
    }

    /// The file never waits for the viewer: [`Live::finish`] does, after the file is written.
    fn flush_blocking(&self, _timeout: Duration) -> Result<(), SinkFlushError> {
        Ok(())
    }
}

/// A message's bytes, as the backlog counts them.
fn size(msg: &LogMsg) -> usize {
    match msg {
        LogMsg::ArrowMsg(_, m) => m.batch.get_array_memory_size(),
        _ => 1024,
    }
}

/// The viewer thread: reaches the viewer, then hands it the queued messages until all are taken
/// or the stream is dropped.
fn feed(shared: &Shared, target: Target) {
    let uri = match target {
        Target::Connect(uri) => Ok(uri),
        Target::Spawn(exe, _) => spawn(shared, &exe),
    };
    if let Err(why) = uri.as_ref().map_err(Clone::clone).and_then(handshake) {
        return shared.drop_stream(&mut shared.lock(), Some(&why));
    }
    let mut s = shared.lock();
    (s.starting, s.progress) = (None, Instant::now());
    shared.child().take(); // it listens: it stays
    drop(s);
    let sink = GrpcSink::new(uri.expect("checked"));
    loop {
        let msg = {
            let mut s = shared.lock();
            while s.queue.is_empty() && !s.closed && !s.ended {
                s = shared.changed.wait(s).unwrap_or_else(|e| e.into_inner());
            }
            if s.ended {
                // Its own flush on drop would wait for ever on a stalled connection.
                return std::mem::forget(sink);
            }
            s.busy = true;
            s.progress = Instant::now();
            let Some(msg) = s.queue.pop_front() else {
                break; // closed and all handed on: the final flush
            };
            s.bytes = s.bytes.saturating_sub(size(&msg));
            msg
        };
        sink.send(msg);
        let mut s = shared.lock();
        s.busy = false;
        s.progress = Instant::now();
        if let GrpcSinkConnectionState::Disconnected(how) = sink.status() {
            let why = match how {
                Ok(()) => "the viewer closed the connection".to_string(),
                Err(e) => format!("the connection failed ({e})"),
            };
            shared.drop_stream(&mut s, Some(&why));
            return std::mem::forget(sink);
        }
        shared.changed.notify_all();
    }
    let flushed = sink.flush_blocking(STALL);
    let mut s = shared.lock();
    match flushed {
        Ok(()) => {
            // Closed before the stream is said to be over, so that the viewer sees its end.
            s.progress = Instant::now();
            drop(s);
            drop(sink);
            shared.lock().ended = true;
            shared.changed.notify_all();
        }
        Err(e) => {
            let why = format!("the viewer did not take the last data ({e})");
            shared.drop_stream(&mut s, Some(&why));
            std::mem::forget(sink);
        }
    }
}

/// Whether a viewer listens at `uri`, asked on a thread of its own (a name lookup can hang)
/// and given up after a second or a signal.
pub fn answers(uri: &ProxyUri) -> bool {
    let (tx, rx) = std::sync::mpsc::channel();
    let uri = uri.clone();
    std::thread::spawn(move || tx.send(listens(&uri, Duration::from_secs(1))));
    let asked = Instant::now();
    while asked.elapsed() < Duration::from_millis(1100) && !crate::interrupt::requested() {
        if let Ok(answer) = rx.recv_timeout(Duration::from_millis(50)) {
            return answer;
        }
    }
    false
}

/// The viewer's first answer, within a second: a gRPC server answers HTTP/2's opening with a
/// SETTINGS frame at once (over TLS for `rerun+https`, where plain HTTP/2 is the mistake), so a
/// connection that accepts and stays silent, or answers something else, is found before any
/// data waits on it.
fn handshake(uri: &ProxyUri) -> Result<(), String> {
    use std::io::{Read as _, Write as _};
    let limit = Duration::from_secs(1);
    let addr = *(addresses(uri).first()).ok_or("the viewer's address does not resolve")?;
    let mut head = [0u8; 9];
    let connected = std::net::TcpStream::connect_timeout(&addr, limit);
    let Ok(mut c) = connected else {
        return Err("no viewer answers there; writing the file only".into());
    };
    let answer = (|| {
        c.set_read_timeout(Some(limit))?;
        c.set_write_timeout(Some(limit))?;
        c.write_all(b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n\0\0\0\x04\0\0\0\0\0")?;
        c.read_exact(&mut head)
    })();
    let tls = matches!(
        uri.origin.scheme,
        rerun::external::re_uri::Scheme::RerunHttps
    );
    match answer {
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
            ) =>
        {
            Err("the viewer accepted the connection but did not answer within 1 s".into())
        }
        Ok(()) if head[3] == 4 && tls => {
            Err("what answers there speaks plain HTTP, not TLS (use rerun+http://)".into())
        }
        Ok(()) if head[3] != 4 && !tls => {
            Err("what answers there is no viewer (its answer is not HTTP/2)".into())
        }
        Err(e) if !tls => Err(format!("the viewer closed the connection at once ({e})")),
        _ => Ok(()),
    }
}

/// Whether something accepts connections at the viewer's address within `limit`.
fn listens(uri: &ProxyUri, limit: Duration) -> bool {
    (addresses(uri).iter()).any(|a| std::net::TcpStream::connect_timeout(a, limit).is_ok())
}

/// The viewer's addresses (none where its host does not resolve).
fn addresses(uri: &ProxyUri) -> Vec<std::net::SocketAddr> {
    use std::net::ToSocketAddrs as _;
    let (host, port) = (uri.origin.host.to_string(), uri.origin.port);
    (host, port)
        .to_socket_addrs()
        .map_or(Vec::new(), Iterator::collect)
}

/// Starts `exe FILE`, a viewer that opens the run's complete file itself, detached as
/// [`viewer`] makes it and never waited for; says so on stderr.
fn open_later(exe: &std::path::Path, file: &std::path::Path) {
    let started = viewer(exe).arg(file).spawn();
    match started {
        Ok(_) => eprintln!(
            "--spawn: the viewer was not listening yet when the run ended; one opening {} was \
             started instead",
            file.display()
        ),
        Err(e) => eprintln!(
            "warning: --spawn: the viewer was not listening when the run ended, and cannot be \
             started again ({e}); open {} later",
            file.display()
        ),
    }
}

/// A `rerun` command with its own standard streams and process group, so that it writes
/// nothing into physlab's output, holds no pipe of it open and is not stopped by a Ctrl-C meant
/// for physlab.
fn viewer(exe: &std::path::Path) -> Command {
    use std::os::unix::process::CommandExt as _;
    let mut command = Command::new(exe);
    command
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .process_group(0);
    command
}

/// Starts the viewer `exe` on Rerun's port (or takes the one already listening there, as Rerun's
/// own spawn does) as [`viewer`] makes it; waits until it listens, it exits, the time runs
/// out or the stream is dropped.
fn spawn(shared: &Shared, exe: &std::path::Path) -> Result<ProxyUri, String> {
    let port = rerun::DEFAULT_SERVER_PORT;
    let uri: ProxyUri = format!("rerun+http://127.0.0.1:{port}/proxy")
        .parse()
        .map_err(|e| format!("{e}"))?;
    if listens(&uri, Duration::from_millis(500)) {
        return Ok(uri);
    }
    let child = viewer(exe)
        .args([
            format!("--port={port}"),
            "--memory-limit=75%".into(),
            "--server-memory-limit=1GiB".into(),
            "--expect-data-soon".into(),
        ])
        .spawn()
        .map_err(|e| format!("cannot start {} ({e})", exe.display()))?;
    *shared.child() = Some(child);
    loop {
        if listens(&uri, Duration::from_millis(200)) {
            return Ok(uri);
        }
        let exited = match shared.child().as_mut() {
            Some(child) => child.try_wait().ok().flatten(),
            None => return Err("the stream was dropped".into()),
        };
        if let Some(status) = exited {
            return Err(format!("the viewer exited ({status}) before listening"));
        }
        let s = shared.lock();
        if s.ended {
            return Err("the stream was dropped".into());
        }
        if let Some(why) = shared.stalled(&s, false) {
            return Err(why);
        }
        drop(s);
        std::thread::sleep(Duration::from_millis(100));
    }
}
