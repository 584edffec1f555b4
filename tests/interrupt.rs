//! Stopping: SIGINT, SIGTERM and SIGHUP in every phase of every command (running, writing,
//! studies, worker threads) end it promptly with exit 130, and leave either the old file
//! or a complete new one, never a broken or hidden partial file.

#[cfg(feature = "rerun")]
mod common;

/// The time a stopped command may take to end [s]. A second is what is promised; the runs here
/// take a minute or more when not stopped, and this bound only has to tell the two apart on a
/// loaded machine (the measured times are printed).
#[cfg(feature = "rerun")]
const ENDS_WITHIN: f64 = 5.0;

#[cfg(feature = "rerun")]
mod runs {
    //! SIGINT, SIGTERM and SIGHUP (a closed terminal) in the running and the writing phases: the
    //! first ends the run with 130 and a finalised file, a second ends at once and removes what the
    //! first left, and at no moment does a signal leave a broken file where a good one was, nor a
    //! hidden partial file.

    use std::path::Path;
    use std::process::{Child, Command, Stdio};
    use std::time::{Duration, Instant};

    use super::ENDS_WITHIN;
    use crate::common::{decode, partials, physlab, scratch_dir, spawn};

    const SIGNALS: [(libc::c_int, &str); 3] = [
        (libc::SIGINT, "SIGINT"),
        (libc::SIGTERM, "SIGTERM"),
        (libc::SIGHUP, "SIGHUP"),
    ];

    fn kill(child: &Child, signal: libc::c_int) {
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    }

