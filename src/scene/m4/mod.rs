//! M4 aggregation of one time series (Jugel et al., "M4: A Visualization-Oriented Time Series
//! Data Aggregation", VLDB 2014): a series of any length reduced to at most five points per
//! pixel column, so that drawing the reduced series draws what drawing every step would.
//!
//! # The grid
//! A run has steps n = 0, 1, ..., N (time t = n·dt, computed from n by the caller, e.g.
//! [`super::harness::schedule::Clock::time`], never summed). The whole run is split into C
//! columns (1 ≤ C ≤ [`MAX_COLUMNS`]) by integer arithmetic:
//!
//! ```text
//! column_C(n) = min(⌊n·C / N⌋, C - 1)        (N ≥ 1; every step is column 0 when N = 0)
//! ```
//!
//! that is, the x axis from t = 0 to t = N·dt cut into C equal columns, the last one closed.
//!
//! # Which widths are exact
//! Exactly the widths W that divide C. For W = C/k, ⌊⌊n·C/N⌋ / k⌋ = ⌊n·W/N⌋ for n < N and
//! ⌊(C - 1)/k⌋ = W - 1 for n = N, so `column_W(n) = column_C(n) / k`: each of the W columns is
//! the union of k whole M4 columns, and its first, last, minimum and maximum are among theirs.
//! A width that does not divide C (or a renderer that maps t to x in floating point and lands a
//! step exactly on a column boundary on the other side) may put one step in a different column
//! and is not covered. With C = 4096, W = 4096, 2048, 1024, ... are exact.
//!
//! What is exact, per column of such a W, for any series: the first and the last point (step
//! and value), the minimum and the maximum value, and whether the column holds a NaN. And the
//! pixels lit by the polyline through consecutive steps (segments at a NaN left out, values
//! mapped to rows by any nondecreasing map, ±∞ clamped to the edge rows) are identical whenever
//! the NaNs of the series form a suffix, as after a divergence: within a column, a chain of
//! finite points lights every row between its minimum and its maximum, which the kept points
//! span too, and the segments between columns join the last point of one column to the first of
//! the next, which are kept. (A NaN in the middle of a column splits its chain in two; keeping
//! both chains' extremes would need unbounded room, so that case keeps only the statistics.)
//!
//! # Non-finite values
//! ±∞ are ordered values: +∞ can be the maximum and -∞ the minimum, so a blow-up is drawn at the
//! edge. NaN is never a minimum or maximum (comparisons with NaN are false, and the extremes are
//! taken over the non-NaN values only); instead the first NaN of each column is kept as a point
//! of its own, besides the column's first and last points (which are kept whatever they are).
//! So a divergence stays visible in every column it reaches.
//!
//! # Cost
//! Streaming: one column is open at a time (five points); a closed column's points (at most
//! five, in step order, without duplicates) are appended to the output, which
//! [`M4::take_completed`] hands over. Memory is O(C) per series whatever N is, O(1) if the
//! caller takes the completed points as it goes.

/// The most columns a series is aggregated to: the widest plot drawn exactly.
pub const MAX_COLUMNS: u32 = 4096;

/// One kept sample of a one-value series: its step index n (time n·dt) and value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub step: u64,
    pub value: f64,
}

/// The column of step `step` when steps 0..=`last_step` are cut into `columns` columns (see the
/// module documentation). Exact integer arithmetic.
pub fn column(step: u64, last_step: u64, columns: u32) -> u32 {
    if last_step == 0 {
        return 0;
    }
    let c = u128::from(step) * u128::from(columns) / u128::from(last_step);
    c.min(u128::from(columns) - 1) as u32
}

/// The first step of column `index` (u64::MAX past the last column): the least n with
/// ⌊n·C/N⌋ ≥ index, so that a stream finds its column by one comparison per step.
fn first_step_of(index: u32, last_step: u64, columns: u32) -> u64 {
    if index >= columns || last_step == 0 {
        return u64::MAX;
    }
    (u128::from(index) * u128::from(last_step)).div_ceil(u128::from(columns)) as u64
}

/// What one column keeps of one value while it is open: its first and last present point, its
/// smallest and largest non-NaN value (the earliest on ties) and the step of its first NaN.
#[derive(Clone, Copy, Debug, Default)]
struct Extremes {
    first: Option<Point>,
    last: Option<Point>,
    min: Option<Point>,
    max: Option<Point>,
    nan: Option<u64>,
}

