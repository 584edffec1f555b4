//! The files physlab makes and the process around them (issues 43 and 44): temporary files and
//! hidden partials never written through a planted symlink, a partial that a live writer holds
//! locked left alone whatever its PID, a reader that leaves standard output early, failures of
//! `reproduce` and `diff` exit 2 naming what failed, resource limits (file size, open files,
//! threads, address space) named, a closed standard output refused, replaced outputs keeping
//! their mode, a read-only output refused, and a study's outputs written as one set.
//! The file system's own view (bytes, modes, listings) is the judge.

#![cfg(feature = "rerun")]

mod common;

use std::os::unix::fs::PermissionsExt as _;
use std::os::unix::process::CommandExt as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{partials, physlab, s, scratch_dir};

/// A small, complete recording (about 60 KB).
fn good_recording(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    common::record_pendulum(&path, "0.01", "2");
    path
}

/// physlab `args` with `setup` run in the child before it starts (limits, closed descriptors).
fn physlab_with(
    args: &[&str],
    env: &[(&str, &Path)],
    setup: fn() -> std::io::Result<()>,
) -> Output {
    physlab_at(Path::new(env!("CARGO_BIN_EXE_physlab")), args, env, setup)
}

/// [`physlab_with`] for the binary at `program`.
fn physlab_at(
    program: &Path,
    args: &[&str],
    env: &[(&str, &Path)],
    setup: fn() -> std::io::Result<()>,
) -> Output {
    let mut command = Command::new(program);
    command.args(args).stdin(Stdio::null());
    for (key, value) in env {
        command.env(key, value);
    }
    // SAFETY: `setup` calls only async-signal-safe functions (setrlimit, close, umask, setuid).
    unsafe { command.pre_exec(setup) };
    command.output().unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn set_limit(resource: libc::__rlimit_resource_t, value: u64) -> std::io::Result<()> {
    let r = libc::rlimit {
        rlim_cur: value,
        rlim_max: value,
    };
    // SAFETY: one valid rlimit.
    if unsafe { libc::setrlimit(resource, &r) } == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// The file-size limit the tests set: 32 KiB, under a recording's size.
const FSIZE: u64 = 32 * 1024;

fn file_size_limit() -> std::io::Result<()> {
    set_limit(libc::RLIMIT_FSIZE, FSIZE)
}

/// The PIDs the next processes are likely to get (the last one given out, plus 1..=n).
fn next_pids(n: u32) -> std::ops::RangeInclusive<u32> {
    let last: u32 = std::fs::read_to_string("/proc/sys/kernel/ns_last_pid")
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    last + 1..=last + n
}

fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Issue 43.1: `reproduce` used `$TMPDIR/physlab-PID-reproduce.{toml,rrd}`, following a
/// symlink planted there (its embedded text and its re-run then replaced the link's target);
/// a writer's hidden `.NAME.PID.partial` was opened through a symlink as well. Symlinks are
/// planted at those names for the PIDs the command is about to get; the file they point at must
/// stay as it was, and the temporary folder must be left as found.
#[test]
fn symlinks_planted_at_predictable_temporary_and_partial_names_are_never_followed() {
    let dir = scratch_dir("files-symlinks");
    let good = good_recording(&dir, "a.rrd");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let victim = dir.join("victim");
    std::fs::write(&victim, "precious").unwrap();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    for pid in next_pids(400) {
        for name in [
            format!("physlab-{pid}-reproduce.toml"),
            format!("physlab-{pid}-reproduce.rrd"),
        ] {
            std::os::unix::fs::symlink(&victim, tmp.join(name)).unwrap();
        }
        std::os::unix::fs::symlink(&victim, out.join(format!(".r.rrd.{pid}.partial"))).unwrap();
    }
    let planted = entries(&tmp);
    let run = physlab_with(&["reproduce", s(&good)], &[("TMPDIR", &tmp)], || Ok(()));
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert_eq!(entries(&tmp), planted, "reproduce left files in TMPDIR");

    let r = out.join("r.rrd");
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.5", "-o", s(&r)]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    assert!(
        std::fs::symlink_metadata(&r).unwrap().is_file(),
        "r.rrd is no regular file"
    );
    common::decode(&r);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `-o l.rrd` where l.rrd is a symlink to a file that is not a recording (run as root against
/// /etc/passwd, the run replaced it): refused with exit 2 naming the link and its target, the
/// file untouched. A link to a recording is still written through, its target replaced.
#[test]
fn a_symlinked_output_never_replaces_a_file_that_is_not_a_recording() {
    let dir = scratch_dir("files-symlinked-output");
    let victim = dir.join("passwd");
    std::fs::write(&victim, "root:x:0:0:root:/root:/bin/bash\n").unwrap();
    let link = dir.join("l.rrd");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.5", "-o", s(&link)]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("l.rrd") && err.contains("passwd") && err.contains("not a Rerun recording"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(&victim).unwrap(),
        "root:x:0:0:root:/root:/bin/bash\n"
    );

    let recording = good_recording(&dir, "a.rrd");
    let to_recording = dir.join("m.rrd");
    std::os::unix::fs::symlink(&recording, &to_recording).unwrap();
    let (code, _, err) = physlab(&[
        "pendulum",
        "-q",
        "--duration",
        "0.5",
        "-o",
        s(&to_recording),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        std::fs::symlink_metadata(&to_recording)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    common::decode(&recording);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A file name holding ESC (a name the user was handed, or pasted): the "recording:" and
/// "replaced" lines show it escaped (`\x1b`), so the terminal never acts on it.
#[test]
fn a_written_path_with_control_characters_is_shown_escaped() {
    let dir = scratch_dir("files-escaped-path");
    let out = dir.join("a\x1b[2Jb.rrd");
    for _ in 0..2 {
        let run = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["pendulum", "--duration", "0.5", "-o", s(&out)])
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(0));
        let all = [run.stdout, run.stderr].concat();
        assert!(!all.contains(&0x1b), "{}", String::from_utf8_lossy(&all));
        assert!(String::from_utf8_lossy(&all).contains("a\\x1b[2Jb.rrd"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 43 point 7: a hidden partial whose writer lives (in another PID namespace, on another
/// NFS client: its PID is not running here) holds it locked; it is left alone. Unlocked, it is
/// stale and removed when its target is written again.
#[test]
fn a_partial_a_live_writer_holds_locked_is_kept_whatever_its_pid() {
    let dir = scratch_dir("files-locked-partial");
    let out = dir.join("r.rrd");
    // A PID above Linux's largest (4194304): no process here has it.
    let partial = dir.join(".r.rrd.4194399.partial");
    std::fs::write(&partial, "half a recording").unwrap();
    let writer = std::fs::File::open(&partial).unwrap();
    writer.lock().unwrap();
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.2", "-o", s(&out)]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read_to_string(&partial).ok().as_deref(),
        Some("half a recording"),
        "a live writer's partial was removed"
    );
    drop(writer);
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.2", "-o", s(&out)]);
    assert_eq!(code, 0, "{err}");
    assert!(!partial.exists(), "a stale partial was kept");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs physlab with standard output a pipe whose reader has already left (`| head` done).
fn with_reader_gone(args: &[&str], tmp: &Path) -> (Option<i32>, String) {
    // The reader closed before physlab starts: a short output (`methods`) cannot slip into the
    // pipe's buffer before it goes.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args(args)
        .env("TMPDIR", tmp)
        .stdout(writer)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    (out.status.code(), text(&out.stderr))
}

/// Issue 43.2: `reproduce … -v | head -1` was killed by SIGPIPE and left its temporary files;
/// `diff … -o d.rrd | head -1` left its partial. Now the command ends quietly with 141 (the
/// status a shell shows for a reader that left) and nothing is left behind; the same for a
/// recording written to standard output (`-o -`).
#[test]
fn a_reader_that_leaves_standard_output_early_ends_the_command_and_leaves_nothing() {
    let dir = scratch_dir("files-pipe");
    let good = good_recording(&dir, "a.rrd");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let d = dir.join("d.rrd");
    for args in [
        vec!["reproduce", s(&good), "-v"],
        vec!["diff", s(&good), s(&good), "-o", s(&d)],
        vec!["pendulum", "--duration", "2", "-o", "-"],
        vec!["methods"],
    ] {
        let (code, err) = with_reader_gone(&args, &tmp);
        assert_eq!(code, Some(141), "{args:?}: {err}");
        assert!(
            !err.contains("error") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
        assert_eq!(entries(&tmp), Vec::<String>::new(), "{args:?}");
        assert!(
            !d.exists() && partials(&dir).is_empty(),
            "{args:?}: {:?}",
            entries(&dir)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issues 43.11 and 43.15: a failed write in `reproduce` or `diff` exited 1 ("they differ"), or
/// died of SIGXFSZ under a file-size limit. Now it is 2, the message names what failed (the
/// temporary file as such when no `-o` was given, else the `-o` path) and the limit, and
/// nothing is left behind. A scene command's failed write exits 1 (a runtime failure, as
/// documented) with the old file kept byte for byte.
#[test]
fn failed_writes_under_a_file_size_limit_are_named_and_leave_nothing() {
    let dir = scratch_dir("files-fsize");
    let good = good_recording(&dir, "a.rrd");
    let tmp = dir.join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let limit = format!("file-size limit of {FSIZE} bytes");

    let run = physlab_with(
        &["reproduce", s(&good)],
        &[("TMPDIR", &tmp)],
        file_size_limit,
    );
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("temporary file") && err.contains(&limit),
        "{err}"
    );
    assert!(!err.contains("-o "), "blames an -o never given: {err}");
    assert_eq!(entries(&tmp), Vec::<String>::new());

    let d = dir.join("d.rrd");
    let run = physlab_with(
        &["diff", s(&good), s(&good), "-o", s(&d)],
        &[],
        file_size_limit,
    );
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("-o {}", s(&d))) && err.contains(&limit),
        "{err}"
    );
    assert!(
        !d.exists() && partials(&dir).is_empty(),
        "{:?}",
        entries(&dir)
    );

    let old = dir.join("old.rrd");
    std::fs::write(&old, "a good old file").unwrap();
    let run = physlab_with(&["pendulum", "-q", "-o", s(&old)], &[], file_size_limit);
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!("-o {}", s(&old))) && err.contains(&limit),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&old).unwrap(), "a good old file");
    assert!(partials(&dir).is_empty(), "{:?}", entries(&dir));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 43.15: with standard output closed the summary was lost and the run exited 0.
#[test]
fn a_closed_standard_output_is_refused() {
    let run = physlab_with(
        &["pendulum", "--duration", "0.2", "--no-record"],
        &[],
        || {
            // SAFETY: closing a descriptor.
            unsafe { libc::close(1) };
            Ok(())
        },
    );
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(err.contains("standard output is closed"), "{err}");
}

/// Issue 44.3: a replaced output took the default mode (a 0600 recording became 0644), and a
/// read-only CSV was replaced (the rename needs only the folder). The mode is read from the
/// file's permission bits, so the test holds as root too.
#[test]
fn a_replaced_output_keeps_its_mode_and_a_read_only_one_is_refused() {
    let dir = scratch_dir("files-mode");
    let r = dir.join("r.rrd");
    let umask = || {
        // SAFETY: umask has no preconditions.
        unsafe { libc::umask(0o022) };
        Ok(())
    };
    let args = ["pendulum", "-q", "--duration", "0.2", "-o", s(&r)];
    assert_eq!(physlab_with(&args, &[], umask).status.code(), Some(0));
    std::fs::set_permissions(&r, std::fs::Permissions::from_mode(0o600)).unwrap();
    let run = physlab_with(&args, &[], umask);
    assert_eq!(run.status.code(), Some(0), "{}", text(&run.stderr));
    let mode = std::fs::metadata(&r).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600, "the replaced recording's mode is {mode:o}");

    let csv = dir.join("c.csv");
    std::fs::write(&csv, "a read-only table").unwrap();
    std::fs::set_permissions(&csv, std::fs::Permissions::from_mode(0o444)).unwrap();
    let started = Instant::now();
    let (code, _, err) = physlab(&[
        "study",
        "convergence",
        "--levels",
        "2",
        "--methods",
        "rk4",
        "--csv",
        s(&csv),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("read-only") && err.contains(s(&csv)), "{err}");
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "refused after the work"
    );
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "a read-only table");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 44.4: two studies writing the same `--csv`/`--plots` at once left the CSV of one and
/// the figures of the other. A study writes its set with its folders locked: while another
/// writer (here the test) holds the folder, it writes nothing; once released, it writes the
/// whole set.
#[test]
fn a_study_writes_its_outputs_as_one_set_while_holding_their_folder() {
    let dir = scratch_dir("files-study-lock");
    let csv = dir.join("c.csv");
    let other_writer = std::fs::File::open(&dir).unwrap();
    other_writer.lock().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
        .args([
            "study",
            "convergence",
            "--levels",
            "2",
            "--methods",
            "rk4",
            "--csv",
            s(&csv),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(3) && child.try_wait().unwrap().is_none() {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(
        child.try_wait().unwrap().is_none() && !csv.exists(),
        "the study wrote while another writer held its folder"
    );
    drop(other_writer);
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let written = std::fs::read_to_string(&csv).unwrap();
    assert!(written.contains("rk4"), "{written}");
    assert!(
        dir.join("c-pendulum-convergence.png").exists(),
        "{:?}",
        entries(&dir)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 44.4 as the user met it: two studies (RK4 and Verlet) writing one `--csv` and
/// `--plots` at once, 8 times; each time the CSV, the SVG and the PNG's stamped data are all one
/// study's (today's main mixed them in 8 of 12 tries).
#[test]
fn two_studies_writing_one_set_at_once_leave_one_study_s_set() {
    let dir = scratch_dir("files-study-race");
    let csv = dir.join("c.csv");
    let study = |method: &str| {
        Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["study", "convergence", "--levels", "2", "--methods", method])
            .args(["--csv", s(&csv), "--plots", s(&dir)])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap()
    };
    for _ in 0..8 {
        let (mut a, mut b) = (study("rk4"), study("verlet"));
        assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
        // The PNG's data is in its tEXt chunk (`rk4 dt=…` lines): a longer needle than its
        // compressed pixels could hold by chance.
        let rk4: Vec<bool> = [
            ("c.csv", "rk4"),
            ("pendulum-convergence.svg", "rk4"),
            ("pendulum-convergence.png", "rk4 dt="),
        ]
        .iter()
        .map(|(file, needle)| text(&std::fs::read(dir.join(file)).unwrap()).contains(needle))
        .collect();
        assert!(
            rk4 == [true; 3] || rk4 == [false; 3],
            "a mixed set: {rk4:?}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 44.8: under resource limits the error names its cause: too few open files
/// (`ulimit -n 4`; a good file was called "unusable"; physlab asks for 16 up front), no threads
/// (`ulimit -u`; "Resource temporarily unavailable" with no subject), and the address-space
/// limit (`ulimit -v`), which the memory guard counts beside MemAvailable (a run it admitted
/// aborted allocating).
#[test]
fn errors_under_resource_limits_name_their_cause() {
    let dir = scratch_dir("files-limits");
    let good = good_recording(&dir, "a.rrd");

    let run = physlab_with(&["inspect", s(&good)], &[], || {
        set_limit(libc::RLIMIT_NOFILE, 4)
    });
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("too many open files") && err.contains("ulimit -n"),
        "{err}"
    );

    // A copy of the binary where nobody may run it (the build folder may be under a private
    // home, as CI's is).
    let open = scratch_dir("files-nproc-binary");
    let program = open.join("physlab");
    std::fs::copy(env!("CARGO_BIN_EXE_physlab"), &program).unwrap();
    for path in [&open, &program] {
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let run = physlab_at(
        &program,
        &["pendulum", "--no-record", "--duration", "0.2"],
        &[],
        || {
            set_limit(libc::RLIMIT_NPROC, 1)?;
            // Root is not held to RLIMIT_NPROC: run as nobody.
            // SAFETY: setgid and setuid have no memory preconditions.
            unsafe {
                if libc::geteuid() == 0 && (libc::setgid(65534) != 0 || libc::setuid(65534) != 0) {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        },
    );
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(
        err.contains("no threads available") && err.contains("ulimit -u"),
        "{err}"
    );
    std::fs::remove_dir_all(&open).unwrap();

    // About 2.5 GB of state under a 2 GiB address space: refused up front,
    // naming the limit (it aborted allocating).
    let started = Instant::now();
    let run = physlab_with(
        &[
            "rope",
            "--nodes",
            "2000000",
            "--no-record",
            "--duration",
            "0.001",
        ],
        &[],
        || set_limit(libc::RLIMIT_AS, 2 << 30),
    );
    let err = text(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{err}");
    assert!(
        err.contains("address-space limit") && err.contains("ulimit -v"),
        "{err}"
    );
    assert!(started.elapsed() < Duration::from_secs(5));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 44.8: a count too large for any scene file (over 2^63 - 1) said "u64 value was too
/// large", exit 1, and one over 2^64 - 1 clap's "number too large to fit in target type", neither
/// naming the option's range. Every count now says its option, the value and the range, exit 2.
#[test]
fn an_oversized_count_names_its_option() {
    let (i64_max, u32_max) = ("9223372036854775807", "4294967295");
    let cases = [
        (
            &["pendulum", "--plot-every"][..],
            "9223372036854775808",
            i64_max,
        ),
        (&["rope", "--nodes"], "9223372036854775808", i64_max),
        (&["rope", "--nodes"], "99999999999999999999", i64_max),
        (&["hair", "--strands"], "9223372036854775808", i64_max),
        (&["hair", "--strands"], "99999999999999999999", i64_max),
        (&["hair", "--log-strands"], "18446744073709551616", i64_max),
        (&["hair", "--nodes"], "9223372036854775808", i64_max),
        (&["hair", "--threads"], "99999999999999999999", i64_max),
        (&["all", "--plot-every"], "99999999999999999999", i64_max),
        (
            &["study", "stability", "--steps"],
            "99999999999999999999",
            i64_max,
        ),
        (
            &["rope", "--newton-iterations"],
            "99999999999999999999",
            u32_max,
        ),
        (&["rope", "--pinned"], "9223372036854775808", i64_max),
    ];
    for (command, value, max) in cases {
        let args = [command, &[value]].concat();
        let (code, _, err) = physlab(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        let flag = command.last().unwrap();
        assert!(
            err.contains(&format!("{flag} <N>"))
                || err.contains(&format!("{flag} {value}:"))
                || err.contains(&format!("'{value}' for '{flag}")),
            "{args:?}: {err}"
        );
        assert!(err.contains(value) && err.contains(max), "{args:?}: {err}");
    }
    // An oversized item of a list is the one named.
    let (code, _, err) = physlab(&["rope", "--pinned", "0,99999999999999999999"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--pinned 99999999999999999999: must be a whole number from 0 to"),
        "{err}"
    );
}

/// `date -u -d @SECONDS`: the clock's reading as GNU date writes it (independent of physlab's).
fn gnu_date(seconds: u64) -> String {
    let out = Command::new("date")
        .args(["-u", "-d", &format!("@{seconds}"), "+%Y-%m-%d %H:%M:%S UTC"])
        .output()
        .unwrap();
    text(&out.stdout).trim().to_string()
}

fn now() -> u64 {
    std::time::UNIX_EPOCH.elapsed().unwrap().as_secs()
}

/// Issue 41.4: a second `physlab pendulum` replaced the first recording without a word. Now the
/// lines `replaced FILE` and `(from `COMMAND` at TIME)` say it: the old recording's own command line
/// (its first 40 characters, the program by its file name) and the time it was made (within the seconds the first run took, read by GNU date), its
/// command line escaped when the old file holds control characters; a file that is no physlab
/// recording is said with its last write.
#[test]
fn a_replaced_recording_is_said_with_the_command_and_time_that_made_it() {
    let dir = scratch_dir("replaced-said");
    let r = dir.join("r.rrd");
    let first = ["pendulum", "-q", "--duration", "0.2", "-o", s(&r)];
    let before = now();
    let (code, _, err) = physlab(&first);
    let after = now();
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("replaced"), "{err}");
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.3", "-o", s(&r)]);
    assert_eq!(code, 0, "{err}");
    // On the line after the path: the program by its file name and the command's words up to
    // 40 characters, so that the line fits a terminal whatever the old file holds.
    let said = format!("replaced {}\n  (", s(&r));
    let at = err.find(&said).map_or(err.len(), |i| i + said.len() - 1);
    let line = err[at..].lines().next().unwrap_or("");
    assert!(
        line.starts_with("(from `physlab pendulum -q --duration 0.2 -o …` at "),
        "{err}"
    );
    assert!(
        (before..=after).any(|t| line.ends_with(&format!(" at {})", gnu_date(t)))),
        "{line}: made between {} and {}",
        gnu_date(before),
        gnu_date(after)
    );

    // A recording whose command line would clear the screen: shown escaped.
    let hostile = dir.join("hostile.rrd");
    let rec = rerun::RecordingStreamBuilder::new("physlab-pendulum")
        .save(&hostile)
        .unwrap();
    let props = rerun::AnyValues::default()
        .with_component::<rerun::components::Text>("command_line", ["a\x1b[2Jb"]);
    rec.send_property("physlab", &props).unwrap();
    drop(rec);
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.2", "-o", s(&hostile)]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("(from `a\\x1b[2Jb` at ") && !err.contains('\x1b'),
        "{err:?}"
    );

    // Not a recording: its last write.
    let plain = dir.join("plain.rrd");
    std::fs::write(&plain, "not a recording").unwrap();
    let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.2", "-o", s(&plain)]);
    assert_eq!(code, 0, "{err}");
    assert!(std::fs::metadata(&plain).unwrap().len() > 1000);
    assert!(
        err.contains(&format!("replaced {}\n  (last written 20", s(&plain))),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 41.4: `physlab pendulum -o out.png` wrote a Rerun file named out.png. Every command
/// whose -o writes a recording refuses another extension by name (exit 2) and writes nothing.
#[test]
fn an_output_recording_named_as_another_kind_of_file_is_refused() {
    let dir = scratch_dir("refused-extension");
    let good = good_recording(&dir, "good.rrd");
    let out = |name: &str| s(&dir.join(name)).to_string();
    let cases: [(Vec<String>, &str); 5] = [
        (vec!["pendulum".into(), "-o".into(), out("out.png")], "png"),
        (vec!["all".into(), "-o".into(), out("all.txt")], "txt"),
        (
            ["study", "stability", "--methods", "rk4", "-o"]
                .map(String::from)
                .into_iter()
                .chain([out("s.csv")])
                .collect(),
            "csv",
        ),
        (
            vec![
                "diff".into(),
                s(&good).into(),
                s(&good).into(),
                "-o".into(),
                out("d.svg"),
            ],
            "svg",
        ),
        (
            vec![
                "reproduce".into(),
                s(&good).into(),
                "-o".into(),
                out("r.toml"),
            ],
            "toml",
        ),
    ];
    for (args, ext) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = physlab(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains(&format!("the extension .{ext} is not a recording's")),
            "{args:?}: {err}"
        );
    }
    assert_eq!(entries(&dir), ["good.rrd"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 41.4: `study convergence -o first.rrd` then `-o second.rrd` overwrote one
/// `pendulum-convergence.png`. Figures beside -o are named after it: each study keeps its own.
#[test]
fn two_studies_with_their_own_recordings_draw_their_own_figures() {
    let dir = scratch_dir("figures-named");
    let study = [
        "study",
        "convergence",
        "--levels",
        "2",
        "--methods",
        "rk4",
        "-q",
    ];
    for (name, methods) in [("first.rrd", "rk4"), ("second.rrd", "verlet")] {
        let out = dir.join(name);
        let mut args = study.to_vec();
        args[5] = methods;
        args.extend(["-o", s(&out)]);
        let (code, _, err) = physlab(&args);
        assert_eq!(code, 0, "{err}");
        assert!(!err.contains("replaced"), "{err}");
    }
    let svg = |stem: &str| std::fs::read_to_string(dir.join(format!("{stem}.svg"))).unwrap();
    let (first, second) = (
        svg("first-pendulum-convergence"),
        svg("second-pendulum-convergence"),
    );
    assert!(first.contains("rk4") && !first.contains("verlet"));
    assert!(second.contains("verlet") && !second.contains("rk4"));
    assert!(!dir.join("pendulum-convergence.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
