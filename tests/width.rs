//! Output that fits a terminal: every command at its defaults prints no line over 100 columns
//! and no table column that holds one value in every row, `--help` wraps to the terminal's width
//! (100 when there is none), `physlab methods` is one screen and `physlab methods NAME` a page,
//! and `--wide` still shows the full tables.

#![cfg(feature = "rerun")]

mod common;

use std::process::Command;

use common::{physlab, s, scratch_dir};
use physlab::report::methods::{method_page, methods_table, page_names};
use physlab::report::table::columns;

const WIDTH: usize = 100;

/// The widest line of `text` in columns, two for a character outside ASCII as a terminal that
/// draws East Asian ambiguous-width characters (°, θ, ≤) wide shows it, and the line.
fn widest(text: &str) -> (usize, &str) {
    (text.lines())
        .map(|l| (columns(l), l))
        .max_by_key(|&(n, _)| n)
        .unwrap_or((0, ""))
}

/// The cells of every markdown table in `text`, one table per run of `|` lines, separator left out.
fn tables(text: &str) -> Vec<Vec<Vec<String>>> {
    let mut out: Vec<Vec<Vec<String>>> = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        if !line.starts_with('|') {
            inside = false;
            continue;
        }
        if !inside {
            out.push(Vec::new());
            inside = true;
        }
        if !line.starts_with("|-") {
            let cells = line
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string());
            out.last_mut().unwrap().push(cells.collect());
        }
    }
    out
}

/// Runs `args`, which must succeed, and checks that stdout and stderr fit 100 columns, that a
/// table with `row` was printed, and that no table column but the first holds one value in
/// every row of two or more.
fn assert_fits(args: &[&str], row: &str) -> String {
    let (code, out, err) = physlab(args);
    assert_eq!(code, 0, "physlab {args:?}:\n{out}\n{err}");
    for (name, text) in [("stdout", &out), ("stderr", &err)] {
        let (n, line) = widest(text);
        assert!(
            n <= WIDTH,
            "physlab {args:?}: a line of {n} columns on {name}:\n{line}"
        );
    }
    assert!(out.contains(row), "physlab {args:?}: no {row:?}:\n{out}");
    for table in tables(&out) {
        let (header, rows) = table.split_first().unwrap();
        for (c, name) in header.iter().enumerate().skip(1) {
            let same = rows.len() > 1 && rows.iter().all(|r| r[c] == rows[0][c]);
            assert!(
                !same,
                "physlab {args:?}: column {name:?} is {:?} in every row:\n{out}",
                rows[0][c]
            );
        }
    }
    out
}

