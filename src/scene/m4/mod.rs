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

/// What one column keeps of one value while it is open: the slots (of the column's rows) of
/// its first and last present value, its smallest and largest non-NaN value (the earliest on
/// ties) and its first NaN, [`NONE`] until there is one; and the smallest and largest values.
#[derive(Clone, Copy, Debug)]
struct Extremes {
    first: usize,
    last: usize,
    min: usize,
    max: usize,
    nan: usize,
    lo: f64,
    hi: f64,
}

/// No slot yet.
const NONE: usize = usize::MAX;

impl Default for Extremes {
    fn default() -> Self {
        Extremes {
            first: NONE,
            last: NONE,
            min: NONE,
            max: NONE,
            nan: NONE,
            lo: 0.0,
            hi: 0.0,
        }
    }
}

/// Rows kept, flat: row i is at `steps[i]`, its values are `values[i·width..(i+1)·width]`, and
/// bit q of `needed[i]` says whether value q's plot needs it (a row kept for one value's
/// extreme is a true point of every other value too, but they can leave it out).
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

/// The rows of one M4 column: the column's first and last row, and for every value the rows of
/// its [`Extremes`]. A slot is a copy of a row, `width + 1` numbers (the step, as f64 bits, then
/// the values). A value's first and last present rows are the column's own when the value is
/// present there (always, for a value never absent), so a row is copied per step only into the
/// column's last slot, and into a value's own slots when it sets an extreme, first appears after
/// the column's first row, or is present in the last row as the next one leaves it absent.
#[derive(Clone, Debug)]
struct Open {
    index: u32,
    slots: Vec<f64>,
    /// Whether the column has its first row.
    started: bool,
    extremes: Vec<Extremes>,
}

/// Slots of an open column: 0 its first row, 1 its last, then five per value (its first and
/// last present rows when they are not the column's, its minimum, maximum and first NaN).
const FIRST: usize = 0;
const LAST: usize = 1;

impl Open {
    fn new(width: usize) -> Self {
        let slots = 2 + 5 * width;
        Open {
            index: 0,
            slots: vec![0.0; slots * (width + 1)],
            started: false,
            extremes: vec![Extremes::default(); width],
        }
    }

    fn width(&self) -> usize {
        self.extremes.len()
    }

    fn reset(&mut self, index: u32) {
        self.index = index;
        self.started = false;
        self.extremes.fill(Extremes::default());
    }

    fn add(&mut self, step: u64, row: &[f64], absent: &[bool]) {
        let w = self.width() + 1;
        let Open {
            slots,
            started,
            extremes,
            ..
        } = self;
        let store = |slots: &mut [f64], slot: usize| {
            let s = &mut slots[slot * w..(slot + 1) * w];
            s[0] = f64::from_bits(step);
            s[1..].copy_from_slice(row);
        };
        let starts = !*started;
        if starts {
            store(slots, FIRST);
            *started = true;
        }
        for (q, ((&v, &absent), e)) in row.iter().zip(absent).zip(extremes.iter_mut()).enumerate() {
            // Slots of value q: first, last, min, max, NaN.
            let base = 2 + 5 * q;
            if absent && v == 0.0 {
                // The last row, about to be overwritten, may be this value's last present one.
                if e.last == LAST {
                    slots.copy_within(LAST * w..(LAST + 1) * w, (base + 1) * w);
                    e.last = base + 1;
                }
                continue;
            }
            if e.first == NONE {
                e.first = if starts {
                    FIRST
                } else {
                    store(slots, base);
                    base
                };
            }
            e.last = LAST;
            if v.is_nan() {
                if e.nan == NONE {
                    store(slots, base + 4);
                    e.nan = base + 4;
                }
                continue;
            }
            if e.min == NONE || v < e.lo {
                store(slots, base + 2);
                (e.min, e.lo) = (base + 2, v);
            }
            if e.max == NONE || v > e.hi {
                store(slots, base + 3);
                (e.max, e.hi) = (base + 3, v);
            }
        }
        store(slots, LAST);
    }

