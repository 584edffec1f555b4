//! What physlab writes: every output file (kinds of file, names, atomic writes, full disks),
//! what `all` writes, and the exit code of a diverged run (the layout a recording opens with is
//! `tests/viewer.rs`).

#[cfg(feature = "rerun")]
mod common;

#[cfg(feature = "rerun")]
mod outputs {
    //! Every file physlab writes: only regular files (symlinks written through), never an input or
    //! another output of the same command, checked before any work, written whole or not at all (a
    //! full disk leaves the old file byte for byte), `-` as standard output or refused, names up to
    //! 255 bytes. The file system's own view (file types, bytes, directory listings) is the judge.

    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt as _;
    use std::os::unix::fs::FileTypeExt as _;
    use std::path::{Path, PathBuf};
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    use crate::common::{decode, partials, physlab, s, scratch_dir};

    /// Hidden partial files left in `dir`.
    /// A small, complete recording and its scene file, to inspect, diff and reproduce.
    fn good_recording(dir: &Path, name: &str) -> PathBuf {
        let path = dir.join(name);
        let (code, _, err) = physlab(&[
            "pendulum",
            "-q",
            "--duration",
            "0.5",
            "--methods",
            "rk4",
            "-o",
            s(&path),
        ]);
        assert_eq!(code, 0, "{err}");
        path
    }

    /// Every command that writes a file, with `{out}` where the written path goes; each is cheap.
    fn writers(dir: &Path) -> Vec<(&'static str, Vec<String>)> {
        let good = good_recording(dir, "input.rrd");
        let g = s(&good).to_string();
        let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        vec![
            (
                "scene -o",
                v(&["pendulum", "-q", "--duration", "0.2", "-o", "{out}"]),
            ),
            (
                "study --csv",
                v(&[
                    "study",
                    "convergence",
                    "--levels",
                    "2",
                    "--methods",
                    "rk4",
                    "--csv",
                    "{out}",
                    "--plots",
                    "PLOTS",
                ]),
            ),
            (
                "study -o",
                v(&[
                    "study",
                    "stability",
                    "--methods",
                    "rk4",
                    "--steps",
                    "100",
                    "-o",
                    "{out}",
                    "--plots",
                    "PLOTS",
                ]),
            ),
            (
                "inspect --config-out",
                v(&["inspect", &g, "--config-out", "{out}"]),
            ),
            ("diff -o", v(&["diff", &g, &g, "-o", "{out}"])),
            ("reproduce -o", v(&["reproduce", &g, "-o", "{out}"])),
        ]
    }

    fn with_out(args: &[String], out: &Path, plots: &Path) -> Vec<String> {
        args.iter()
            .map(|a| match a.as_str() {
                "{out}" => s(out).to_string(),
                "PLOTS" => s(plots).to_string(),
                _ => a.clone(),
            })
            .collect()
    }

    fn run(args: &[String]) -> (i32, String, String) {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        physlab(&a)
    }

