//! Plain-text tables in Markdown pipe syntax, padded so they read well in a terminal and paste
//! cleanly into a bug report; in full (`--wide`, the recordings, the documents) or fitted to a
//! terminal of [`WIDTH`] columns.

use crate::scene::harness::LaneStats;

/// The widest line printed by default: a terminal of 100 columns shows it without wrapping.
pub const WIDTH: usize = 100;

/// A table under construction: a header row and data rows of the same width.
pub struct Table {
    header: Vec<String>,
    /// Each column's header in the fitted table ([`Table::with_short`]); empty: left out there.
    short: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<I, S>(header: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        let header: Vec<String> = header.into_iter().map(Into::into).collect();
        Table {
            short: header.clone(),
            header,
            rows: Vec::new(),
        }
    }

    /// A table of columns each with its full header and its header in the fitted table: short,
    /// units kept; an empty one leaves its column out there (what the others or the lines above
    /// already say).
    pub fn with_short<const N: usize>(columns: [(&str, &str); N]) -> Self {
        Table {
            header: columns.map(|c| c.0.to_string()).into(),
            short: columns.map(|c| c.1.to_string()).into(),
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

    /// The full table (`wide`) or the fitted one: the short headers, and each column that holds
    /// the same value in every row said once above the table instead (left out if a dash).
    pub fn render_at(&self, wide: bool) -> String {
        if wide {
            return self.render();
        }
        let same = |c: usize| {
            c > 0 && self.rows.len() > 1 && self.rows.iter().all(|r| r[c] == self.rows[0][c])
        };
        let (mut kept, mut said) = (Vec::new(), Vec::new());
        for (c, short) in self.short.iter().enumerate() {
            match (short.is_empty(), same(c)) {
                (true, _) => {}
                (false, true) if self.rows[0][c] == "—" => {}
                (false, true) => said.push(format!("{short} = {}", self.rows[0][c])),
                (false, false) => kept.push(c),
            }
        }
        let fitted = self.pick(&self.short, &kept);
        let mut out = String::new();
        if !said.is_empty() {
            out = fit_lines(&format!("every row: {}\n", said.join(", ")));
        }
        out + &fitted.render_within(WIDTH)
    }

    /// The columns `cols` of this table under the headers `header` (indexed as the columns).
    fn pick(&self, header: &[String], cols: &[usize]) -> Table {
        let mut t = Table::new(cols.iter().map(|&c| header[c].clone()));
        for r in &self.rows {
            t.row(cols.iter().map(|&c| r[c].clone()));
        }
        t
    }

    /// The table, or where a line of it is wider than `width` [`columns`] (long runs widen the
    /// counts and times), the table in parts one under another: each part the leading columns
    /// that tell its rows apart and as many of the next as fit, so that no value is left out.
    pub fn render_within(&self, width: usize) -> String {
        let fits = |t: &Table| t.render().lines().all(|l| columns(l) <= width);
        let key = (1..self.header.len())
            .find(|&k| {
                let mut seen = std::collections::HashSet::new();
                self.rows.iter().all(|r| seen.insert(&r[..k]))
            })
            .unwrap_or(self.header.len());
        if key + 1 >= self.header.len() || fits(self) {
            return self.render();
        }
        let mut parts = vec![(0..key).collect::<Vec<_>>()];
        for c in key..self.header.len() {
            let part = parts.last_mut().expect("one part");
            part.push(c);
            if part.len() > key + 1 && !fits(&self.pick(&self.header, part)) {
                part.pop();
                parts.push((0..key).chain([c]).collect());
            }
        }
        let rendered: Vec<String> = (parts.iter())
            .map(|p| self.pick(&self.header, p).render())
            .collect();
        rendered.join("\n")
    }

    /// The full table.
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
        // Padded to `w` characters (format's width counts chars, as the widths do).
        let line = |cells: &[String]| -> String {
            let cell = |c: usize| cells.get(c).map_or("", String::as_str);
            let padded: String = (widths.iter().enumerate())
                .map(|(c, &w)| format!(" {:<w$} |", cell(c)))
                .collect();
            format!("|{padded}\n")
        };
        let rule: String = widths.iter().map(|w| "-".repeat(w + 2) + "|").collect();
        let mut out = line(&self.header) + "|" + &rule + "\n";
        for r in &self.rows {
            out.push_str(&line(r));
        }
        out
    }
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

/// The steps a lane took; an adaptive lane's own steps after them, fitted as "(accepted+rejected)".
pub fn steps_cell(s: &LaneStats, wide: bool) -> String {
    match s.counts.own_steps {
        Some((accepted, rejected)) if !wide => {
            format!("{} ({accepted}+{rejected})", s.ticks_taken())
        }
        _ => s.steps_text(),
    }
}

/// Whether and when a lane diverged; fitted, "at T s" or "no" (and missed solves, in full).
pub fn diverged_cell(s: &LaneStats, wide: bool) -> String {
    match &s.divergence {
        Some(ev) if !wide && s.counts.failed_solves == 0 => format!("at {:.3} s", ev.time),
        _ => crate::scene::harness::divergence_cell(s),
    }
}

/// Said under a summary table that holds an adaptive method.
pub const OWN_STEPS_NOTE: &str = "adaptive methods, and fixed-step ones given --step: \"steps\" counts the dt grid they are \
     sampled on (by their dense output or interpolant); their own accepted and rejected steps are in \
     brackets, and ns/step is per own step\n";

/// The most columns any terminal gives `text`: two for every character outside ASCII, as a
/// terminal that draws East Asian ambiguous-width characters (°, θ, ≤, −) wide does.
pub fn columns(text: &str) -> usize {
    text.chars().map(|c| if c.is_ascii() { 1 } else { 2 }).sum()
}

/// Text broken into lines of at most `width` [`columns`] at spaces (a longer word stands alone).
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let last = lines.last_mut().expect("one line");
        if !last.is_empty() && columns(last) + 1 + columns(word) > width {
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

/// `text` as a terminal of [`WIDTH`] columns shows it: every longer line that is not a table
/// row wrapped at spaces, its indentation kept.
pub fn fit_lines(text: &str) -> String {
    let mut out = String::new();
    for line in text.split_inclusive('\n') {
        let body = line.trim_end_matches('\n');
        if columns(body) <= WIDTH || body.starts_with('|') {
            out.push_str(line);
            continue;
        }
        let indent = &body[..body.len() - body.trim_start().len()];
        let lines = wrap(body, WIDTH - indent.chars().count());
        let indented: Vec<String> = (lines.iter()).map(|l| format!("{indent}{l}")).collect();
        out.push_str(&indented.join("\n"));
        out.push_str(&line[body.len()..]);
    }
    out
}

/// `- name: text` wrapped to `width` columns, its continuation lines indented by two.
pub fn list_item(name: &str, text: &str, width: usize) -> String {
    let lines = wrap(&format!("- {name}: {text}"), width - 2);
    let indent = |k: usize| if k > 0 { "  " } else { "" };
    (lines.iter().enumerate())
        .map(|(k, line)| format!("{}{line}\n", indent(k)))
        .collect()
}
