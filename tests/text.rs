//! Text as physlab prints it: numbers in their forms (`physlab::format`), tables fitted to a
//! terminal (`physlab::report::table`), and a recording's text escaped before it reaches one
//! (`physlab::shell::escaped`), each against text written out by hand.

use physlab::format::*;
use physlab::report::table::{Table, WIDTH, fit_lines};

/// Against `date -u -d @N`: the epoch, a leap day, before the epoch, year 9999.
#[test]
fn utc_dates_are_gnu_dates() {
    assert_eq!(
        [0, 951_782_400, -1, 1_795_000_000, 253_402_300_799].map(utc),
        [
            "1970-01-01 00:00:00 UTC",
            "2000-02-29 00:00:00 UTC",
            "1969-12-31 23:59:59 UTC",
            "2026-11-18 11:06:40 UTC",
            "9999-12-31 23:59:59 UTC"
        ]
    );
}

#[test]
fn trims_float_noise_and_zeros() {
    assert_eq!(trim_number(60f64.to_radians().to_degrees(), 9), "60");
    assert_eq!(trim_number(0.125, 9), "0.125");
    assert_eq!(trim_number(-1e-12, 9), "0");
    assert_eq!(trim_number(100.0, 3), "100");
}

#[test]
fn a_pair_shows_the_digits_that_tell_it_apart() {
    assert_eq!(
        sig_pair(1.0471975511965976, 1.0471975521965976),
        ("1.0471975512".to_string(), "1.0471975522".to_string())
    );
    assert_eq!(
        sig_pair(0.52, 0.61),
        ("0.520".to_string(), "0.610".to_string())
    );
    let (a, b) = sig_pair(1.0, 1.0 + f64::EPSILON);
    assert_ne!(a, b);
    assert_eq!(sig_pair(2.0, 2.0), ("2.00".to_string(), "2.00".to_string()));
}

/// Each form at the ends of its ranges, written out by hand.
#[test]
fn each_form_switches_where_it_says() {
    assert_eq!(
        [1e-4, 9.9e-5, 999999.0, 1e6, -0.5, 0.0].map(shown),
        ["0.0001", "9.9e-5", "999999", "1e6", "-0.5", "0"]
    );
    assert_eq!(
        [1e-3, 9e-4, 9999.0, 1e4].map(bound),
        ["0.001", "9e-4", "9999", "1e4"]
    );
    assert_eq!(
        [4.0404, 0.004471, 1234.6, 0.0].map(seconds),
        ["4.04", "0.00447", "1235", "0"]
    );
    assert_eq!(
        [17.270511, 0.0012345678, 6.1987214e8, 4.4e-7].map(|x| sig(x, 7)),
        ["17.27051", "0.001234568", "6.198721e8", "4.400000e-7"]
    );
    assert_eq!([30.4, 100.0, -1.0].map(eta), ["30s", "1m 40s", "0s"]);
    assert_eq!(
        [45.2, 185.0, 25_920.0].map(duration),
        ["45 s", "3 min 05 s", "7 h 12 min"]
    );
    assert_eq!([1.2e8, 3.44e9].map(size), ["120 MB", "3.4 GB"]);
    assert_eq!(
        [0u64, 1, 2].map(|n| plural(n, "entity")),
        ["0 entities", "1 entity", "2 entities"]
    );
}

#[test]
fn table_pads_columns() {
    let mut t = Table::new(["a", "long"]);
    t.row(["xyz", "1"]);
    assert_eq!(
        t.render(),
        "| a   | long |\n|-----|------|\n| xyz | 1    |\n"
    );
}

/// The fitted table: short headers, a left-out column, a constant column said once above
/// and a constant dash left out; the full table keeps all.
#[test]
fn the_fitted_table_says_a_constant_column_once() {
    let mut t = Table::with_short([
        ("method", "method"),
        ("steps taken", "steps"),
        ("wall", ""),
        ("diverged", "diverged"),
        ("note", "note"),
    ]);
    t.row(["a", "10", "1", "no", "—"]);
    t.row(["b", "20", "2", "no", "—"]);
    let fitted = [
        "every row: diverged = no",
        "| method | steps |",
        "|--------|-------|",
        "| a      | 10    |",
        "| b      | 20    |",
    ];
    assert_eq!(t.render_at(false), fitted.join("\n") + "\n");
    assert_eq!(t.render_at(true), t.render());
    assert!(t.render().contains("| steps taken | wall |"));
}

#[test]
fn long_lines_are_wrapped_and_table_rows_kept() {
    let long = format!("  {}\n| {} |\nshort", "word ".repeat(30), "x".repeat(120));
    let fitted = fit_lines(&long);
    let lines: Vec<&str> = fitted.lines().collect();
    assert_eq!(lines.len(), 4, "{fitted}");
    assert!(lines[0].starts_with("  word") && lines[1].starts_with("  word"));
    assert!(lines[..2].iter().all(|l| l.chars().count() <= WIDTH));
    assert_eq!(lines[2].chars().count(), 124);
    assert_eq!(lines[3], "short");
}

#[cfg(feature = "rerun")]
/// Every character that moves, hides or reorders text is shown as its UTF-8 bytes (the
/// hostile pass found U+061C, the Arabic letter mark, reaching the terminal), and plain text,
/// accents and CJK included, passes unchanged.
#[test]
fn characters_that_hide_or_reorder_text_are_shown_as_bytes() {
    for (c, bytes) in [
        ('\u{061c}', "\\xd8\\x9c"),
        ('\u{200b}', "\\xe2\\x80\\x8b"),
        ('\u{200f}', "\\xe2\\x80\\x8f"),
        ('\u{2028}', "\\xe2\\x80\\xa8"),
        ('\u{202e}', "\\xe2\\x80\\xae"),
        ('\u{2069}', "\\xe2\\x81\\xa9"),
        ('\u{feff}', "\\xef\\xbb\\xbf"),
        ('\u{1b}', "\\x1b"),
    ] {
        assert_eq!(
            physlab::shell::escaped(&format!("a{c}b")),
            format!("a{bytes}b"),
            "{c:?}"
        );
    }
    let plain = "θ0 = 60°, naïve 模型 E − E0";
    assert_eq!(physlab::shell::escaped(plain), plain);
}
