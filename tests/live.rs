//! The live stream is a side channel: whatever a viewer does (accepts and stays silent, dies
//! mid-run, answers garbage) or a `rerun` started by `--spawn` does (never listens, exits 1,
//! hangs on `--version`, writes to its standard output), the run ends with one warning, its
//! summary and a complete recording, within a second of the run's own time (the same run and
//! output without a viewer, the slower of one just before and one just after); a viewer that
//! never listened is ended (one opening the file is started in its place), and none holds
//! physlab's standard output.

mod common;

use std::io::{Read as _, Write as _};
use std::net::TcpListener;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{decode, s, scratch_dir};

/// A run's exit code, standard output and error, and its wall time (killed after `limit`).
struct Ran {
    code: Option<i32>,
    stdout: Vec<u8>,
    stderr: String,
    took: Duration,
}

fn run(args: &[&str], path: Option<&Path>, limit: Duration) -> Ran {
    let mut command = Command::new(env!("CARGO_BIN_EXE_physlab"));
    command
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(dir) = path {
        let old = std::env::var("PATH").unwrap_or_default();
        command.env("PATH", format!("{}:{old}", dir.display()));
    }
    let started = Instant::now();
    let mut child = command.spawn().unwrap();
    let out = child.stdout.take().unwrap();
    let err = child.stderr.take().unwrap();
    // Read until end of file: a viewer holding physlab's output would keep it open.
    let read_all = |mut pipe: Box<dyn std::io::Read + Send>| {
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut b = Vec::new();
            let _ = pipe.read_to_end(&mut b);
            tx.send(b)
        });
        rx
    };
    let (stdout, stderr) = (read_all(Box::new(out)), read_all(Box::new(err)));
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if started.elapsed() > limit {
            child.kill().unwrap();
            child.wait().unwrap();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let left = || limit.saturating_sub(started.elapsed());
    let stdout = stdout.recv_timeout(left()).unwrap_or_default();
    let took = started.elapsed();
    let stderr =
        String::from_utf8_lossy(&stderr.recv_timeout(left()).unwrap_or_default()).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    Ran {
        code,
        stdout,
        stderr,
        took,
    }
}

/// A complete recording: footer written, read by `physlab inspect` (and `rerun rrd verify` where
/// the viewer is installed).
fn assert_complete(path: &Path) {
    assert!(decode(path).has_footer, "{}: no footer", path.display());
    let inspect = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(["inspect", s(path)])
        .output()
        .unwrap();
    assert!(inspect.status.success(), "inspect {}", path.display());
    if let Ok(verify) = Command::new("rerun")
        .args(["rrd", "verify", s(path)])
        .output()
    {
        assert!(
            verify.status.success(),
            "rerun rrd verify {}",
            path.display()
        );
    }
}

/// One warning naming the option.
fn assert_one_warning(stderr: &str, option: &str) {
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.contains("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains(option), "{stderr}");
}

/// The pendulum over 50 s: about a second of work and 7 MB of recording.
const RUN: [&str; 5] = ["pendulum", "--duration", "50", "--plot-every", "1"];

/// The same run with the same output (`-o -` or `-o FILE`) and no viewer: the run's own time.
fn alone(output: &str) -> Duration {
    let args = [&RUN[..], &["-o", output]].concat();
    let alone = run(&args, None, Duration::from_secs(120));
    assert_eq!(alone.code, Some(0), "{}", alone.stderr);
    alone.took
}

/// Runs `case` between two runs of its own without a viewer, writing `output` as it does:
/// what `case` gives and its own time, the slower of the two (the load of the machine varies).
fn timed<T>(output: &str, case: impl FnOnce() -> T) -> (T, Duration) {
    let before = alone(output);
    let ran = case();
    (ran, before.max(alone(output)))
}

/// Within a second of the run's own time.
const MARGIN: Duration = Duration::from_secs(1);

#[derive(Clone, Copy, Debug)]
enum Fake {
    /// Accepts and never answers (on main: the run held as long as the peer, then no file).
    Silent,
    /// Answers HTTP/2's opening, takes 30 KB, then closes.
    Dies,
    /// Answers bytes that are no HTTP/2.
    Garbage,
    /// Answers HTTP/2's opening, then takes nothing.
    Stalls,
}

/// A fake viewer on a free local port: its URL.
fn fake_viewer(fake: Fake) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        let mut held = Vec::new();
        for mut c in listener.incoming().flatten() {
            match fake {
                Fake::Silent => held.push(c),
                Fake::Garbage | Fake::Stalls => {
                    let answer = match fake {
                        Fake::Garbage => &[0xde; 256][..],
                        _ => &[0, 0, 0, 4, 0, 0, 0, 0, 0],
                    };
                    let _ = c.write_all(answer);
                    held.push(c);
                }
                Fake::Dies => {
                    std::thread::spawn(move || {
                        let _ = c.write_all(&[0, 0, 0, 4, 0, 0, 0, 0, 0]);
                        let mut buf = [0u8; 4096];
                        let mut got = 0;
                        while got < 30_000 {
                            match c.read(&mut buf) {
                                Ok(0) | Err(_) => break,
                                Ok(n) => got += n,
                            }
                        }
                    });
                }
            }
        }
    });
    format!("rerun+http://127.0.0.1:{port}/proxy")
}