    fn mkfifo(path: &Path) {
        let c = CString::new(path.as_os_str().as_bytes()).unwrap();
        // SAFETY: a plain libc call on a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    }

    /// A character device node like /dev/null (1, 3), made in the scratch folder so that a failure
    /// never touches the system's; `false` when this user may not make one.
    fn mknod_null(path: &Path) -> bool {
        let c = CString::new(path.as_os_str().as_bytes()).unwrap();
        // SAFETY: a plain libc call on a NUL-terminated path.
        unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) == 0 }
    }

    #[test]
    fn only_regular_files_are_written_and_symlinks_are_written_through() {
        let dir = scratch_dir("out-kinds");
        let plots = dir.join("plots");
        let device_ok = mknod_null(&dir.join("probe-dev"));
        if !device_ok {
            println!("skipping the device case: mknod is not allowed for this user");
        }
        let mut cases = 0;
        for (name, args) in writers(&dir) {
            // Refused kinds: the thing stays what it was.
            let fifo = dir.join("fifo");
            let device = dir.join("dev");
            let folder = dir.join("folder");
            let link_to_fifo = dir.join("link-to-fifo");
            let _ = std::fs::remove_file(&fifo);
            let _ = std::fs::remove_file(&device);
            let _ = std::fs::remove_file(&link_to_fifo);
            mkfifo(&fifo);
            std::fs::create_dir_all(&folder).unwrap();
            std::os::unix::fs::symlink(&fifo, &link_to_fifo).unwrap();
            let mut refused = vec![
                (fifo.clone(), "is a FIFO"),
                (folder.clone(), "is a folder"),
                (link_to_fifo.clone(), "is a FIFO"),
            ];
            if device_ok {
                assert!(mknod_null(&device));
                refused.push((device.clone(), "is a device"));
            }
            for (path, message) in &refused {
                let (code, stdout, err) = run(&with_out(&args, path, &plots));
                // Bad input like any other: exit 2.
                assert_eq!(code, 2, "{name} {path:?}: {err}");
                assert!(
                    err.contains(message) && err.contains(s(path)),
                    "{name}: {err}"
                );
                assert!(
                    stdout.is_empty() || name.starts_with("scene"),
                    "{name} worked first:\n{stdout}"
                );
                cases += 1;
            }
            let t = std::fs::symlink_metadata(&fifo).unwrap().file_type();
            assert!(t.is_fifo(), "{name}: the FIFO was replaced");
            if device_ok {
                let t = std::fs::symlink_metadata(&device).unwrap().file_type();
                assert!(t.is_char_device(), "{name}: the device was replaced");
            }
            assert!(
                std::fs::symlink_metadata(&link_to_fifo)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            assert!(folder.is_dir() && std::fs::read_dir(&folder).unwrap().next().is_none());

            // A symlink to a regular file: the file is replaced, the link stays.
            let target = dir.join(format!("target-{}", name.replace(' ', "_")));
            let link = dir.join("link");
            std::fs::write(&target, b"old").unwrap();
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&target, &link).unwrap();
            let (code, _, err) = run(&with_out(&args, &link, &plots));
            assert_eq!(code, 0, "{name} through a symlink: {err}");
            assert!(
                std::fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            let written = std::fs::read(&target).unwrap();
            assert!(
                written.len() > 3 && written != b"old",
                "{name}: target not written"
            );
            // A dangling symlink: its target is created.
            let missing = dir.join(format!("created-{}", name.replace(' ', "_")));
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&missing, &link).unwrap();
            let (code, _, err) = run(&with_out(&args, &link, &plots));
            assert_eq!(code, 0, "{name} through a dangling symlink: {err}");
            assert!(
                missing.is_file(),
                "{name}: the link's target was not created"
            );
            assert!(
                std::fs::symlink_metadata(&link)
                    .unwrap()
                    .file_type()
                    .is_symlink()
            );
            cases += 2;
            assert!(partials(&dir).is_empty(), "{name}: {:?}", partials(&dir));
        }
        println!("{cases} cases");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn no_output_is_an_input_or_another_output_of_the_same_command() {
        let dir = scratch_dir("out-same");
        let good = good_recording(&dir, "a.rrd");
        let csv = dir.join("s.csv");
        let rec = dir.join("s.rrd");
        let scene = dir.join("scene.toml");
        std::fs::write(&scene, "[pendulum]\nduration = 2.0\n").unwrap();
        std::fs::write(&csv, b"keep me").unwrap();
        std::fs::copy(&good, &rec).unwrap();
        let alias = dir.join("alias.rrd");
        std::os::unix::fs::symlink(&csv, &alias).unwrap();
        let scene_alias = dir.join("scene-alias.rrd");
        std::os::unix::fs::symlink(&scene, &scene_alias).unwrap();
        let plots = dir.join("plots");
        let png = plots.join("pendulum-convergence.png");
        std::fs::create_dir_all(&plots).unwrap();
        std::fs::write(&png, b"keep me too").unwrap();
        let study = ["study", "convergence", "--levels", "2", "--methods", "rk4"];
        let cat = |a: &[&str], b: &[&str]| -> Vec<String> {
            a.iter().chain(b).map(|x| x.to_string()).collect()
        };
        let cases: Vec<(Vec<String>, &str)> = vec![
            (
                cat(&study, &["-o", s(&csv), "--csv", s(&csv)]),
                "the extension .csv",
            ),
            (
                cat(&study, &["-o", s(&rec), "--csv", s(&rec)]),
                "both write",
            ),
            (
                cat(&study, &["-o", s(&alias), "--csv", s(&csv)]),
                "both write",
            ),
            (
                cat(&study, &["--csv", s(&png), "--plots", s(&plots)]),
                "both write",
            ),
            (
                cat(&study, &["-o", "-", "--csv", "-"]),
                "both write standard output",
            ),
            (
                cat(&study, &["--config", s(&scene), "--csv", s(&scene)]),
                "scene file",
            ),
            (
                cat(
                    &["pendulum", "--config", s(&scene)],
                    &["-o", s(&scene_alias)],
                ),
                "scene file",
            ),
            (
                cat(&["inspect", s(&good)], &["--config-out", s(&good)]),
                "recording inspected",
            ),
            (
                cat(&["diff", s(&good), s(&rec)], &["-o", s(&rec)]),
                "being compared",
            ),
            (
                cat(&["diff", s(&good), s(&rec)], &["-o", s(&good)]),
                "being compared",
            ),
            (
                cat(&["reproduce", s(&good)], &["-o", s(&good)]),
                "being compared",
            ),
        ];
        let before: Vec<Vec<u8>> = [&csv, &rec, &good, &scene, &png]
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect();
        for (args, message) in &cases {
            let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"));
            child
                .args(args)
                .stdout(Stdio::piped())
                .stderr(Stdio::piped());
            let out = child.output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(message),
                "{args:?}: expected {message:?} in {err}"
            );
            assert!(out.stdout.is_empty(), "{args:?}: it ran first");
        }
        let after: Vec<Vec<u8>> = [&csv, &rec, &good, &scene, &png]
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect();
        assert_eq!(before, after, "a refused command touched a file");
        assert!(partials(&dir).is_empty());
        println!("{} cases", cases.len());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn outputs_are_checked_before_any_work() {
        let dir = scratch_dir("out-first");
        let good = good_recording(&dir, "a.rrd");
        let file = dir.join("file");
        std::fs::write(&file, b"x").unwrap();
        let under_file = dir.join("file/sub/c.csv");
        // A study that would take minutes if it ran: each case must fail at once.
        let long = ["study", "convergence", "--scene", "rope", "--levels", "8"];
        let cat =
            |b: &[&str]| -> Vec<String> { long.iter().chain(b).map(|x| x.to_string()).collect() };
        let g = s(&good).to_string();
        let cases: Vec<(Vec<String>, i32, &str)> = vec![
            (
                cat(&["--csv", s(&under_file)]),
                1,
                "cannot create the folder",
            ),
            (cat(&["--plots", s(&file)]), 2, "is not a folder"),
            (cat(&["--plots", "-"]), 2, "--plots -"),
            (cat(&["-o", s(&dir)]), 2, "is a folder"),
            (cat(&["--csv", s(&dir)]), 2, "is a folder"),
            (
                vec!["diff".into(), g.clone(), g.clone(), "-o".into(), ".".into()],
                2,
                "is a folder",
            ),
            (
                vec![
                    "diff".into(),
                    g.clone(),
                    g.clone(),
                    "-o".into(),
                    s(&under_file.with_extension("rrd")).into(),
                ],
                // Any failure of `diff` is 2: 1 says "they differ".
                2,
                "cannot create the folder",
            ),
            (
                vec!["reproduce".into(), g.clone(), "-o".into(), "-".into()],
                2,
                "standard output",
            ),
            (
                vec!["reproduce".into(), g.clone(), "-o".into(), s(&dir).into()],
                2,
                "is a folder",
            ),
            (
                vec![
                    "inspect".into(),
                    g.clone(),
                    "--config-out".into(),
                    s(&dir).into(),
                ],
                2,
                "is a folder",
            ),
        ];
        for (args, code, message) in &cases {
            let started = Instant::now();
            let (got, stdout, err) = run(args);
            let took = started.elapsed();
            assert_eq!(got, *code, "{args:?}: {err}");
            assert!(
                err.contains(message),
                "{args:?}: expected {message:?} in {err}"
            );
            assert!(stdout.is_empty(), "{args:?}: it worked first:\n{stdout}");
            assert!(took < Duration::from_secs(5), "{args:?}: took {took:?}");
        }
        assert!(!dir.join("-").exists());
        println!("{} cases", cases.len());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_dash_is_standard_output_everywhere_a_file_is_written_or_refused() {
        let dir = scratch_dir("out-dash");
        let good = good_recording(&dir, "a.rrd");
        let in_dir = |args: &[&str]| {
            let out = Command::new(env!("CARGO_BIN_EXE_physlab"))
                .args(args)
                .current_dir(&dir)
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .output()
                .unwrap();
            (
                out.status.code().unwrap(),
                out.stdout,
                String::from_utf8_lossy(&out.stderr).into_owned(),
            )
        };
        // The CSV on stdout, the tables on stderr.
        let (code, stdout, err) = in_dir(&[
            "study",
            "convergence",
            "--levels",
            "2",
            "--methods",
            "rk4",
            "--csv",
            "-",
        ]);
        assert_eq!(code, 0, "{err}");
        let text = String::from_utf8(stdout).unwrap();
        let header = text.lines().next().unwrap();
        assert!(header.contains(',') && !header.contains('|'), "{text}");
        assert!(
            err.contains("convergence"),
            "the tables go to stderr: {err}"
        );
        // The scene file on stdout, parseable TOML, the report on stderr.
        let (code, stdout, err) = in_dir(&["inspect", s(&good), "--config-out", "-"]);
        assert_eq!(code, 0, "{err}");
        let table: toml::Table = String::from_utf8(stdout).unwrap().parse().unwrap();
        assert!(table.contains_key("pendulum"), "{table:?}");
        assert!(err.contains("recording:"), "{err}");
        // The difference recording on stdout, readable, the report on stderr.
        let (code, stdout, err) = in_dir(&["diff", s(&good), s(&good), "-o", "-"]);
        assert_eq!(code, 0, "{err}");
        let copy = dir.join("diff-from-stdout.rrd");
        std::fs::write(&copy, &stdout).unwrap();
        assert!(decode(&copy).has_footer);
        assert!(err.contains("shared entities differ"), "{err}");
        // Never a file named `-`.
        assert!(!dir.join("-").exists(), "a file named - was created");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn names_up_to_255_bytes_work_and_longer_ones_are_refused_by_name() {
        let dir = scratch_dir("out-long");
        let good = good_recording(&dir, "a.rrd");
        for len in [200usize, 241, 250, 254, 255, 256] {
            let name = |ext: &str| "n".repeat(len - ext.len()) + ext;
            let cases: Vec<(Vec<String>, PathBuf)> = vec![
                (
                    vec![
                        "pendulum".into(),
                        "-q".into(),
                        "--duration".into(),
                        "0.2".into(),
                        "-o".into(),
                    ],
                    dir.join(name(".rrd")),
                ),
                (
                    vec![
                        "study".into(),
                        "stability".into(),
                        "--methods".into(),
                        "rk4".into(),
                        "--steps".into(),
                        "100".into(),
                        "--plots".into(),
                        s(&dir.join("plots")).into(),
                        "--csv".into(),
                    ],
                    dir.join(name(".csv")),
                ),
                (
                    vec!["inspect".into(), s(&good).into(), "--config-out".into()],
                    dir.join(name(".toml")),
                ),
            ];
            for (mut args, path) in cases {
                args.push(s(&path).into());
                let (code, _, err) = run(&args);
                if len <= 255 {
                    assert_eq!(code, 0, "{len} bytes: {err}");
                    assert!(path.is_file(), "{len} bytes: not written");
                    std::fs::remove_file(&path).unwrap();
                } else {
                    assert_eq!(code, 1, "{len} bytes: {err}");
                    assert!(err.contains("256 bytes") && err.contains("255"), "{err}");
                }
            }
            assert!(partials(&dir).is_empty(), "{len}: {:?}", partials(&dir));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn hidden_files_of_dead_processes_are_removed_and_live_ones_kept() {
        let dir = scratch_dir("out-stale");
        let out = dir.join("r.rrd");
        // A live writer holds its hidden file locked, whatever its pid (here one that never runs
        // on Linux, above 4194304); a dead one's lock went with it.
        let dead = dir.join(".r.rrd.4194399.partial");
        let live = dir.join(".r.rrd.4194398.partial");
        let other = dir.join(".x.rrd.4194399.partial");
        for p in [&dead, &live, &other] {
            std::fs::write(p, b"half a recording").unwrap();
        }
        let writer = std::fs::File::open(&live).unwrap();
        writer.lock().unwrap();
        let (code, _, err) = physlab(&["pendulum", "-q", "--duration", "0.2", "-o", s(&out)]);
        assert_eq!(code, 0, "{err}");
        assert!(!dead.exists(), "the dead process's hidden file was kept");
        assert!(live.exists(), "a running process's hidden file was removed");
        assert!(other.exists(), "another target's hidden file was removed");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_unusable_tmpdir_is_named() {
        let dir = scratch_dir("out-tmpdir");
        let good = good_recording(&dir, "a.rrd");
        let missing = dir.join("no-such-folder");
        let out = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(["reproduce", s(&good)])
            .env("TMPDIR", &missing)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        // A failure in `reproduce` exits 2: 1 says "it differs".
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("TMPDIR") && err.contains(s(&missing)), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A tmpfs of `size` at a fresh folder (read-only with `ro`), unmounted on drop; `None` (with
    /// the reason printed) when this user may not mount.
    struct Tmpfs(PathBuf);

    impl Tmpfs {
        fn mount(name: &str, options: &str) -> Option<Self> {
            let dir = scratch_dir(name);
            let out = Command::new("mount")
                .args(["-t", "tmpfs", "-o", options, "tmpfs", s(&dir)])
                .output();
            match out {
                Ok(o) if o.status.success() => Some(Tmpfs(dir)),
                Ok(o) => {
                    println!(
                        "skipped: mount -t tmpfs refused: {}",
                        String::from_utf8_lossy(&o.stderr).trim()
                    );
                    None
                }
                Err(e) => {
                    println!("skipped: cannot run mount: {e}");
                    None
                }
            }
        }
    }

    impl Drop for Tmpfs {
        fn drop(&mut self) {
            let _ = Command::new("umount").arg(&self.0).status();
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Fills the file system at `dir` until `free` bytes or fewer are left.
    fn fill(dir: &Path, free: u64) {
        use std::io::Write as _;
        let mut f = std::fs::File::create(dir.join("filler")).unwrap();
        let chunk = vec![7u8; 4096];
        loop {
            // SAFETY: statvfs on a NUL-terminated path into a zeroed struct.
            let avail = unsafe {
                let mut st: libc::statvfs = std::mem::zeroed();
                let c = CString::new(dir.as_os_str().as_bytes()).unwrap();
                assert_eq!(libc::statvfs(c.as_ptr(), &mut st), 0);
                st.f_bavail * st.f_frsize
            };
            if avail <= free || f.write_all(&chunk).is_err() {
                break;
            }
        }
        let _ = f.sync_all();
    }

    /// Runs physlab with a time limit (a full disk once made it hang).
    fn run_limited(args: &[String], limit: Duration) -> (i32, String, String) {
        let mut child = Command::new(env!("CARGO_BIN_EXE_physlab"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let started = Instant::now();
        loop {
            if child.try_wait().unwrap().is_some() {
                break;
            }
            if started.elapsed() > limit {
                let _ = child.kill();
                panic!("{args:?} still runs after {limit:?}");
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            err,
        )
    }

    #[test]
    fn a_full_disk_leaves_the_old_file_byte_for_byte_and_names_the_file() {
        let Some(disk) = Tmpfs::mount("out-full", "size=2m") else {
            return;
        };
        let elsewhere = scratch_dir("out-full-inputs");
        let good = good_recording(&elsewhere, "a.rrd");
        let v = |a: &[&str]| a.iter().map(|x| x.to_string()).collect::<Vec<String>>();
        // (what, command with {out}, free bytes left before it runs)
        let cases: Vec<(&str, Vec<String>, u64)> = vec![
            (
                "recording, the disk full mid-run",
                v(&["rope", "-q", "--duration", "1", "-o", "{out}"]),
                300_000,
            ),
            (
                "recording, no room at all",
                v(&["pendulum", "-q", "--duration", "1", "-o", "{out}"]),
                0,
            ),
            (
                "study CSV",
                v(&[
                    "study",
                    "convergence",
                    "--levels",
                    "2",
                    "--methods",
                    "rk4",
                    "--csv",
                    "{out}",
                    "--plots",
                    s(&elsewhere.join("plots")),
                ]),
                0,
            ),
            (
                "study PNGs",
                v(&[
                    "study",
                    "convergence",
                    "--levels",
                    "2",
                    "--methods",
                    "rk4",
                    "--csv",
                    s(&elsewhere.join("c.csv")),
                    "--plots",
                    "{dir}",
                ]),
                0,
            ),
            (
                "study recording",
                v(&[
                    "study",
                    "stability",
                    "--methods",
                    "rk4",
                    "--steps",
                    "100",
                    "-o",
                    "{out}",
                    "--plots",
                    s(&elsewhere.join("plots")),
                ]),
                0,
            ),
            (
                "--config-out",
                v(&["inspect", s(&good), "--config-out", "{out}"]),
                0,
            ),
            (
                "diff -o",
                v(&["diff", s(&good), s(&good), "-o", "{out}"]),
                0,
            ),
        ];
        for (what, args, free) in &cases {
            let keep = disk.0.join("keep");
            let png = disk.0.join("pendulum-convergence.png");
            for p in [&keep, &png] {
                std::fs::write(p, format!("a good old file: {what}")).unwrap();
            }
            let before = (std::fs::read(&keep).unwrap(), std::fs::read(&png).unwrap());
            fill(&disk.0, *free);
            let args: Vec<String> = args
                .iter()
                .map(|a| a.replace("{out}", s(&keep)).replace("{dir}", s(&disk.0)))
                .collect();
            let (code, _, err) = run_limited(&args, Duration::from_secs(120));
            // `diff` exits 2 for any failure: 1 says "they differ".
            let failed = if what.starts_with("diff") { 2 } else { 1 };
            assert_eq!(code, failed, "{what}: {err}");
            assert!(err.contains("disk full"), "{what}: {err}");
            let named = if what.contains("PNG") {
                s(&disk.0).to_string()
            } else {
                s(&keep).to_string()
            };
            assert!(err.contains(&named), "{what}: the file is not named: {err}");
            let after = (std::fs::read(&keep).unwrap(), std::fs::read(&png).unwrap());
            assert_eq!(before, after, "{what}: the old file changed");
            assert!(
                partials(&disk.0).is_empty(),
                "{what}: {:?}",
                partials(&disk.0)
            );
            std::fs::remove_file(disk.0.join("filler")).unwrap();
        }
        println!("{} cases", cases.len());
        std::fs::remove_dir_all(&elsewhere).unwrap();
    }

    #[test]
    fn a_read_only_file_system_is_refused_before_any_work() {
        let Some(disk) = Tmpfs::mount("out-ro", "size=1m,ro") else {
            return;
        };
        let out = disk.0.join("r.rrd");
        for args in [
            vec!["pendulum", "-q", "-o", s(&out)],
            vec![
                "study",
                "convergence",
                "--scene",
                "rope",
                "--levels",
                "8",
                "--csv",
                s(&out),
            ],
        ] {
            let started = Instant::now();
            let (code, stdout, err) = physlab(&args);
            assert_eq!(code, 1, "{args:?}: {err}");
            assert!(
                err.contains("read-only file system") && err.contains(s(&out)),
                "{err}"
            );
            assert!(stdout.is_empty(), "{args:?} worked first");
            assert!(started.elapsed() < Duration::from_secs(5));
        }
    }
}

#[cfg(feature = "rerun")]
mod all {
    //! `physlab all`: three scenes with provenance that `inspect` reads back, scene files and flags
    //! layered, and the drawing and method flags applied to every scene.

    use crate::common::{SMALL, physlab, scratch_dir};

    #[test]
    fn all_writes_three_scenes_with_provenance_that_inspect_reads_back() {
        let dir = scratch_dir("all-provenance");
        let config = dir.join("small.toml");
        std::fs::write(&config, SMALL).unwrap();
        let out = dir.join("all.rrd");
        let (code, stdout, stderr) = physlab(&[
            "all",
            "--config",
            config.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert!(
            stdout.contains("pendulum:") && stdout.contains("rope:") && stdout.contains("hair:")
        );
        assert!(
            stdout.contains(" MB)"),
            "the summary prints the file size:\n{stdout}"
        );

        let (code, info, stderr) = physlab(&[
            "inspect",
            out.to_str().unwrap(),
            "--config-out",
            dir.join("again.toml").to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        for expected in [
            "scenes: hair, pendulum, rope",
            "Rerun SDK 0.36.3",
            &format!("physlab {}", env!("CARGO_PKG_VERSION")),
            "footer written",
            "pendulum: complete: t = 4 s",
            "sim_time: 0.000000 s to 4.000000 s",
            "/pendulum/rk4/bob",
            "/rope/plots/max_strain/verlet",
            "/hair/ftl/strands",
            "explicit-euler diverged",
        ] {
            assert!(
                info.contains(expected),
                "inspect lacks '{expected}':\n{info}"
            );
        }
        assert!(
            !info.contains("commit unknown") && info.contains("(commit "),
            "{info}"
        );
        // The embedded scene file is complete: every parameter resolved, not just the ones given.
        let again = std::fs::read_to_string(dir.join("again.toml")).unwrap();
        for key in [
            "[pendulum]",
            "theta0 = 60.0",
            "[rope]",
            "nodes = 8",
            "[hair]",
            "strands = 40",
            "head_motion = \"tour\"",
        ] {
            assert!(again.contains(key), "embedded config lacks {key}:\n{again}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn flags_override_the_scene_file_and_print_config_shows_the_result() {
        let dir = scratch_dir("config-override");
        let config = dir.join("p.toml");
        std::fs::write(&config, "[pendulum]\ndt = 0.02\ntheta0 = 30.0\n").unwrap();
        let (code, text, stderr) = physlab(&[
            "pendulum",
            "--config",
            config.to_str().unwrap(),
            "--dt",
            "0.005",
            "--print-config",
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert!(
            text.contains("dt = 0.005")
                && text.contains("theta0 = 30.0")
                && text.contains("gravity = 9.81"),
            "{text}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn all_fps_and_plot_every_override_every_scene() {
        let (code, text, err) =
            physlab(&["all", "--fps", "5", "--plot-every", "3", "--print-config"]);
        assert_eq!(code, 0, "{err}");
        assert_eq!(text.matches("fps = 5.0").count(), 3, "{text}");
        assert_eq!(text.matches("plot_every = 3").count(), 2, "{text}");
    }

    #[test]
    fn all_methods_gives_each_scene_the_listed_methods_it_supports() {
        let (code, toml, stderr) =
            physlab(&["all", "--methods", "rk4,ftl,verlet", "--print-config"]);
        assert_eq!(code, 0, "{stderr}");
        let file: toml::Table = toml.parse().unwrap();
        let methods = |scene: &str| -> Vec<String> {
            file[scene]["methods"]
                .as_array()
                .unwrap()
                .iter()
                .map(|m| m.as_str().unwrap().to_string())
                .collect()
        };
        assert_eq!(methods("pendulum"), ["rk4", "verlet"]);
        assert_eq!(methods("rope"), ["rk4", "verlet"]);
        assert_eq!(methods("hair"), ["ftl", "verlet"]);

        // A name no scene has, or a list that leaves a scene without a method, is refused naming
        // the option, the value and the scene's allowed names: rows of `cli_input.rs`.
    }
}

#[cfg(feature = "rerun")]
mod exit_codes {
    //! A missing viewer costs no recording; a diverged run exits 3 and still writes its recording.

    use crate::common;
    use crate::common::{decode, physlab, scratch_dir};

    #[test]
    fn a_missing_viewer_costs_no_recording() {
        let dir = scratch_dir("edges-viewer");
        let out = dir.join("sub/p.rrd");
        // Nothing listens on port 1.
        let (code, _, stderr) = physlab(&[
            "pendulum",
            "--duration",
            "0.5",
            "-q",
            "--connect",
            "rerun+http://127.0.0.1:1/proxy",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{stderr}");
        assert!(
            stderr.contains("no viewer answers there; writing the file only"),
            "{stderr}"
        );
        assert!(common::decode(&out).has_footer);
        // Without a file there is nothing to keep: refused, not silently dropped.
        let (code, _, stderr) = physlab(&[
            "pendulum",
            "--duration",
            "0.5",
            "--no-save",
            "--connect",
            "rerun+http://127.0.0.1:1/proxy",
        ]);
        assert_eq!(code, 1, "{stderr}");
        assert!(
            stderr.contains("--no-save leaves nothing to write"),
            "{stderr}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn fail_on_divergence_exits_3_and_still_writes_the_recording() {
        let dir = scratch_dir("diverge");
        let out = dir.join("r.rrd");
        // Explicit Euler blows up on the default rope within a second.
        let (code, stdout, stderr) = physlab(&[
            "rope",
            "--duration",
            "1",
            "--fail-on-divergence",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 3, "{stderr}");
        assert!(stderr.contains("rope/explicit-euler"), "{stderr}");
        // The summary's diverged column: "at T s" (fitted to 100 columns).
        let euler = stdout.lines().find(|l| l.starts_with("| explicit-euler "));
        assert!(euler.is_some_and(|l| l.contains("| at 0.")), "{stdout}");
        assert!(decode(&out).has_footer);
        let (code, _, _) = physlab(&[
            "pendulum",
            "--duration",
            "1",
            "--fail-on-divergence",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "nothing diverges on the default pendulum");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

mod long_runs {
    //! The plots of a run longer than a plot keeps whole: the same run observed row by row and
    //! as recorded (M4 aggregate plus windows) must draw the same thing at every plot width
    //! dividing the column count, keep its windows bit for bit, and change no summary.

    use std::collections::BTreeMap;
    use std::time::Duration;

    use physlab::scene::hair::run::{HairConfig, HairScene};
    use physlab::scene::harness::{
        Observer, Run, Scene, SeriesBatch, WantedRows, Window, absent_when_zero, run,
    };
    use physlab::scene::m4::MAX_COLUMNS;
    use physlab::scene::pendulum::run::{PendulumConfig, PendulumScene};
    use physlab::scene::rope::run::{RopeConfig, RopeScene};

    /// One lane's rows: ticks, a column per quantity, and which quantities need each row.
    #[derive(Default)]
    struct LaneRows {
        ticks: Vec<u64>,
        columns: Vec<Vec<f64>>,
        needed: Vec<u64>,
    }

    struct Collect {
        wanted: WantedRows,
        lanes: BTreeMap<usize, LaneRows>,
    }

    impl<S: Scene> Observer<S> for Collect {
        fn rows(&self) -> WantedRows {
            self.wanted
        }
        fn series(&mut self, _: &S, lane: usize, b: &SeriesBatch) -> anyhow::Result<()> {
            let rows = self.lanes.entry(lane).or_default();
            rows.columns.resize(b.columns.len(), Vec::new());
            rows.ticks.extend(&b.ticks);
            rows.needed.extend(&b.needed);
            for (c, values) in rows.columns.iter_mut().zip(&b.columns) {
                c.extend(values);
            }
            Ok(())
        }
    }

    /// Per plot column at width `w`: the first and last point (tick, value bits), the least
    /// and the greatest value (bits), written out here on their own: column = ⌊n·w/N⌋, the last
    /// step in the last column.
    type Column = ((u64, u64), (u64, u64), u64, u64);

    fn raster(points: &[(u64, f64)], last: u64, w: u64) -> Vec<Option<Column>> {
        let mut cols: Vec<Option<Column>> = vec![None; w as usize];
        for &(n, v) in points {
            let x = ((u128::from(n) * u128::from(w) / u128::from(last)) as u64).min(w - 1);
            let at = (n, v.to_bits());
            let c = cols[x as usize].get_or_insert((at, at, v.to_bits(), v.to_bits()));
            c.1 = at;
            if v < f64::from_bits(c.2) {
                c.2 = v.to_bits();
            }
            if v > f64::from_bits(c.3) {
                c.3 = v.to_bits();
            }
        }
        cols
    }

    /// Runs `make()` twice, row by row and as plotted, and checks that both draw the same,
    /// keep the same windows and give the same summary.
    fn check<S: Scene>(make: impl Fn() -> S, summary: impl Fn(&S, &Run<S::Lane>, bool) -> String) {
        let mut runs = Vec::new();
        for wanted in [WantedRows::Every, WantedRows::Plotted] {
            let mut scene = make();
            let mut observer = Collect {
                wanted,
                lanes: BTreeMap::new(),
            };
            let mut ran = run(&mut scene, &mut observer).unwrap();
            for s in &mut ran.stats {
                s.wall = Duration::ZERO;
            }
            runs.push((summary(&scene, &ran, true), observer.lanes));
        }
        let (every_summary, every) = &runs[0];
        let (plotted_summary, plotted) = &runs[1];
        assert_eq!(every_summary, plotted_summary, "summaries differ");

        let scene = make();
        let schedule = scene.schedule();
        let plan = schedule
            .series_plan(&scene.windows())
            .expect("the run is long enough to be aggregated");
        let quantities: Vec<&[&str]> = scene
            .lanes()
            .iter()
            .map(|(_, l)| scene.quantities(l))
            .collect();
        let whole = schedule.whole_rows(&scene.windows()) as usize;
        for (lane, full) in every {
            let kept = &plotted[lane];
            // At most a column's first and last row and five per quantity, and the windows.
            let most = MAX_COLUMNS as usize * (2 + 5 * quantities[*lane].len()) + whole;
            assert!(
                kept.ticks.len() <= most,
                "lane {lane}: {} rows",
                kept.ticks.len()
            );
            assert!(full.needed.iter().all(|&n| n == u64::MAX));
            for (q, name) in quantities[*lane].iter().enumerate() {
                let present = |v: f64| !(absent_when_zero(name) && v == 0.0);
                let series = |rows: &LaneRows, only_needed: bool| -> Vec<(u64, f64)> {
                    (0..rows.ticks.len())
                        .filter(|&i| !only_needed || rows.needed[i] & (1 << q) != 0)
                        .map(|i| (rows.ticks[i], rows.columns[q][i]))
                        .filter(|&(_, v)| present(v))
                        .collect()
                };
                let (a, b) = (series(full, false), series(kept, true));
                for w in [4096, 2048, 1024, 256, 1] {
                    assert!(
                        raster(&a, schedule.total, w) == raster(&b, schedule.total, w),
                        "lane {lane} {name}: drawn differently at {w} px"
                    );
                }
            }
            // The windows, and the last window before the lane stopped, bit for bit.
            let rows = |r: &LaneRows, i: usize| -> Vec<u64> {
                std::iter::once(r.ticks[i])
                    .chain(r.columns.iter().map(|c| c[i].to_bits()))
                    .collect()
            };
            let in_range = |r: &LaneRows, from: u64, to: u64| -> Vec<Vec<u64>> {
                (0..r.ticks.len())
                    .filter(|&i| (from..=to).contains(&r.ticks[i]))
                    .map(|i| rows(r, i))
                    .collect()
            };
            let stopped = *full.ticks.last().unwrap();
            for &(from, to) in plan.windows.iter().filter(|w| w.0 <= stopped) {
                let want = in_range(full, from, to);
                assert!(!want.is_empty());
                assert_eq!(
                    want,
                    in_range(kept, from, to),
                    "lane {lane}: window {from}..={to}"
                );
            }
            let last = full.ticks.len().saturating_sub(plan.last_rows);
            let (from, to) = (full.ticks[last], *full.ticks.last().unwrap());
            assert_eq!(
                in_range(full, from, to),
                in_range(kept, from, to),
                "lane {lane}: the last window"
            );
        }
    }

    #[test]
    fn pendulum_plots_draw_every_step_and_keep_their_windows() {
        let make = || {
            PendulumScene::new(PendulumConfig {
                dt: 0.05,
                duration: 1500.0,
                window: vec!["400:410".parse::<Window>().unwrap()],
                ..PendulumConfig::default()
            })
        };
        assert!(make().schedule().aggregates());
        // explicit-euler diverges early, so its last window is the one before its divergence.
        check(make, physlab::report::pendulum::summary_text);
    }

    #[test]
    fn rope_plots_draw_every_step_and_keep_their_windows() {
        let make = || {
            RopeScene::new(RopeConfig {
                duration: 100.0,
                ..RopeConfig::default()
            })
        };
        // Three methods diverge.
        check(make, physlab::report::rope::summary_text);
    }

    #[test]
    fn hair_plots_draw_every_frame_and_keep_their_windows() {
        let make = || {
            let mut c = HairConfig {
                duration: 250.0,
                window: vec!["-100:-90".parse::<Window>().unwrap()],
                ..HairConfig::default()
            };
            c.params.strands = 8;
            c.params.nodes = 6;
            HairScene::new(c)
        };
        check(make, physlab::report::hair::summary_text);
    }
}