    /// Waits for the child; returns (exit code, stderr, seconds since `since`).
    fn wait(child: Child, since: Instant) -> (i32, String, f64) {
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!err.contains("panicked"), "{err}");
        (
            out.status.code().unwrap_or(-1),
            err,
            since.elapsed().as_secs_f64(),
        )
    }

    /// A run of about a minute when not stopped.
    fn long_run(out: &Path) -> Vec<String> {
        ["hair", "--strands", "3000", "--duration", "60", "-q", "-o"]
            .iter()
            .map(|s| s.to_string())
            .chain([out.to_str().unwrap().to_string()])
            .collect()
    }

    /// Waits until the run's hidden file exists (the run is under way).
    fn wait_for_partial(dir: &Path) {
        let started = Instant::now();
        while partials(dir).is_empty() {
            assert!(
                started.elapsed() < Duration::from_secs(30),
                "no run started"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        std::thread::sleep(Duration::from_millis(300));
    }

    #[test]
    fn each_signal_stops_a_run_and_finalises_its_recording() {
        let dir = scratch_dir("int-first");
        for (signal, name) in SIGNALS {
            let out = dir.join(format!("{name}.rrd"));
            let args = long_run(&out);
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let child = spawn(&args);
            wait_for_partial(&dir);
            let sent = Instant::now();
            kill(&child, signal);
            let (code, err, took) = wait(child, sent);
            assert_eq!(code, 130, "{name}: {err}");
            assert!(err.contains("interrupted"), "{name}: {err}");
            assert!(took < ENDS_WITHIN, "{name}: took {took:.2} s");
            assert!(decode(&out).has_footer, "{name}: not finalised");
            assert!(partials(&dir).is_empty(), "{name}: {:?}", partials(&dir));
            println!("{name}: ended {took:.3} s after the signal");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_second_signal_ends_at_once_removes_the_partial_and_keeps_the_old_file() {
        let dir = scratch_dir("int-second");
        let out = dir.join("r.rrd");
        let (code, _, err) = physlab(&[
            "pendulum",
            "-q",
            "--duration",
            "0.5",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let before = std::fs::read(&out).unwrap();
        for (first, a) in SIGNALS {
            for (second, b) in SIGNALS {
                let args = long_run(&out);
                let args: Vec<&str> = args.iter().map(String::as_str).collect();
                let child = spawn(&args);
                wait_for_partial(&dir);
                let sent = Instant::now();
                kill(&child, first);
                kill(&child, second);
                let (code, err, took) = wait(child, sent);
                assert_eq!(code, 130, "{a} then {b}: {err}");
                assert!(took < ENDS_WITHIN, "{a} then {b}: took {took:.2} s");
                assert!(
                    partials(&dir).is_empty(),
                    "{a} then {b}: {:?}",
                    partials(&dir)
                );
                // Either the first signal's finalised recording made it in time, or the old file
                // is there byte for byte: never a broken one.
                let now = std::fs::read(&out).unwrap();
                assert!(
                    now == before || decode(&out).has_footer,
                    "{a} then {b}: broken file"
                );
                std::fs::write(&out, &before).unwrap();
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A study that computes for a moment and then writes its CSV, diagrams and recording, signalled
    /// at a sweep of moments that cover the computing and the writing: each ends with 0 or 130, and
    /// every file is either the old one byte for byte or a complete new one.
    #[test]
    fn a_signal_at_any_moment_of_a_study_leaves_old_or_complete_files() {
        let dir = scratch_dir("int-writing");
        let csv = dir.join("s.csv");
        let rec = dir.join("s.rrd");
        let plots = dir.join("plots");
        let args = [
            "study",
            "convergence",
            "--levels",
            "6",
            "--methods",
            "rk4,verlet",
            "--csv",
            csv.to_str().unwrap(),
            "-o",
            rec.to_str().unwrap(),
            "--plots",
            plots.to_str().unwrap(),
        ];
        // How long a whole run takes here, to spread the signals over it.
        let started = Instant::now();
        let (code, _, err) = physlab(&args);
        assert_eq!(code, 0, "{err}");
        let whole = started.elapsed();
        let good_csv = std::fs::read(&csv).unwrap();
        let mut outcomes = [0usize; 2];
        for (i, (signal, name)) in SIGNALS.iter().cycle().take(12).enumerate() {
            std::fs::write(&csv, b"old csv").unwrap();
            std::fs::write(&rec, b"old recording").unwrap();
            let child = spawn(&args);
            std::thread::sleep(whole.mul_f64(i as f64 / 11.0));
            let sent = Instant::now();
            kill(&child, *signal);
            let (code, err, took) = wait(child, sent);
            // -1: killed by the signal itself, sent before the handlers were installed at start-up
            // (nothing written yet); the files below must hold in every case.
            assert!(
                code == 0 || code == 130 || code == -1,
                "{name} at {i}/11: {code} {err}"
            );
            assert!(took < ENDS_WITHIN, "{name}: took {took:.2} s");
            outcomes[usize::from(code != 0)] += 1;
            let c = std::fs::read(&csv).unwrap();
            assert!(
                c == b"old csv"
                    || c.starts_with(
                        &good_csv[..good_csv.iter().position(|&b| b == b'\n').unwrap()]
                    ),
                "{name} at {i}/11: a broken CSV"
            );
            let r = std::fs::read(&rec).unwrap();
            assert!(
                r == b"old recording" || decode(&rec).has_footer,
                "{name} at {i}/11: a broken recording"
            );
            for d in [&dir, &plots] {
                if d.exists() {
                    assert!(
                        partials(d).is_empty(),
                        "{name} at {i}/11: {:?}",
                        partials(d)
                    );
                }
            }
        }
        println!(
            "12 moments: {} ran to the end, {} stopped",
            outcomes[0], outcomes[1]
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A recording written to standard output that nobody reads blocks in `write`, where the run
    /// never reaches its next check: a signal still ends it, with 130 and a message saying why.
    #[test]
    fn a_signal_ends_a_run_blocked_writing_to_an_unread_pipe() {
        for (signal, name) in SIGNALS {
            let mut child = spawn(&["pendulum", "--duration", "1000", "-q", "-o", "-"]);
            // The pipe (64 KiB) is full within a fraction of a second; nobody reads it.
            std::thread::sleep(Duration::from_millis(1500));
            assert!(child.try_wait().unwrap().is_none(), "{name}: ended unread");
            let since = Instant::now();
            kill(&child, signal);
            let code = loop {
                if let Some(status) = child.try_wait().unwrap() {
                    break status.code().unwrap_or(-1);
                }
                assert!(
                    since.elapsed().as_secs_f64() < ENDS_WITHIN,
                    "{name}: still blocked {ENDS_WITHIN} s after the signal"
                );
                std::thread::sleep(Duration::from_millis(10));
            };
            let took = since.elapsed().as_secs_f64();
            let mut err = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
            assert_eq!(code, 130, "{name}: {err}");
            assert!(
                err.contains("standard output was not being read"),
                "{name}: {err}"
            );
            assert!(!err.contains("panicked"), "{err}");
            eprintln!("{name}: ended {took:.2} s after the signal");
        }
    }

    /// A hair run of about 20 s writing to `out`, started in the background for a test to
    /// interrupt or kill.
    fn spawn_long_hair_run(out: &std::path::Path, output: fn() -> Stdio) -> std::process::Child {
        Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args([
                "hair",
                "--strands",
                "3000",
                "--nodes",
                "32",
                "--duration",
                "60",
                "-q",
                "-o",
                out.to_str().unwrap(),
            ])
            .stdout(output())
            .stderr(output())
            .spawn()
            .unwrap()
    }

    #[test]
    fn failed_and_killed_runs_leave_an_existing_recording_byte_identical() {
        let dir = scratch_dir("keep-good");
        let good = dir.join("good.rrd");
        let (code, _, _) = physlab(&["pendulum", "--duration", "2", "-o", good.to_str().unwrap()]);
        assert_eq!(code, 0);
        let before = std::fs::read(&good).unwrap();

        // Refused input.
        let (code, _, _) = physlab(&["pendulum", "--dt", "0", "-o", good.to_str().unwrap()]);
        assert_eq!(code, 2);
        assert_eq!(std::fs::read(&good).unwrap(), before);

        // A long run killed outright (no chance to clean up) half way.
        let mut child = spawn_long_hair_run(&good, Stdio::null);
        std::thread::sleep(Duration::from_millis(1500));
        child.kill().unwrap();
        child.wait().unwrap();
        assert_eq!(
            std::fs::read(&good).unwrap(),
            before,
            "the killed run touched the recording"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn sigint_finalises_a_readable_recording_and_exits_130() {
        let dir = scratch_dir("sigint");
        let out = dir.join("int.rrd");
        let child = spawn_long_hair_run(&out, Stdio::piped);
        std::thread::sleep(Duration::from_millis(1500));
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
        let result = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(130), "{stderr}");
        assert!(
            stderr.contains("interrupted") && stderr.contains("finalised"),
            "{stderr}"
        );
        let d = decode(&out);
        assert!(d.has_footer, "the interrupted recording has its footer");
        let ke = &d.scalars["/hair/plots/specific_kinetic_energy/verlet"];
        let last = ke.last().unwrap().0 as f64 * 1e-9;
        assert!(
            ke.len() > 10 && last < 59.0,
            "holds the run up to the interruption ({} rows, last t = {last})",
            ke.len()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_second_sigint_ends_at_once_and_leaves_no_file_behind() {
        let dir = scratch_dir("sigint2");
        let out = dir.join("int.rrd");
        let child = spawn_long_hair_run(&out, Stdio::piped);
        std::thread::sleep(Duration::from_millis(1500));
        // SAFETY: sending signals to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
        let result = child.wait_with_output().unwrap();
        assert_eq!(result.status.code(), Some(130));
        // Either the first signal's finalised recording made it, or nothing: never a hidden
        // `.int.rrd.PID.partial`.
        let left: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".partial"))
            .collect();
        assert!(left.is_empty(), "stray files: {left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[cfg(feature = "rerun")]
mod studies {
    //! Signals in studies, bisections and worker threads: a command stopped by SIGINT or SIGTERM
    //! ends within a second with exit 130, and shows or writes only what ran to the end; the
    //! pendulum's fine-step reference stops at once.

    use std::process::{Child, Command, Stdio};
    use std::time::{Duration, Instant};

    use super::ENDS_WITHIN;
    use crate::common;
    use crate::common::{decode, partials, scratch_dir, spawn};

    /// A fixed-step method stepping across the samples at the finest step allowed (4096 steps of
    /// its own per sample, a rope of 2000 nodes: about half a second of stepping a sample) still
    /// stops within a second of each signal: the run's blocks hold fewer samples.
    #[test]
    fn a_run_stepping_many_times_per_sample_stops_at_each_signal() {
        for (signal, name) in [
            (libc::SIGINT, "SIGINT"),
            (libc::SIGTERM, "SIGTERM"),
            (libc::SIGHUP, "SIGHUP"),
        ] {
            let child = spawn(&[
                "rope",
                "--nodes",
                "2000",
                "--methods",
                "verlet",
                "--dt",
                "0.4096",
                "--step",
                "1e-4",
                "--duration",
                "4000",
                "--no-record",
                "-q",
            ]);
            let (code, waited, _, stderr) = stop(child, Duration::from_millis(1500), signal);
            assert_eq!(code, Some(130), "{name}: {stderr}");
            assert!(waited < 1.0, "{name}: {waited:.2} s after the signal");
        }
    }

    // ---- studies and worker threads -------------------------------------------------------------

    /// Sends `signal` to `child` after `after`, and returns (exit code, seconds from the signal to
    /// the exit, stdout, stderr).
    fn stop(
        child: Child,
        after: Duration,
        signal: libc::c_int,
    ) -> (Option<i32>, f64, String, String) {
        std::thread::sleep(after);
        let sent = Instant::now();
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let out = child.wait_with_output().unwrap();
        (
            out.status.code(),
            sent.elapsed().as_secs_f64(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }

    /// The stability bisection looks at the stop flag in every trial, however large a step is: a
    /// rope of 30,000 and 100,000 nodes (one RK4 or implicit step of milliseconds) stops within a
    /// second of SIGINT or SIGTERM, in the first trial and later ones. The long one says up front
    /// how long it would take.
    #[test]
    fn study_stability_on_a_large_rope_stops_within_a_second() {
        for (nodes, method, signal, after) in [
            ("30000", "rk4", libc::SIGINT, 1500),
            ("30000", "implicit-euler", libc::SIGTERM, 1500),
            ("100000", "rk4", libc::SIGINT, 3000),
            ("100000", "verlet", libc::SIGTERM, 800),
        ] {
            let child = spawn(&[
                "study",
                "stability",
                "--scene",
                "rope",
                "--nodes",
                nodes,
                "--methods",
                method,
            ]);
            let (code, waited, stdout, stderr) = stop(child, Duration::from_millis(after), signal);
            assert_eq!(code, Some(130), "{nodes} {method}: {stderr}");
            assert!(
                waited < 1.0,
                "{nodes} {method}: {waited:.2} s after the signal"
            );
            assert!(
                stderr.contains("interrupted: 0 of 1 methods' limits complete"),
                "{stderr}"
            );
            assert!(!stdout.contains(method), "no limit shown: {stdout}");
            if nodes == "100000" {
                assert!(
                    stderr.starts_with("study stability: this takes about")
                        && stderr.contains(" min ")
                        && stderr.contains("node-steps"),
                    "{stderr}"
                );
            }
        }
    }

    /// A short study says nothing about time.
    #[test]
    fn a_short_study_gives_no_time_warning() {
        let (code, _, stderr) = common::physlab(&["study", "stability", "--methods", "rk4"]);
        assert_eq!(code, 0, "{stderr}");
        assert!(!stderr.contains("warning"), "{stderr}");
    }

    /// Stopped during `study hair`: exit 130, and the table, the CSV and the recommendations hold
    /// only configurations that ran to the end (each with a measured cost), never one that did not.
    #[test]
    fn study_hair_stopped_shows_and_writes_only_what_ran() {
        let dir = scratch_dir("interrupt-study-hair");
        let csv = dir.join("h.csv");
        for (after, signal) in [(2500, libc::SIGINT), (5000, libc::SIGTERM)] {
            let _ = std::fs::remove_file(&csv);
            let child = spawn(&["study", "hair", "--wide", "--csv", csv.to_str().unwrap()]);
            let (code, waited, stdout, stderr) = stop(child, Duration::from_millis(after), signal);
            assert_eq!(code, Some(130), "{stderr}");
            assert!(waited < 1.0, "{waited:.2} s after the signal");
            let complete = stderr
                .split("interrupted: ")
                .nth(1)
                .and_then(|s| s.split(' ').next())
                .and_then(|n| n.parse::<usize>().ok())
                .unwrap_or_else(|| panic!("{stderr}"));
            if complete == 0 {
                assert!(stdout.is_empty() && !csv.exists(), "{stdout}");
                continue;
            }
            let text = std::fs::read_to_string(&csv).unwrap();
            let rows: Vec<Vec<&str>> = text
                .lines()
                .skip(1)
                .map(|l| l.split(',').collect())
                .collect();
            assert_eq!(rows.len(), complete, "{text}");
            // Each row ran: a measured cost, and a stretch (or a divergence, left empty).
            for r in &rows {
                let ms: f64 = r[6].parse().unwrap();
                assert!(ms > 0.0, "{text}");
                assert!(
                    r[5].is_empty() || r[5].parse::<f64>().unwrap() > 0.0,
                    "{text}"
                );
            }
            // The trade table shows those rows and no other; every cheapest pick is one of them
            // (its ms/frame is one the table measured).
            let (trade, cheapest) = stdout.split_once("cheapest configuration").unwrap();
            let cells = |line: &str| -> Vec<String> {
                line.split('|').map(|c| c.trim().to_string()).collect()
            };
            let measured: Vec<String> = trade
                .lines()
                .filter(|l| l.starts_with('|') && !l.contains("---") && !l.contains("method"))
                .map(|l| cells(l)[7].clone())
                .collect();
            assert_eq!(measured.len(), complete, "{stdout}");
            for l in cheapest.lines().filter(|l| l.contains("--methods")) {
                let ms = cells(l)[5].clone();
                assert!(measured.contains(&ms), "{l} did not run: {stdout}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// At the largest thread count allowed, a hair run still answers SIGINT and SIGTERM within a
    /// second.
    #[test]
    fn hair_at_the_most_threads_allowed_answers_signals() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let max = (4 * cores).to_string();
        for signal in [libc::SIGINT, libc::SIGTERM] {
            let child = spawn(&[
                "hair",
                "--threads",
                &max,
                "--duration",
                "600",
                "--no-record",
                "-q",
            ]);
            let (code, waited, _, stderr) = stop(child, Duration::from_millis(1500), signal);
            assert_eq!(code, Some(130), "{stderr}");
            assert!(waited < 1.0, "{waited:.2} s after the signal");
        }
    }

    /// Names of hidden partial files left in `dir`.
    /// Starts `physlab args`, sends `signal` after `after`, and returns (exit code, stdout, stderr,
    /// seconds from the signal to the exit).
    fn interrupt(
        args: &[&str],
        after: Duration,
        signal: libc::c_int,
    ) -> (i32, String, String, f64) {
        let child = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(after);
        let sent = Instant::now();
        // SAFETY: sending a signal to our own child process.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let out = child.wait_with_output().unwrap();
        let took = sent.elapsed().as_secs_f64();
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        (out.status.code().unwrap_or(-1), stdout, stderr, took)
    }

    /// Every study kind on both scenes, stopped by SIGINT or SIGTERM early (in the reference or the
    /// first runs) and later (in the sweep or the bisections): each ends at once with 130, says it
    /// was interrupted, shows and writes only complete rows (the CSV has as many rows as the
    /// printed table; the drift study's a row per checkpoint of each complete method), leaves no
    /// partial file, and leaves a good CSV alone when nothing was complete.
    #[test]
    fn a_study_stops_in_every_phase_and_keeps_what_is_complete() {
        let dir = scratch_dir("edges-study-stop");
        let csv = dir.join("s.csv");
        let good = "a good file from an earlier study\n";
        let cases: [(&[&str], u64, libc::c_int); 11] = [
            // The pendulum's fine-step reference (ω0 ≠ 0) at 16 levels takes ~15 s.
            (
                &["convergence", "--omega0", "1", "--levels", "16"],
                300,
                libc::SIGINT,
            ),
            (
                &["convergence", "--omega0", "1", "--levels", "16"],
                1500,
                libc::SIGTERM,
            ),
            // The exact reference is instant: these stop in the sweep.
            (&["convergence", "--levels", "14"], 1000, libc::SIGINT),
            (&["work-precision", "--levels", "14"], 1000, libc::SIGTERM),
            (&["stability", "--steps", "10000000"], 300, libc::SIGINT),
            (&["stability", "--steps", "1000000"], 2000, libc::SIGTERM),
            (
                &["convergence", "--scene", "rope", "--levels", "9"],
                500,
                libc::SIGINT,
            ),
            (
                // (Levels 7 take about 1.3 s on a quiet machine: 9 take four times that.)
                &["work-precision", "--scene", "rope", "--levels", "9"],
                1500,
                libc::SIGTERM,
            ),
            (
                &["stability", "--scene", "rope", "--steps", "1000000"],
                300,
                libc::SIGINT,
            ),
            (
                // (30,000 steps end in 2 s on a quiet machine: 120,000 take about 8.)
                &["stability", "--scene", "rope", "--steps", "120000"],
                2500,
                libc::SIGTERM,
            ),
            // Eight methods of 4e7 steps, one to four seconds each.
            (&["drift"], 2500, libc::SIGINT),
        ];
        let mut kept_some = 0;
        for (args, after_ms, signal) in cases {
            std::fs::write(&csv, good).unwrap();
            let mut all = vec!["study"];
            all.extend_from_slice(args);
            all.extend(["-q", "--csv", csv.to_str().unwrap()]);
            let (code, stdout, stderr, took) =
                interrupt(&all, Duration::from_millis(after_ms), signal);
            println!("{args:?} after {after_ms} ms: ended {took:.3} s after the signal");
            assert_eq!(code, 130, "{args:?}: {stderr}");
            assert!(took < ENDS_WITHIN, "{args:?}: took {took:.1} s");
            assert!(stderr.contains("interrupted: "), "{args:?}: {stderr}");
            assert!(partials(&dir).is_empty(), "{args:?}: {:?}", partials(&dir));
            let written = std::fs::read_to_string(&csv).unwrap();
            if stderr.contains("nothing was written") {
                assert_eq!(written, good, "{args:?}: the good CSV was touched");
                assert!(
                    !stdout.contains("| "),
                    "{args:?}: a table without rows\n{stdout}"
                );
            } else {
                kept_some += 1;
                // Whole: a header and one line per complete run, each with the header's columns.
                let lines: Vec<&str> = written.lines().collect();
                let columns = lines[0].split(',').count();
                assert!(lines.len() >= 2, "{args:?}: {written}");
                assert!(
                    lines.iter().all(|l| l.split(',').count() == columns),
                    "{args:?}: a ragged CSV\n{written}"
                );
                let done: usize = stderr
                    .split("interrupted: ")
                    .nth(1)
                    .and_then(|s| s.split(' ').next())
                    .and_then(|n| n.parse().ok())
                    .unwrap();
                // The drift study writes a row per checkpoint: its runs are its methods.
                let runs = if args[0] == "drift" {
                    let mut methods: Vec<&str> = lines[1..]
                        .iter()
                        .filter_map(|l| l.split(',').nth(1))
                        .collect();
                    methods.dedup();
                    methods.len()
                } else {
                    lines.len() - 1
                };
                assert_eq!(runs, done, "{args:?}: {stderr}");
            }
        }
        assert!(kept_some >= 5, "the later stops kept rows ({kept_some})");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Issue 44.7: the undamped rope's convergence study runs the damped rope after it, and a stop
    /// counts both: "N of M runs complete" with M the rows an uninterrupted run writes (its CSV,
    /// damped rows included), N the rows the stopped one wrote, whether it stopped in the undamped
    /// sweep or later (the damped one, on main said "138 of 138" having dropped it).
    #[test]
    fn the_ropes_convergence_counts_its_damped_runs_when_stopped() {
        let dir = scratch_dir("edges-damped-count");
        let csv = dir.join("c.csv");
        let args = [
            "study",
            "convergence",
            "--scene",
            "rope",
            "--levels",
            "4",
            "-q",
        ];
        let mut whole = args.to_vec();
        whole.extend(["--csv", csv.to_str().unwrap()]);
        let started = Instant::now();
        let (code, _, stderr) = common::physlab(&whole);
        let took = started.elapsed();
        assert_eq!(code, 0, "{stderr}");
        let text = std::fs::read_to_string(&csv).unwrap();
        let planned = text.lines().count() - 1;
        assert!(text.contains("\nrope-damped,"), "no damped runs:\n{text}");
        // The later stop lands in the damped sweep on a steady machine; one that the run
        // outpaced (its pace varies with the load) ends complete, and says nothing to check.
        let mut stopped = 0;
        for fraction in [0.2, 0.5, 0.75] {
            std::fs::remove_file(&csv).unwrap();
            let (code, _, stderr, _) = interrupt(&whole, took.mul_f64(fraction), libc::SIGINT);
            if code == 0 {
                let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
                assert_eq!(
                    rows, planned,
                    "at {fraction} of the run, complete: {stderr}"
                );
                continue;
            }
            stopped += 1;
            assert_eq!(code, 130, "{stderr}");
            let said = stderr
                .split("interrupted: ")
                .nth(1)
                .unwrap_or_else(|| panic!("{stderr}"));
            let (done, of) = said.split_once(" of ").unwrap();
            let total: usize = of.split(' ').next().unwrap().parse().unwrap();
            assert_eq!(total, planned, "at {fraction} of the run: {stderr}");
            let done: usize = done.parse().unwrap();
            assert!(done < planned, "at {fraction} of the run: {stderr}");
            let written = std::fs::read_to_string(&csv).map_or(0, |t| t.lines().count() - 1);
            assert_eq!(written, done, "at {fraction} of the run: {stderr}");
        }
        assert!(stopped >= 1, "every run outpaced its stop");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The pendulum's fine-step reference (a start with ω0 ≠ 0: `--omega0 1e4` takes ~3e8 RK4 steps,
    /// ~30 s) stops at once on SIGINT and SIGTERM, at several ω0 and moments, and finalises a
    /// readable recording in place of the good one, with no partial file.
    #[test]
    fn the_pendulum_reference_stops_at_once_and_finalises_the_recording() {
        let dir = scratch_dir("edges-reference-stop");
        let out = dir.join("p.rrd");
        for (omega0, after_ms, signal) in [
            ("1e4", 300, libc::SIGINT),
            ("1e4", 1500, libc::SIGTERM),
            ("-2e4", 800, libc::SIGINT),
            ("3e3", 1000, libc::SIGTERM),
        ] {
            let (code, _, stderr, took) = interrupt(
                &["pendulum", "--omega0", omega0, "-o", out.to_str().unwrap()],
                Duration::from_millis(after_ms),
                signal,
            );
            println!("--omega0 {omega0} after {after_ms} ms: ended {took:.3} s after the signal");
            assert_eq!(code, 130, "--omega0 {omega0}: {stderr}");
            assert!(took < ENDS_WITHIN, "--omega0 {omega0}: took {took:.1} s");
            assert!(stderr.contains("fine-step reference takes"), "{stderr}");
            assert!(stderr.contains("finalised"), "{stderr}");
            assert!(decode(&out).has_footer, "--omega0 {omega0}: unreadable");
            assert!(partials(&dir).is_empty(), "{:?}", partials(&dir));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
