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

/// What one column keeps of one value while it is open: the steps (as slots of the column's
/// rows) of its first and last present value, its smallest and largest non-NaN value (the
/// earliest on ties) and its first NaN.
#[derive(Clone, Copy, Debug, Default)]
struct Extremes {
    first: Option<usize>,
    last: Option<usize>,
    min: Option<usize>,
    max: Option<usize>,
    nan: Option<usize>,
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
/// the values), and the values that need it.
#[derive(Clone, Debug)]
struct Open {
    index: u32,
    slots: Vec<f64>,
    used: Vec<bool>,
    needed_by: Vec<u64>,
    extremes: Vec<Extremes>,
}

/// Slots of an open column: 0 its first row, 1 its last, then five per value.
const FIRST: usize = 0;
const LAST: usize = 1;

impl Open {
    fn new(absent: &[bool]) -> Self {
        let width = absent.len();
        let slots = 2 + 5 * width;
        // The column's first and last rows are the first and last points of every value that
        // has no absent points; the others have slots of their own.
        let present: u64 = (0..width).filter(|&q| !absent[q]).map(|q| 1 << q).sum();
        let mut needed_by = vec![present; 2];
        needed_by.extend((0..width).flat_map(|q| [1u64 << q; 5]));
        Open {
            index: 0,
            slots: vec![0.0; slots * (width + 1)],
            used: vec![false; slots],
            needed_by,
            extremes: vec![Extremes::default(); width],
        }
    }

    fn width(&self) -> usize {
        self.extremes.len()
    }

    fn store(&mut self, slot: usize, step: u64, row: &[f64]) {
        let w = self.width() + 1;
        let s = &mut self.slots[slot * w..(slot + 1) * w];
        s[0] = f64::from_bits(step);
        s[1..].copy_from_slice(row);
        self.used[slot] = true;
    }

    fn value(&self, slot: usize, q: usize) -> f64 {
        self.slots[slot * (self.width() + 1) + 1 + q]
    }

    fn reset(&mut self, index: u32) {
        self.index = index;
        self.used.fill(false);
        self.extremes.fill(Extremes::default());
    }

    fn add(&mut self, step: u64, row: &[f64], absent: &[bool]) {
        if !self.used[FIRST] {
            self.store(FIRST, step, row);
        }
        self.store(LAST, step, row);
        for (q, &v) in row.iter().enumerate() {
            if absent[q] && v == 0.0 {
                continue;
            }
            // Slots of value q: first, last, min, max, NaN.
            let base = 2 + 5 * q;
            let e = self.extremes[q];
            if e.first.is_none() {
                self.store(base, step, row);
                self.extremes[q].first = Some(base);
            }
            self.store(base + 1, step, row);
            self.extremes[q].last = Some(base + 1);
            if v.is_nan() {
                if e.nan.is_none() {
                    self.store(base + 4, step, row);
                    self.extremes[q].nan = Some(base + 4);
                }
                continue;
            }
            if e.min.is_none_or(|m| v < self.value(m, q)) {
                self.store(base + 2, step, row);
                self.extremes[q].min = Some(base + 2);
            }
            if e.max.is_none_or(|m| v > self.value(m, q)) {
                self.store(base + 3, step, row);
                self.extremes[q].max = Some(base + 3);
            }
        }
    }