/// The scenes and `all` at their defaults (the recordings into a scratch folder).
#[test]
fn every_scene_at_its_defaults_prints_no_line_over_100_columns() {
    let dir = scratch_dir("width-scenes");
    for scene in ["pendulum", "rope", "hair", "all"] {
        let out = dir.join(format!("{scene}.rrd"));
        assert_fits(&[scene, "-o", s(&out)], "| verlet ");
        // Again: the line that says the first recording is replaced fits too (the old
        // recording's command line starts with this test binary's long path).
        // (tests/files.rs checks that the line is said.)
        assert_fits(&[scene, "-o", s(&out)], "| verlet ");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every study kind at its defaults, except two that take minutes: `drift` over 400 s instead of
/// 10⁵ periods and `hair` over 0.1 s instead of 4 s (their tables have the same columns).
#[test]
fn every_study_at_its_defaults_prints_no_line_over_100_columns() {
    for (args, row) in [
        (&["study", "convergence"][..], "| rk4 "),
        (&["study", "convergence", "--scene", "rope"], "| rk4 "),
        (&["study", "work-precision"], "| dprkn12 "),
        (&["study", "stability"], "| rk4 "),
        (&["study", "stability", "--scene", "rope"], "| rk4 "),
        (&["study", "drift", "--duration", "400"], "| verlet "),
        (&["study", "hair", "--duration", "0.1"], "| ftl "),
    ] {
        assert_fits(args, row);
    }
}

/// A long run widens the counts, times and divergence times past what the defaults print: its
/// tables come in parts one under another, every column kept (main printed a 107-column
/// pendulum table over 3000 s).
#[test]
fn a_long_run_still_prints_no_line_over_100_columns() {
    let out = assert_fits(
        &["pendulum", "--duration", "3000", "--no-record"],
        "| verlet ",
    );
    assert!(
        out.contains("| diverged ") && out.contains("at 1388.700 s"),
        "{out}"
    );
    assert!(out.contains("| 1200000 "), "{out}");
    assert_fits(&["rope", "--duration", "400", "--no-record"], "| verlet ");
    assert_fits(&["hair", "--duration", "60", "--no-record"], "| verlet ");
}

/// The drift table says its command once, above the table, instead of in every row.
#[test]
fn the_drift_command_is_said_once() {
    let out = assert_fits(
        &[
            "study",
            "drift",
            "--duration",
            "400",
            "--methods",
            "rk4,verlet",
        ],
        "| rk4 ",
    );
    assert_eq!(out.matches("--duration 400").count(), 1, "{out}");
    assert!(
        out.contains("  physlab study drift --methods NAME --theta0 60 --dt 0.01 --duration 400\n"),
        "{out}"
    );
}

/// `--help` of every command, wrapped by clap: at most 100 columns without a terminal, and at
/// most 80 with COLUMNS=80.
#[test]
fn help_is_wrapped_to_the_terminal_width() {
    let kinds = [
        "convergence",
        "work-precision",
        "stability",
        "hair",
        "drift",
    ];
    let mut commands: Vec<Vec<&str>> = [
        "all",
        "pendulum",
        "rope",
        "hair",
        "study",
        "inspect",
        "reproduce",
        "diff",
        "methods",
    ]
    .iter()
    .map(|c| vec![*c])
    .collect();
    commands.extend(kinds.iter().map(|k| vec!["study", k]));
    commands.push(Vec::new());
    for command in &commands {
        for (columns, width) in [(None, WIDTH), (Some("80"), 80)] {
            let mut run = Command::new(env!("CARGO_BIN_EXE_physlab"));
            run.args(command).arg("--help").env_remove("COLUMNS");
            if let Some(c) = columns {
                run.env("COLUMNS", c);
            }
            let out = run.output().unwrap();
            let text = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success() && text.contains("Usage"),
                "{command:?}: {text}"
            );
            // clap wraps by Unicode display width, where °, θ and ≤ take one column.
            let line = (text.lines())
                .max_by_key(|l| l.chars().count())
                .unwrap_or("");
            let n = line.chars().count();
            assert!(
                n <= width,
                "{command:?} --help with COLUMNS={columns:?}: a line of {n} columns:\n{line}"
            );
        }
    }
}

/// `physlab methods` is one screen holding every method's row; `physlab methods NAME` is that
/// method's page, its stability limit the theory's (2√2 for rk4 on the undamped oscillator);
/// an unknown name is refused with the names allowed.
#[test]
fn methods_is_one_screen_and_a_name_its_page() {
    let out = assert_fits(&["methods"], "| rk4 ");
    assert!(
        out.lines().count() <= 30,
        "{} lines:\n{out}",
        out.lines().count()
    );
    for m in ["explicit-euler", "yoshida4", "dprkn12", "vern9"] {
        assert!(out.contains(&format!("| {m} ")), "{m}:\n{out}");
    }
    let page = assert_fits(&["methods", "rk4"], "");
    let limit = format!("{:.4}", 2.0 * 2f64.sqrt());
    assert!(page.starts_with("rk4\n"), "{page}");
    assert!(
        page.contains("- order: 4 ") && page.contains(&limit),
        "{page}"
    );
    assert!(page.contains("- update: classic Runge-Kutta"), "{page}");
    let page = assert_fits(&["methods", "verlet"], "");
    assert!(
        page.contains("- notes: ") && page.contains("- in hair"),
        "{page}"
    );
    let (code, out, err) = physlab(&["methods", "rk5"]);
    assert_eq!((code, out.as_str()), (2, ""), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("rk5") && err.contains("rk4, verlet") && err.contains("ftl"),
        "{err}"
    );
}

/// `--wide` prints the full tables: every column (wall times, the period, W, the notes of the
/// stability study) under its full header, wider than 100 columns.
#[test]
fn wide_shows_the_full_tables() {
    let dir = scratch_dir("width-wide");
    let out = dir.join("p.rrd");
    let (_, fitted, _) = physlab(&["pendulum", "-o", s(&out)]);
    let (code, wide, err) = physlab(&["pendulum", "-o", s(&out), "--wide"]);
    assert_eq!(code, 0, "{err}");
    for header in ["| wall [ms] ", "| max abs(θ−θref) [rad] ", "| period [s] "] {
        assert!(
            wide.contains(header) && !fitted.contains(header),
            "{header}:\n{wide}"
        );
    }
    assert!(widest(&wide).0 > WIDTH, "{wide}");
    let (_, wide, _) = physlab(&["rope", "-o", s(&out), "--wide"]);
    assert!(
        wide.contains("| W [J] ") && wide.contains("| cost per step "),
        "{wide}"
    );
    let (_, wide, _) = physlab(&["study", "stability", "--wide"]);
    assert!(
        wide.contains("| note ") && widest(&wide).0 > WIDTH,
        "{wide}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_methods_text_fits_a_terminal_of_100_columns_in_30_lines() {
    let text = methods_table();
    let widest = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
    assert!(widest <= WIDTH, "{widest} columns");
    assert!(text.lines().count() <= 30, "{text}");
    assert!(text.contains("| rk4 "), "{text}");
    for name in page_names() {
        let page = method_page(name).unwrap();
        let widest = page.lines().map(|l| l.chars().count()).max().unwrap_or(0);
        assert!(widest <= WIDTH, "{name}: {widest} columns");
    }
    assert!(method_page("vern9").unwrap().contains("- notes: "));
    assert!(method_page("ftl").unwrap().contains("in hair"));
    assert!(method_page("nope").is_none());
}