impl Extremes {
    /// Takes in value `q` of consecutive rows whose values q are all present and not NaN,
    /// given their extremes per chunk of [`CHUNK`] rows: where the rows' extremes are is looked
    /// up only when they beat the column's, in the first chunk that holds them.
    fn add_plain(&mut self, rows: &[Sample], q: usize, chunks: &[(Row, Row)]) {
        let point = |k: usize| Point {
            step: rows[k].0,
            value: rows[k].1[q],
        };
        self.first.get_or_insert(point(0));
        self.last = Some(point(rows.len() - 1));
        let lo = chunks.iter().fold(f64::INFINITY, |m, c| m.min(c.0[q]));
        let hi = chunks.iter().fold(f64::NEG_INFINITY, |m, c| m.max(c.1[q]));
        let at = |x: f64, of: fn(&(Row, Row)) -> &Row| {
            let c = chunks
                .iter()
                .position(|c| of(c)[q] == x)
                .expect("an extreme is a value");
            let start = c * CHUNK;
            let end = (start + CHUNK).min(rows.len());
            start
                + rows[start..end]
                    .iter()
                    .position(|r| r.1[q] == x)
                    .expect("in its chunk")
        };
        if self.min.is_none_or(|m| lo < m.value) {
            self.min = Some(point(at(lo, |c| &c.0)));
        }
        if self.max.is_none_or(|m| hi > m.value) {
            self.max = Some(point(at(hi, |c| &c.1)));
        }
    }

    /// Takes in value `q` of consecutive rows, whatever they are: zeros that are absent, NaNs.
    fn add_any(&mut self, rows: &[Sample], q: usize, absent_when_zero: bool) {
        const NO: usize = usize::MAX;
        let (mut first, mut last, mut nan) = (NO, NO, NO);
        let (mut lo, mut lo_at, mut hi, mut hi_at) = (f64::INFINITY, NO, f64::NEG_INFINITY, NO);
        for (k, row) in rows.iter().enumerate() {
            let v = row.1[q];
            if absent_when_zero && v == 0.0 {
                continue;
            }
            first = first.min(k);
            last = k;
            if v < lo {
                (lo, lo_at) = (v, k);
            }
            if v > hi {
                (hi, hi_at) = (v, k);
            }
            if v.is_nan() && nan == NO {
                nan = k;
            }
        }
        if last == NO {
            return;
        }
        // Only +∞ (or only −∞) is never below (above) the start: its first one is the extreme.
        let present_not_nan = |k: &usize| {
            let v = rows[*k].1[q];
            !(v.is_nan() || absent_when_zero && v == 0.0)
        };
        if lo_at == NO {
            lo_at = (first..=last).find(present_not_nan).unwrap_or(NO);
        }
        if hi_at == NO {
            hi_at = (first..=last).find(present_not_nan).unwrap_or(NO);
        }
        let point = |k: usize| Point {
            step: rows[k].0,
            value: rows[k].1[q],
        };
        self.first.get_or_insert(point(first));
        self.last = Some(point(last));
        if lo_at != NO && self.min.is_none_or(|m| point(lo_at).value < m.value) {
            self.min = Some(point(lo_at));
        }
        if hi_at != NO && self.max.is_none_or(|m| point(hi_at).value > m.value) {
            self.max = Some(point(hi_at));
        }
        if nan != NO && self.nan.is_none() {
            self.nan = Some(rows[nan].0);
        }
    }
}

/// Rows kept, flat: row i is at `steps[i]`, its values are `values[i·width..(i+1)·width]`, and
/// bit q of `needed[i]` says whether value q's plot needs it. Only the values a row is needed
/// for are kept; the others are NaN there and must not be drawn.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Kept {
    pub steps: Vec<u64>,
    pub values: Vec<f64>,
    pub needed: Vec<u64>,
}

impl Kept {
    pub fn push(&mut self, step: u64, row: &[f64], needed: u64) {
        self.steps.push(step);
        self.values.extend_from_slice(row);
        self.needed.push(needed);
    }

    pub fn len(&self) -> usize {
        self.steps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }
}

/// The rows of one M4 column: its first and last row whole, and what each value keeps
/// ([`Extremes`]). A value's points are kept as that value alone, so a step that sets an extreme
/// costs one (step, value) pair, not a copy of the row; the whole rows stand for every value's
/// first and last point that falls on them.
#[derive(Clone, Debug)]
struct Open {
    index: u32,
    first: Option<(u64, Row)>,
    last: (u64, Row),
    extremes: Vec<Extremes>,
    /// Scratch of [`extremes_of`].
    chunks: Vec<(Row, Row)>,
}