    /// Appends the kept rows in step order, each once, with the values that need them.
    fn close(&self, out: &mut Kept) {
        let w = self.width() + 1;
        let mut kept: Vec<(u64, usize)> = (0..self.used.len())
            .filter(|&s| self.used[s])
            .map(|s| (self.slots[s * w].to_bits(), s))
            .collect();
        kept.sort_unstable();
        for (step, s) in kept {
            if out.steps.last() == Some(&step) {
                *out.needed.last_mut().expect("a row per step") |= self.needed_by[s];
            } else {
                out.push(step, &self.slots[s * w + 1..(s + 1) * w], self.needed_by[s]);
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
            open: Open::new(absent_when_zero),
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
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Rows of the test rasters.
    const HEIGHT: u32 = 64;

    /// A column of a plain rasterisation: first and last (step, value bits), minimum and maximum
    /// value bits over non-NaN values, whether it holds a NaN.
    type Stats = ((u64, u64), (u64, u64), Option<u64>, Option<u64>, bool);

    /// The pixel column of step n at width w, written out here on its own: x = n·w/N, floored,
    /// the right edge belonging to the last column.
    fn pixel(n: u64, last: u64, w: u32) -> u32 {
        if last == 0 {
            0
        } else {
            ((u128::from(n) * u128::from(w) / u128::from(last)) as u32).min(w - 1)
        }
    }

    /// Per column statistics of the points drawn at width w.
    fn stats(points: &[Point], last: u64, w: u32) -> Vec<Option<Stats>> {
        let mut cols: Vec<Option<Stats>> = vec![None; w as usize];
        for p in points {
            let at = (p.step, p.value.to_bits());
            let c = &mut cols[pixel(p.step, last, w) as usize];
            let s = c.get_or_insert((at, at, None, None, false));
            s.1 = at;
            if p.value.is_nan() {
                s.4 = true;
            } else {
                if s.2.is_none_or(|m| p.value < f64::from_bits(m)) {
                    s.2 = Some(p.value.to_bits());
                }
                if s.3.is_none_or(|m| p.value > f64::from_bits(m)) {
                    s.3 = Some(p.value.to_bits());
                }
            }
        }
        cols
    }

    /// The pixels (w × HEIGHT) lit by the polyline through consecutive points, segments at a
    /// NaN left out. Values map to a continuous row in [0, HEIGHT] by the finite range
    /// [lo, hi], ±∞ clamped; a segment lights, in each column its x range crosses, the rows
    /// between its heights where it enters and leaves the column (all rows between its ends
    /// when both lie in one column). It depends on nothing but the segment's two points.
    fn lit(points: &[Point], last: u64, w: u32, lo: f64, hi: f64) -> Vec<bool> {
        let h = f64::from(HEIGHT);
        let y = |v: f64| {
            let r = if hi > lo {
                (v - lo) / (hi - lo) * h
            } else {
                0.0
            };
            r.clamp(0.0, h)
        };
        let x = |n: u64| {
            if last == 0 {
                0.0
            } else {
                n as f64 * f64::from(w) / last as f64
            }
        };
        let mut on = vec![false; (w * HEIGHT) as usize];
        let mut light = |c: u32, ya: f64, yb: f64| {
            let (a, b) = (ya.min(yb).floor() as u32, ya.max(yb).floor() as u32);
            for r in a.min(HEIGHT - 1)..=b.min(HEIGHT - 1) {
                on[(c * HEIGHT + r) as usize] = true;
            }
        };
        for p in points {
            if !p.value.is_nan() {
                let yp = y(p.value);
                light(pixel(p.step, last, w), yp, yp);
            }
        }
        for s in points.windows(2) {
            let (a, b) = (s[0], s[1]);
            if a.value.is_nan() || b.value.is_nan() {
                continue;
            }
            let (ca, cb) = (pixel(a.step, last, w), pixel(b.step, last, w));
            let (ya, yb) = (y(a.value), y(b.value));
            if ca == cb {
                light(ca, ya, yb);
                continue;
            }
            let (xa, xb) = (x(a.step), x(b.step));
            let at = |xx: f64| ya + (yb - ya) * ((xx - xa) / (xb - xa));
            for c in ca..=cb {
                let from = xa.max(f64::from(c));
                let to = if c == cb {
                    xb
                } else {
                    xb.min(f64::from(c + 1))
                };
                light(c, at(from), at(to));
            }
        }
        on
    }

    /// A test series: a swing with noise, spikes, runs of one repeated value, ties from
    /// rounding to a coarse grid, and non-finite values, all from one seed.
    #[derive(Clone, Debug)]
    struct Shape {
        seed: u64,
        last: u64,
        /// Percent of steps that spike.
        spikes: u32,
        /// Longest run of one repeated value.
        run: u64,
        /// Round values to multiples of 1/4 (many ties).
        coarse: bool,
        /// From this fraction of the run on, every value is non-finite (+∞ first, then NaN).
        diverge: Option<f64>,
        /// Sprinkle NaN and ±∞ at this per mille of the steps before that.
        sprinkle: u32,
    }

    fn series(s: &Shape) -> Vec<Point> {
        let mut state = s.seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let diverge_at = s.diverge.map(|f| (f * s.last as f64) as u64);
        let mut out = Vec::with_capacity(s.last as usize + 1);
        let mut repeat = 0u64;
        let mut held = 0.0;
        for n in 0..=s.last {
            let r = next();
            let mut v = if repeat > 0 {
                repeat -= 1;
                held
            } else {
                let base = (n as f64 * 0.013).sin() * 2.0 + (r % 1000) as f64 * 1e-3;
                let v = if ((r >> 20) % 100) < u64::from(s.spikes) {
                    ((r >> 30) % 2000) as f64 - 1000.0
                } else {
                    base
                };
                if s.run > 0 && (r >> 40) % 50 == 0 {
                    repeat = (r >> 45) % s.run;
                    held = v;
                }
                if s.coarse { (v * 4.0).round() / 4.0 } else { v }
            };
            match diverge_at {
                Some(d) if n == d => v = f64::INFINITY,
                Some(d) if n > d => v = f64::NAN,
                _ if ((r >> 50) % 1000) < u64::from(s.sprinkle) => {
                    v = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][(r % 3) as usize];
                }
                _ => {}
            }
            out.push(Point { step: n, value: v });
        }
        out
    }

    fn points(kept: Kept) -> Vec<Point> {
        kept.steps
            .into_iter()
            .zip(kept.values)
            .map(|(step, value)| Point { step, value })
            .collect()
    }

    fn aggregate(points: &[Point], last: u64, columns: u32) -> Vec<Point> {
        let mut m4 = M4::new(last, columns, &[false]).unwrap();
        let mut out = Vec::new();
        for (i, p) in points.iter().enumerate() {
            m4.push(p.step, &[p.value]);
            if i % 997 == 0 {
                out.extend(self::points(m4.take_completed()));
            }
        }
        out.extend(self::points(m4.finish()));
        out
    }

    /// Every width that divides `columns`.
    fn exact_widths(columns: u32) -> Vec<u32> {
        (1..=columns)
            .filter(|w| columns.is_multiple_of(*w))
            .collect()
    }

    fn finite_range(points: &[Point]) -> (f64, f64) {
        let finite = points.iter().map(|p| p.value).filter(|v| v.is_finite());
        let lo = finite.clone().fold(f64::INFINITY, f64::min);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max);
        if lo <= hi { (lo, hi) } else { (0.0, 1.0) }
    }

    /// Checks the M4 output of a series: step order without duplicates, at most five points
    /// per column, per-column statistics at every exact width equal to the full series', and,
    /// when `lines`, the lit pixels too. Returns the number of points kept.
    fn check(full: &[Point], last: u64, columns: u32, lines: bool) -> Result<usize, TestCaseError> {
        let kept = aggregate(full, last, columns);
        prop_assert!(kept.windows(2).all(|w| w[0].step < w[1].step));
        let mut per_column = vec![0u32; columns as usize];
        for p in &kept {
            per_column[pixel(p.step, last, columns) as usize] += 1;
            let original = full[p.step as usize];
            prop_assert_eq!(original.value.to_bits(), p.value.to_bits());
        }
        prop_assert!(per_column.iter().all(|&k| k <= 5));
        let (lo, hi) = finite_range(full);
        for w in exact_widths(columns) {
            prop_assert_eq!(stats(full, last, w), stats(&kept, last, w), "width {}", w);
            if lines {
                prop_assert!(
                    lit(full, last, w, lo, hi) == lit(&kept, last, w, lo, hi),
                    "lit pixels differ at width {}",
                    w
                );
            }
        }
        Ok(kept.len())
    }

    fn columns() -> impl Strategy<Value = u32> {
        prop_oneof![
            Just(4096u32),
            Just(1024),
            Just(3600),
            Just(1),
            Just(7),
            1u32..=4096,
        ]
    }

    fn shape(sprinkle: u32) -> impl Strategy<Value = Shape> {
        (
            any::<u64>(),
            prop_oneof![1u64..=100, 1u64..=5_000, 1u64..=100_000],
            0u32..20,
            0u64..500,
            any::<bool>(),
            proptest::option::of(0.0f64..1.0),
        )
            .prop_map(move |(seed, last, spikes, run, coarse, diverge)| Shape {
                seed,
                last,
                spikes,
                run,
                coarse,
                diverge,
                sprinkle,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// Series that end in a divergence (or are finite throughout): statistics and lit
        /// pixels identical at every width dividing C.
        #[test]
        fn drawn_exactly_at_every_dividing_width(s in shape(0), c in columns()) {
            let full = series(&s);
            let kept = check(&full, s.last, c, true)?;
            prop_assert!(kept <= 5 * c as usize);
        }

        /// NaN and ±∞ anywhere: the statistics stay identical (NaN kept per column, never an
        /// extreme).
        #[test]
        fn statistics_exact_with_non_finite_anywhere(s in shape(30), c in columns()) {
            check(&series(&s), s.last, c, false)?;
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Rows of three values aggregated together, the third absent where it is zero (a log
        /// plot leaves zeros out): each value's statistics and lit pixels are those of its own
        /// full series, and a column keeps at most 2 + 5 · 3 rows.
        #[test]
        fn rows_keep_every_value_exact(
            a in shape(0), b in shape(0), c in columns(), zero_percent in 0u64..60
        ) {
            let last = a.last;
            let first = series(&a);
            let second = series(&Shape { last, ..b });
            let third: Vec<Point> = second
                .iter()
                .map(|p| {
                    let zero = (p.step.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 32) % 100 < zero_percent;
                    Point { step: p.step, value: if zero { 0.0 } else { p.value.abs() } }
                })
                .collect();
            let mut m4 = M4::new(last, c, &[false, false, true]).unwrap();
            for n in 0..=last as usize {
                m4.push(n as u64, &[first[n].value, second[n].value, third[n].value]);
            }
            let Kept { steps, values, needed } = m4.finish();
            prop_assert!(steps.windows(2).all(|w| w[0] < w[1]));
            let mut per_column = vec![0u32; c as usize];
            for &n in &steps {
                per_column[pixel(n, last, c) as usize] += 1;
            }
            prop_assert!(per_column.iter().all(|&k| k <= 17));
            for q in 0..3 {
                let mut per_column = vec![0u32; c as usize];
                for (i, &n) in steps.iter().enumerate() {
                    if needed[i] & (1 << q) != 0 {
                        per_column[pixel(n, last, c) as usize] += 1;
                    }
                }
                prop_assert!(per_column.iter().all(|&k| k <= 5), "value {} needs more than 5 rows in a column", q);
            }
            for (q, full) in [first, second, third].iter().enumerate() {
                let present = |p: &Point| q < 2 || p.value != 0.0;
                let full: Vec<Point> = full.iter().copied().filter(present).collect();
                // Only the rows value q needs.
                let kept: Vec<Point> = steps
                    .iter()
                    .enumerate()
                    .filter(|&(i, _)| needed[i] & (1 << q) != 0)
                    .map(|(i, &step)| Point { step, value: values[3 * i + q] })
                    .filter(present)
                    .collect();
                for (k, p) in kept.iter().enumerate() {
                    let original = full.iter().find(|f| f.step == p.step).unwrap();
                    prop_assert_eq!(original.value.to_bits(), kept[k].value.to_bits());
                }
                let (lo, hi) = finite_range(&full);
                for w in exact_widths(c) {
                    prop_assert_eq!(stats(&full, last, w), stats(&kept, last, w), "value {} width {}", q, w);
                    prop_assert!(lit(&full, last, w, lo, hi) == lit(&kept, last, w, lo, hi), "value {} width {}", q, w);
                }
            }
        }
    }

    /// The grid identity the exactness rests on, over every step of small grids.
    #[test]
    fn dividing_widths_are_unions_of_whole_columns() {
        for last in 1..300u64 {
            for c in [1u32, 2, 6, 12, 60, 64, 4096] {
                for w in exact_widths(c) {
                    for n in 0..=last {
                        assert_eq!(column(n, last, c) / (c / w), pixel(n, last, w));
                    }
                }
            }
        }
    }

    /// A spike between columns' sample points, a NaN after divergence and a lone step: each
    /// kept where a plain every-Nth thinning would lose it.
    #[test]
    fn spikes_and_divergence_are_kept() {
        let mut values = vec![0.0; 1001];
        values[517] = 9.0;
        values[900] = f64::INFINITY;
        for v in &mut values[901..] {
            *v = f64::NAN;
        }
        let mut m4 = M4::new(1000, 10, &[false]).unwrap();
        for (n, v) in values.iter().enumerate() {
            m4.push(n as u64, &[*v]);
        }
        let steps = m4.finish().steps;
        // Column k holds steps 100k ..= 100k + 99 (the last also step 1000).
        let mut want = Vec::new();
        for k in 0..9u64 {
            want.extend([100 * k, 100 * k + 99]);
        }
        // Column 9: +∞ (first, min and max), the first NaN, the last.
        want.extend([517, 900, 901, 1000]);
        want.sort();
        assert_eq!(steps, want);
        assert!(M4::new(10, 0, &[false]).is_err() && M4::new(10, 4097, &[false]).is_err());
        let one = M4::new(0, 4096, &[false]).unwrap();
        assert!(one.finish().is_empty());
        assert!(M4::new(10, 4, &[]).is_err() && M4::new(10, 4, &[false; 64]).is_err());
    }
}
