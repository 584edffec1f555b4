//! Plain-text tables in Markdown pipe syntax, padded so they read well in a terminal and paste
//! cleanly into a bug report.

use crate::scene::harness::LaneStats;

/// A table under construction: a header row and data rows of the same width.
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<I, S>(header: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        Table {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    pub fn row<I, S>(&mut self, cells: I)
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        let row: Vec<String> = cells.into_iter().map(Into::into).collect();
        debug_assert_eq!(row.len(), self.header.len(), "row width matches the header");
        self.rows.push(row);
    }

    pub fn render(&self) -> String {
        let widths: Vec<usize> = (0..self.header.len())
            .map(|c| {
                std::iter::once(&self.header)
                    .chain(&self.rows)
                    .map(|r| r.get(c).map_or(0, |s| s.chars().count()))
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |cells: &[String]| {
            let mut s = String::from("|");
            for (c, w) in widths.iter().enumerate() {
                let cell = cells.get(c).map_or("", String::as_str);
                let pad = w - cell.chars().count();
                s.push(' ');
                s.push_str(cell);
                s.push_str(&" ".repeat(pad));
                s.push_str(" |");
            }
            s.push('\n');
            s
        };
        let mut out = line(&self.header);
        out.push('|');
        for w in &widths {
            out.push_str(&"-".repeat(w + 2));
            out.push('|');
        }
        out.push('\n');
        for r in &self.rows {
            out.push_str(&line(r));
        }
        out
    }
}

/// A number to `digits` significant digits: fixed point between 1e-3 and 1e6 (17.27051,
/// 0.001234568), exponent form outside (6.198721e8, 4.4e-7), so that no digit a reader needs is
/// lost to a fixed number of decimals.
pub fn sig(x: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let exponent = x.abs().log10().floor() as i32;
    if (-3..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

/// Two values to the digits that tell them apart, and one more: 1.0471975512 and
/// 1.0471975522 for a difference of 1e-9, 0.52 and 0.61 for one of 0.09 (at least three
/// digits; at most seventeen, which tell any two doubles apart).
pub fn sig_pair(a: f64, b: f64) -> (String, String) {
    let scale = a.abs().max(b.abs());
    let apart = (b - a).abs();
    let mut digits = if apart > 0.0 && scale.is_finite() && apart.is_finite() {
        ((scale / apart).log10().ceil() as usize + 1).clamp(3, 17)
    } else {
        3
    };
    while digits < 17 && a.to_bits() != b.to_bits() && sig(a, digits) == sig(b, digits) {
        digits += 1;
    }
    (sig(a, digits), sig(b, digits))
}

/// In exponent form with four significant digits.
pub fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// A lane's figure, or a dash for a lane that failed its first check: it has only the values
/// it started from.
pub fn figure(s: &LaneStats, text: String) -> String {
    if s.failed_at_once() {
        "—".into()
    } else {
        text
    }
}

/// Said under a summary table that holds an adaptive method.
pub const OWN_STEPS_NOTE: &str = "adaptive methods, and fixed-step ones given --step: \"steps\" counts the dt grid they are \
     sampled on (by their dense output or interpolant); their own accepted and rejected steps are in \
     brackets, and ns/step is per own step\n";

/// Text broken into lines of at most `width` characters at spaces (a longer word stands alone).
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && last.chars().count() + 1 + word.chars().count() > width {
            lines.push(word.to_string());
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(word);
        }
    }
    lines
}

/// `- name: text` wrapped to `width` columns, its continuation lines indented by two.
pub fn list_item(name: &str, text: &str, width: usize) -> String {
    let mut out = String::new();
    for (k, line) in wrap(&format!("- {name}: {text}"), width - 2)
        .into_iter()
        .enumerate()
    {
        if k > 0 {
            out.push_str("  ");
        }
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// A count with its noun: "1 substep", "2 substeps".
pub fn plural(n: impl Into<u64>, noun: &str) -> String {
    let n = n.into();
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// A number with at most `decimals` decimals and no trailing zeros: 59.99999999999999 → "60".
pub fn trim_number(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        let t = s.trim_end_matches('0').trim_end_matches('.');
        if t == "-0" {
            "0".to_string()
        } else {
            t.to_string()
        }
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trims_float_noise_and_zeros() {
        assert_eq!(trim_number(60f64.to_radians().to_degrees(), 9), "60");
        assert_eq!(trim_number(0.125, 9), "0.125");
        assert_eq!(trim_number(-1e-12, 9), "0");
        assert_eq!(trim_number(100.0, 3), "100");
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
}