/// Values per row at most: a row is a fixed-size array, so that keeping one is a move the
/// compiler writes out, not a call.
pub const MAX_VALUES: usize = 8;

/// One row's values, padded with zeros past its width.
pub type Row = [f64; MAX_VALUES];

/// A row and its step.
pub type Sample = (u64, Row);

/// A row of `values.len()` ≤ [`MAX_VALUES`] values as a [`Row`].
#[inline]
pub fn row_of(values: &[f64]) -> Row {
    std::array::from_fn(|q| values.get(q).copied().unwrap_or(0.0))
}

/// Rows per chunk of the extremes pass: where an extreme is is looked up in one chunk.
const CHUNK: usize = 64;

/// Per chunk of [`CHUNK`] rows, per value q < W: the smallest and largest value; and per value
/// whether any is NaN or an absent zero (then its extremes are meaningless). Written into
/// `chunks` (cleared first).
fn extremes_of<const W: usize>(
    rows: &[Sample],
    absent: &[bool; MAX_VALUES],
    chunks: &mut Vec<(Row, Row)>,
) -> [bool; MAX_VALUES] {
    chunks.clear();
    let mut odd = [false; MAX_VALUES];
    for chunk in rows.chunks(CHUNK) {
        let (mut lo, mut hi) = ([f64::INFINITY; MAX_VALUES], [f64::NEG_INFINITY; MAX_VALUES]);
        for (_, row) in chunk {
            for q in 0..W {
                let v = row[q];
                lo[q] = if v < lo[q] { v } else { lo[q] };
                hi[q] = if v > hi[q] { v } else { hi[q] };
                odd[q] |= v.is_nan() | (absent[q] & (v == 0.0));
            }
        }
        chunks.push((lo, hi));
    }
    odd
}

impl Open {
    fn new(width: usize) -> Self {
        Open {
            index: 0,
            first: None,
            last: (0, [0.0; MAX_VALUES]),
            extremes: vec![Extremes::default(); width],
            chunks: Vec::new(),
        }
    }

    fn width(&self) -> usize {
        self.extremes.len()
    }

    fn reset(&mut self, index: u32) {
        self.index = index;
        self.first = None;
        self.extremes.fill(Extremes::default());
    }

    /// Takes in consecutive rows of this column: one pass finds every value's extremes at once
    /// and which values are not plain (a NaN, or an absent zero); only those take the slower way.
    fn add(&mut self, rows: &[Sample], absent: &[bool; MAX_VALUES]) {
        // The pass over the values the rows have, not all MAX_VALUES.
        let chunks = &mut self.chunks;
        let odd = match self.extremes.len() {
            0..=2 => extremes_of::<2>(rows, absent, chunks),
            3..=4 => extremes_of::<4>(rows, absent, chunks),
            5..=6 => extremes_of::<6>(rows, absent, chunks),
            _ => extremes_of::<MAX_VALUES>(rows, absent, chunks),
        };
        self.first.get_or_insert(rows[0]);
        for (q, e) in self.extremes.iter_mut().enumerate() {
            if odd[q] {
                e.add_any(rows, q, absent[q]);
            } else {
                e.add_plain(rows, q, &self.chunks);
            }
        }
        self.last = rows[rows.len() - 1];
    }

    /// Appends the kept rows in step order, each once, with the values that need them; a
    /// value a row is not kept for is NaN there.
    fn close(&self, out: &mut Kept) {
        let Some(first) = &self.first else {
            return;
        };
        let w = self.width();
        let (mut from_first, mut from_last) = (0u64, 0u64);
        let mut points: Vec<(u64, usize, f64)> = Vec::with_capacity(5 * w);
        for (q, e) in self.extremes.iter().enumerate() {
            let own = |p: &Point| (p.step, q, p.value);
            match e.first {
                Some(p) if p.step == first.0 => from_first |= 1 << q,
                Some(p) => points.push(own(&p)),
                None => {}
            }
            match e.last {
                Some(p) if p.step == self.last.0 => from_last |= 1 << q,
                Some(p) => points.push(own(&p)),
                None => {}
            }
            points.extend(e.min.iter().chain(&e.max).map(own));
            points.extend(e.nan.map(|step| (step, q, f64::NAN)));
        }
        let whole = [(first, from_first), (&self.last, from_last)];
        let mut rows: Vec<(u64, Row, u64)> = whole
            .iter()
            .filter(|(_, needed)| *needed != 0)
            .map(|((step, row), needed)| (*step, *row, *needed))
            .collect();
        rows.extend(points.iter().map(|&(step, q, value)| {
            let mut row = [f64::NAN; MAX_VALUES];
            row[q] = value;
            (step, row, 1 << q)
        }));
        rows.sort_by_key(|r| r.0);
        for (step, row, needed) in rows {
            if out.steps.last() == Some(&step) {
                let at = out.len() - 1;
                let kept = &mut out.values[at * w..(at + 1) * w];
                for (q, (k, v)) in kept.iter_mut().zip(&row).enumerate() {
                    if needed & (1 << q) != 0 {
                        *k = *v;
                    }
                }
                out.needed[at] |= needed;
            } else {
                out.push(step, &row[..w], needed);
            }
        }
    }
}