    /// Appends the kept rows in step order, each once, with the values that need them.
    fn close(&self, out: &mut Kept) {
        let w = self.width() + 1;
        let mut needed = vec![0u64; 2 + 5 * self.width()];
        for (q, e) in self.extremes.iter().enumerate() {
            for slot in [e.first, e.last, e.min, e.max, e.nan] {
                if slot != NONE {
                    needed[slot] |= 1 << q;
                }
            }
        }
        let mut kept: Vec<(u64, usize)> = (0..needed.len())
            .filter(|&s| needed[s] != 0)
            .map(|s| (self.slots[s * w].to_bits(), s))
            .collect();
        kept.sort_unstable();
        for (step, s) in kept {
            if out.steps.last() == Some(&step) {
                *out.needed.last_mut().expect("a row per step") |= needed[s];
            } else {
                out.push(step, &self.slots[s * w + 1..(s + 1) * w], needed[s]);
            }
        }
    }
}

/// The M4 aggregate of rows of `width` values (one series per value, sharing their steps) over
/// the steps 0..=N, fed one step at a time. Each value is aggregated on its own; a column keeps
/// the union of the rows its values keep, so every value keeps its first, last, minimum,
/// maximum and first NaN per column (and maybe more of its true points, which changes nothing
/// drawn: see the module documentation; [`Kept::needed`] says which rows each value needs). A
/// value marked `absent_when_zero` (plotted as log10 |x|, where zeros are left out) treats its
/// zeros as no point at all.
#[derive(Clone, Debug)]
pub struct M4 {
    last_step: u64,
    columns: u32,
    absent: Vec<bool>,
    open: Open,
    is_open: bool,
    next_column_at: u64,
    previous_step: Option<u64>,
    completed: Kept,
}

impl M4 {
    /// An empty aggregate of rows of `absent_when_zero.len()` values over steps 0..=`last_step`
    /// in `columns` columns; an error unless 1 ≤ columns ≤ [`MAX_COLUMNS`] and 1 ≤ width ≤ 63
    /// (bit 63 of [`Kept::needed`] is left to the caller).
    pub fn new(last_step: u64, columns: u32, absent_when_zero: &[bool]) -> Result<Self, String> {
        if !(1..=MAX_COLUMNS).contains(&columns) {
            return Err(format!(
                "M4 columns must be from 1 to {MAX_COLUMNS}, got {columns}"
            ));
        }
        if !(1..=63).contains(&absent_when_zero.len()) {
            return Err(format!(
                "M4 rows must have from 1 to 63 values, got {}",
                absent_when_zero.len()
            ));
        }
        Ok(M4 {
            last_step,
            columns,
            absent: absent_when_zero.to_vec(),
            open: Open::new(absent_when_zero.len()),
            is_open: false,
            next_column_at: 0,
            previous_step: None,
            completed: Kept::default(),
        })
    }

    pub fn columns(&self) -> u32 {
        self.columns
    }

    /// Adds the row at `step`. Steps come in increasing order and at most N (a lane that stops
    /// early simply stops pushing; steps may be skipped). Panics otherwise: that is a bug in the
    /// caller, not input.
    pub fn push(&mut self, step: u64, row: &[f64]) {
        assert!(
            step <= self.last_step
                && self.previous_step.is_none_or(|s| step > s)
                && row.len() == self.absent.len(),
            "M4 steps must increase within 0..={}: {step} after {:?}",
            self.last_step,
            self.previous_step
        );
        self.previous_step = Some(step);
        if step >= self.next_column_at || !self.is_open {
            let index = column(step, self.last_step, self.columns);
            if self.is_open {
                self.open.close(&mut self.completed);
            }
            self.open.reset(index);
            self.is_open = true;
            self.next_column_at = first_step_of(index + 1, self.last_step, self.columns);
        }
        self.open.add(step, row, &self.absent);
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

#[cfg(test)]
mod tests;
