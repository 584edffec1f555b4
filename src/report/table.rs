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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_pads_columns() {
        let mut t = Table::new(["a", "long"]);
        t.row(["xyz", "1"]);
        assert_eq!(
            t.render(),
            "| a   | long |\n|-----|------|\n| xyz | 1    |\n"
        );
    }
}