/// The M4 aggregate of rows of `width` values (one series per value, sharing their steps) over
/// the steps 0..=N, fed one step at a time. Each value is aggregated on its own; a column keeps
/// the union of the rows its values keep ([`Kept::needed`] says which each value needs). A value
/// marked `absent_when_zero` (plotted as log10 |x|) treats its zeros as no point at all.
#[derive(Clone, Debug)]
pub struct M4 {
    last_step: u64,
    columns: u32,
    width: usize,
    absent: [bool; MAX_VALUES],
    open: Open,
    is_open: bool,
    next_column_at: u64,
    previous_step: Option<u64>,
    completed: Kept,
}

impl M4 {
    /// An empty aggregate of rows of `absent_when_zero.len()` values over steps 0..=`last_step`
    /// in `columns` columns; an error unless 1 ≤ columns ≤ [`MAX_COLUMNS`] and
    /// 1 ≤ width ≤ [`MAX_VALUES`] (so bit 63 of [`Kept::needed`] is left to the caller).
    pub fn new(last_step: u64, columns: u32, absent_when_zero: &[bool]) -> Result<Self, String> {
        if !(1..=MAX_COLUMNS).contains(&columns) {
            return Err(format!(
                "M4 columns must be from 1 to {MAX_COLUMNS}, got {columns}"
            ));
        }
        if !(1..=MAX_VALUES).contains(&absent_when_zero.len()) {
            return Err(format!(
                "M4 rows must have from 1 to {MAX_VALUES} values, got {}",
                absent_when_zero.len()
            ));
        }
        Ok(M4 {
            last_step,
            columns,
            width: absent_when_zero.len(),
            absent: std::array::from_fn(|q| absent_when_zero.get(q) == Some(&true)),
            open: Open::new(absent_when_zero.len()),
            is_open: false,
            next_column_at: 0,
            previous_step: None,
            completed: Kept::default(),
        })
    }

    /// Adds the row at `step`. Steps come in increasing order and at most N (a lane that stops
    /// early simply stops pushing; steps may be skipped). Panics otherwise: that is a bug in the
    /// caller, not input.
    pub fn push(&mut self, step: u64, values: &[f64]) {
        assert_eq!(values.len(), self.width, "M4 rows have a fixed width");
        self.push_rows(&[(step, row_of(values))]);
    }

    /// Adds rows (values past the width are ignored), by the same rules as [`M4::push`].
    pub fn push_rows(&mut self, rows: &[Sample]) {
        assert!(
            rows.windows(2).all(|w| w[0].0 < w[1].0)
                && rows
                    .first()
                    .is_none_or(|r| self.previous_step.is_none_or(|p| r.0 > p))
                && rows.last().is_none_or(|r| r.0 <= self.last_step),
            "M4 steps must increase within 0..={}: {:?} after {:?}",
            self.last_step,
            rows.first().map(|r| r.0),
            self.previous_step
        );
        let mut i = 0;
        while i < rows.len() {
            let step = rows[i].0;
            if step >= self.next_column_at || !self.is_open {
                let index = column(step, self.last_step, self.columns);
                if self.is_open {
                    self.open.close(&mut self.completed);
                }
                self.open.reset(index);
                self.is_open = true;
                self.next_column_at = first_step_of(index + 1, self.last_step, self.columns);
            }
            let end = i + rows[i..].partition_point(|r| r.0 < self.next_column_at);
            self.open.add(&rows[i..end], &self.absent);
            i = end;
        }
        self.previous_step = rows.last().map(|r| r.0).or(self.previous_step);
    }

    /// The rows of the columns closed so far, in step order, handed over and forgotten.
    pub fn take_completed(&mut self) -> Kept {
        std::mem::take(&mut self.completed)
    }

    /// Closes the last column and returns every row not yet taken, in step order.
    pub fn finish(mut self) -> Kept {
        if self.is_open {
            self.open.close(&mut self.completed);
        }
        self.completed
    }
}