#[test]
fn a_viewer_that_stalls_dies_or_answers_garbage_costs_neither_the_run_nor_its_file() {
    let _turn = rerun_port();
    let dir = scratch_dir("live-connect");
    let alone_out = dir.join("alone.rrd");
    for fake in [Fake::Silent, Fake::Dies, Fake::Garbage] {
        let url = fake_viewer(fake);
        let out = dir.join(format!("{fake:?}.rrd"));
        let mut args = RUN.to_vec();
        args.extend(["--connect", &url, "-o", s(&out)]);
        let (ran, own) = timed(s(&alone_out), || run(&args, None, Duration::from_secs(60)));
        assert_eq!(ran.code, Some(0), "{fake:?}: {}", ran.stderr);
        assert!(
            String::from_utf8_lossy(&ran.stdout).contains("recording:"),
            "{fake:?}: the summary"
        );
        assert_one_warning(&ran.stderr, "--connect");
        assert_complete(&out);
        assert!(
            ran.took < own + MARGIN,
            "{fake:?}: {:?} against {own:?} alone",
            ran.took
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A fake `rerun` in `dir` running `body` (a shell script; each start adds its pid and
/// arguments to `dir/started`).
fn fake_rerun(dir: &Path, body: &str) {
    std::fs::create_dir_all(dir).unwrap();
    let exe = dir.join("rerun");
    std::fs::write(
        &exe,
        format!("#!/bin/sh\necho \"$$ $*\" >> \"$(dirname \"$0\")/started\"\n{body}\n"),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt as _;
    std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// The fake's starts, each its pid and arguments; waited for up to 2 s to number `n`.
fn started(dir: &Path, n: usize) -> Vec<(String, String)> {
    let asked = Instant::now();
    loop {
        let text = std::fs::read_to_string(dir.join("started")).unwrap_or_default();
        let starts: Vec<(String, String)> = (text.lines())
            .map(|l| l.split_once(' ').unwrap_or((l, "")))
            .map(|(pid, args)| (pid.to_string(), args.to_string()))
            .collect();
        if starts.len() >= n || asked.elapsed() > Duration::from_secs(2) {
            return starts;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Whether the process `pid` still runs (a zombie has ended).
fn still_runs(pid: &str) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| !stat.contains(") Z "))
}

/// Rerun's port, which `--spawn` takes a viewer already listening on instead of starting one:
/// the `--spawn` tests take turns, each once nothing listens there (waited for up to a minute);
/// the other timed tests take their turn too, so that no test's runs slow another's.
fn rerun_port() -> std::sync::MutexGuard<'static, ()> {
    static PORT: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let turn = PORT.lock().unwrap_or_else(|e| e.into_inner());
    let asked = Instant::now();
    while std::net::TcpStream::connect("127.0.0.1:9876").is_ok() {
        assert!(
            asked.elapsed() < Duration::from_secs(60),
            "port 9876 stays taken"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    turn
}

#[test]
fn a_spawned_viewer_that_cannot_start_or_never_listens_costs_nothing_and_holds_no_output() {
    let _port = rerun_port();
    let dir = scratch_dir("live-spawn");
    // Exits 1 at once; hangs on `--version` (which physlab never waits on); never listens.
    let cases = [
        ("exits", "echo viewer-output\nexit 1"),
        (
            "version",
            "[ \"$1\" = --version ] && exec sleep 100\nexit 1",
        ),
        ("never", "echo viewer-output\nexec sleep 100"),
    ];
    for (name, body) in cases {
        let bin = dir.join(name);
        fake_rerun(&bin, body);
        // `-o -`: the recording is standard output, where no viewer line may land.
        let args = [&RUN[..], &["--spawn", "-o", "-"]].concat();
        let (ran, own) = timed("-", || run(&args, Some(&bin), Duration::from_secs(60)));
        assert_eq!(ran.code, Some(0), "{name}: {}", ran.stderr);
        assert_one_warning(&ran.stderr, "--spawn");
        let out = dir.join(format!("{name}.rrd"));
        std::fs::write(&out, &ran.stdout).unwrap();
        assert_complete(&out);
        assert!(
            ran.took < own + MARGIN,
            "{name}: {:?} against {own:?}",
            ran.took
        );
        let starts = started(&bin, 1);
        assert!(
            !starts.is_empty() && !starts.iter().any(|(pid, _)| still_runs(pid)),
            "{name}: the viewer that never listened is ended: {starts:?}"
        );
    }

    // Still starting when the run ends, with a file written: not waited for; ended, and a
    // viewer opening the file started in its place (detached; ended here by the test).
    let bin = dir.join("slow");
    fake_rerun(&bin, "exec sleep 100");
    let out = dir.join("slow.rrd");
    let args = [&RUN[..], &["--spawn", "-o", s(&out)]].concat();
    let alone_out = dir.join("alone.rrd");
    let (ran, own) = timed(s(&alone_out), || {
        run(&args, Some(&bin), Duration::from_secs(60))
    });
    assert_eq!(ran.code, Some(0), "{}", ran.stderr);
    assert!(!ran.stderr.contains("warning"), "{}", ran.stderr);
    assert!(ran.stderr.contains("one opening"), "{}", ran.stderr);
    assert_complete(&out);
    assert!(ran.took < own + MARGIN, "{:?} against {own:?}", ran.took);
    let starts = started(&bin, 2);
    let kill = Command::new("kill")
        .args(starts.iter().map(|s| &s.0))
        .stderr(Stdio::null())
        .status();
    drop(kill);
    assert_eq!(starts.len(), 2, "{starts:?}");
    assert!(starts[0].1.starts_with("--port=9876"), "{starts:?}");
    assert_eq!(starts[1].1, s(&out), "{starts:?}");

    // A viewer that listens (and so is kept) but holds its standard output open for a minute:
    // physlab's output ends with physlab (`physlab --spawn | cat` returns).
    let listener = TcpListener::bind("127.0.0.1:9876");
    if let Ok(listener) = listener {
        drop(listener);
        let bin = dir.join("listens");
        let py = "import socket,time\ns=socket.socket()\ns.setsockopt(socket.SOL_SOCKET,socket.SO_REUSEADDR,1)\ns.bind(('127.0.0.1',9876))\ns.listen(8)\nc=[]\nend=time.time()+60\nwhile time.time()<end:\n  a,_=s.accept(); a.sendall(bytes([0,0,0,4,0,0,0,0,0])); c.append(a)";
        fake_rerun(&bin, &format!("exec python3 -c \"{py}\""));
        let out = dir.join("listens.rrd");
        let args = [&RUN[..], &["--spawn", "-o", s(&out)]].concat();
        let (ran, own) = timed(s(&alone_out), || {
            run(&args, Some(&bin), Duration::from_secs(60))
        });
        let _ = Command::new("kill").arg(&started(&bin, 1)[0].0).status();
        assert_eq!(ran.code, Some(0), "{}", ran.stderr);
        assert_complete(&out);
        // Within the stall rule: a viewer that takes no data for 3 s is dropped.
        assert!(
            ran.took < own + Duration::from_secs(5),
            "standard output held: {:?} against {own:?}",
            ran.took
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A viewer that answered HTTP/2's opening and then takes nothing holds the run's end for up to
/// the stall rule's 3 s: a signal then is answered within a second, the file complete.
#[test]
fn a_signal_is_answered_within_a_second_while_a_viewer_is_awaited() {
    let _turn = rerun_port();
    let dir = scratch_dir("live-signal");
    let out = dir.join("p.rrd");
    let url = fake_viewer(Fake::Stalls);
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([
            "pendulum",
            "--duration",
            "5",
            "--connect",
            &url,
            "-o",
            s(&out),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // The summary is out: the run is over and physlab waits for the viewer to take the rest.
    let mut stdout = child.stdout.take().unwrap();
    let mut text = String::new();
    let mut buf = [0u8; 4096];
    while !text.contains("recording:") {
        let n = stdout.read(&mut buf).unwrap();
        assert!(n > 0, "ended before its summary: {text}");
        text.push_str(&String::from_utf8_lossy(&buf[..n]));
    }
    std::thread::sleep(Duration::from_millis(300));
    assert!(child.try_wait().unwrap().is_none(), "no wait to signal");
    let _ = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status();
    let signalled = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if signalled.elapsed() > Duration::from_secs(5) {
            child.kill().unwrap();
            child.wait().unwrap();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    assert!(
        signalled.elapsed() < Duration::from_secs(1),
        "{:?} after the signal",
        signalled.elapsed()
    );
    assert_eq!(code, Some(130));
    assert_complete(&out);
    std::fs::remove_dir_all(&dir).unwrap();
}
