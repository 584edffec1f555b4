//! The sampled series: what a scene measures at a plotted tick, batched per lane for the
//! observer.

use super::Schedule;
use crate::scene::m4::{self, Kept, M4, Sample};
use std::collections::VecDeque;

/// Sampled values are handed to the observer in batches of about this many rows: every batch
/// becomes a chunk in a recording, and small chunks cost more than their data.
/// 4096 is the chunk size `rerun rrd optimize` compacts to (`ChunkStoreConfig::DEFAULT`).
pub(super) const SERIES_BATCH: usize = 4096;

/// Sampled values of one lane: the ticks, their times and one column per quantity.
#[derive(Clone, Debug, Default)]
pub struct SeriesBatch {
    pub ticks: Vec<u64>,
    pub times: Vec<f64>,
    pub columns: Vec<Vec<f64>>,
    /// Per row, bit q set when quantity q's plot needs the row (a row of the M4 aggregate kept
    /// for one quantity's extreme need not be drawn by the others); [`WHOLE`] (every bit) for
    /// a row of a stretch whose every sampled step is kept.
    pub needed: Vec<u64>,
}

impl SeriesBatch {
    pub fn new(quantities: usize) -> Self {
        SeriesBatch {
            columns: vec![Vec::new(); quantities],
            ..SeriesBatch::default()
        }
    }

    pub fn len(&self) -> usize {
        self.ticks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ticks.is_empty()
    }

    pub fn clear(&mut self) {
        self.ticks.clear();
        self.times.clear();
        self.needed.clear();
        self.columns.iter_mut().for_each(Vec::clear);
    }
}

/// The rows of both, in step order, a step in both once: each value from the one that needs
/// it (a row keeps only the values it is needed for). Both are in step order.
fn merged(a: Kept, b: Kept, width: usize) -> Kept {
    if b.is_empty() {
        return a;
    }
    if a.is_empty() {
        return b;
    }
    let mut out = Kept::default();
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let sa = a.steps.get(i).copied().unwrap_or(u64::MAX);
        let sb = b.steps.get(j).copied().unwrap_or(u64::MAX);
        if sa == sb {
            let (na, nb) = (a.needed[i], b.needed[j]);
            let (ra, rb) = (row(&a, i, width), row(&b, j, width));
            let values: Vec<f64> = (0..width)
                .map(|q| if na & (1 << q) != 0 { ra[q] } else { rb[q] })
                .collect();
            out.push(sa, &values, na | nb);
            (i, j) = (i + 1, j + 1);
        } else if sa < sb {
            out.push(sa, row(&a, i, width), a.needed[i]);
            i += 1;
        } else {
            out.push(sb, row(&b, j, width), b.needed[j]);
            j += 1;
        }
    }
    out
}

/// Row `i` of `k`'s values.
fn row(k: &Kept, i: usize, width: usize) -> &[f64] {
    &k.values[i * width..(i + 1) * width]
}

/// Splits off the rows at steps ≥ `step`, keeping those before.
fn split_from(rows: &mut Kept, step: u64, width: usize) -> Kept {
    let at = rows.steps.partition_point(|&s| s < step);
    Kept {
        steps: rows.steps.split_off(at),
        values: rows.values.split_off(at * width),
        needed: rows.needed.split_off(at),
    }
}

/// [`SeriesBatch::needed`] of a row of a stretch whose every sampled step is kept: every
/// quantity needs it, and bit 63, which no M4 row has, says so.
pub const WHOLE: u64 = u64::MAX;

/// How the sampled rows of a run beyond [`super::MAX_PLOT_POINTS`] are kept; see [`LaneSeries`].
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesPlan {
    /// Sampled ticks whose rows are all kept: the first window and those asked for, each an
    /// inclusive range of ticks, in order.
    pub windows: Vec<(u64, u64)>,
    /// Sampled rows kept whole before a lane stops (at the end, a divergence or Ctrl-C).
    pub last_rows: usize,
}

/// A lane's sampled rows on their way to the observer.
///
/// A run that samples at most [`super::MAX_PLOT_POINTS`] ticks keeps every sampled row. A longer one
/// (`plan` given) keeps the rows of the M4 aggregate over [`m4::MAX_COLUMNS`] columns of the
/// whole run (so a plot up to that many pixels wide draws what every row would draw), every row
/// inside the plan's windows, and every row of the last window before the lane stopped — held
/// back in a ring, since only the stop says where that window is. Rows reach the batch in tick
/// order, each once: a closed column's rows wait until they are older than the ring.
pub struct LaneSeries {
    pub batch: SeriesBatch,
    /// Whether rows are kept at all (an observer that plots nothing wants none).
    wanted: bool,
    aggregate: Option<Aggregate>,
}

struct Aggregate {
    m4: M4,
    width: usize,
    windows: Vec<(u64, u64)>,
    /// The rows sampled since the last [`LaneSeries::settle`]: the M4 aggregate and the
    /// windows take them in a block, then they join `trailing`.
    staged: Vec<Sample>,
    /// Window rows not yet merged with their column's rows.
    in_windows: Kept,
    /// Rows of closed columns, merged, not yet older than the trailing rows.
    pending: Kept,
    /// The last blocks of sampled rows, at least `last_rows` rows once there are (whole blocks
    /// are kept, not copied row by row).
    trailing: VecDeque<Vec<Sample>>,
    last_rows: usize,
}

impl LaneSeries {
    /// `absent_when_zero`: per quantity, whether its zeros are no point of its plot
    /// ([`absent_when_zero`]).
    pub fn new(
        schedule: &Schedule,
        absent_when_zero: &[bool],
        plan: Option<&SeriesPlan>,
        wanted: bool,
    ) -> Self {
        let width = absent_when_zero.len();
        LaneSeries {
            batch: SeriesBatch::new(width),
            wanted,
            aggregate: plan.map(|plan| Aggregate {
                m4: M4::new(schedule.total, m4::MAX_COLUMNS, absent_when_zero)
                    .expect("a scene plots at most m4::MAX_VALUES quantities"),
                width,
                windows: plan.windows.clone(),
                staged: Vec::new(),
                in_windows: Kept::default(),
                pending: Kept::default(),
                trailing: VecDeque::new(),
                last_rows: plan.last_rows.max(1),
            }),
        }
    }

    #[inline]
    fn push(&mut self, schedule: &Schedule, step: u64, row: &[f64]) {
        if !self.wanted {
            return;
        }
        match &mut self.aggregate {
            None => push_row(&mut self.batch, schedule, step, row, WHOLE),
            Some(a) => a.staged.push((step, m4::row_of(row))),
        }
    }

    /// Moves the rows that are final into the batch (after each block).
    pub fn settle(&mut self, schedule: &Schedule) {
        let Some(a) = &mut self.aggregate else {
            return;
        };
        a.take_staged();
        let closed = a.m4.take_completed();
        if let Some(&last) = closed.steps.last() {
            let later = split_from(&mut a.in_windows, last + 1, a.width);
            let windows = std::mem::replace(&mut a.in_windows, later);
            let pending = std::mem::take(&mut a.pending);
            a.pending = merged(pending, merged(closed, windows, a.width), a.width);
        }
        let oldest_trailing = a
            .trailing
            .front()
            .and_then(|b| b.first())
            .map_or(u64::MAX, |r| r.0);
        let later = split_from(&mut a.pending, oldest_trailing, a.width);
        let done = std::mem::replace(&mut a.pending, later);
        push_rows(&mut self.batch, schedule, &done, a.width);
    }

    /// Moves every row still held into the batch: the lane has stopped.
    pub fn finish(&mut self, schedule: &Schedule) {
        let Some(mut a) = self.aggregate.take() else {
            return;
        };
        a.take_staged();
        let w = a.width;
        let held: usize = a.trailing.iter().map(Vec::len).sum();
        let mut last = Kept::default();
        for (step, row) in a
            .trailing
            .iter()
            .flatten()
            .skip(held.saturating_sub(a.last_rows))
        {
            last.push(*step, &row[..w], WHOLE);
        }
        let rest = merged(
            merged(a.pending, a.m4.finish(), w),
            merged(a.in_windows, last, w),
            w,
        );
        push_rows(&mut self.batch, schedule, &rest, w);
    }
}

impl Aggregate {
    /// Hands the staged rows to the M4 aggregate and the windows, and keeps them as the newest
    /// trailing block.
    fn take_staged(&mut self) {
        if self.staged.is_empty() {
            return;
        }
        let rows = &self.staged;
        self.m4.push_rows(rows);
        for &(from, to) in &self.windows {
            let start = rows.partition_point(|r| r.0 < from);
            let end = rows.partition_point(|r| r.0 <= to);
            for (step, row) in &rows[start..end] {
                self.in_windows.push(*step, &row[..self.width], WHOLE);
            }
        }
        // The oldest block goes once the others hold the last rows; its buffer is reused.
        let mut spare = Vec::new();
        let held: usize = self.trailing.iter().map(Vec::len).sum::<usize>() + rows.len();
        if let Some(oldest) = self.trailing.front()
            && held - oldest.len() >= self.last_rows
        {
            spare = self.trailing.pop_front().expect("a front block");
            spare.clear();
        }
        self.trailing
            .push_back(std::mem::replace(&mut self.staged, spare));
    }
}

fn push_row(batch: &mut SeriesBatch, schedule: &Schedule, step: u64, row: &[f64], needed: u64) {
    debug_assert_eq!(row.len(), batch.columns.len());
    batch.ticks.push(step);
    batch.times.push(schedule.time(step));
    batch.needed.push(needed);
    for (column, &v) in batch.columns.iter_mut().zip(row) {
        column.push(v);
    }
}

fn push_rows(batch: &mut SeriesBatch, schedule: &Schedule, rows: &Kept, width: usize) {
    for (i, &step) in rows.steps.iter().enumerate() {
        push_row(batch, schedule, step, row(rows, i, width), rows.needed[i]);
    }
}

/// Error-like quantities, plotted as log10 |value| under their own name so that methods ten
/// decades apart are all visible (a linear plot shows everything but the worst method as a flat
/// line at zero). Samples equal to zero (log10 = −∞: the reference against itself, the start)
/// are left out of the log series, so they are no point of its plot, and the aggregate treats
/// them so. (quantity, plotted entity name)
pub const LOG10: [(&str, &str); 4] = [
    ("theta_error", "log10_theta_error"),
    ("energy_error", "log10_energy_error"),
    ("energy_balance", "log10_energy_balance"),
    ("max_stretch", "log10_max_stretch"),
];

/// Whether a quantity's zeros are left out of its plot (it is plotted as log10 |value|).
pub fn absent_when_zero(quantity: &str) -> bool {
    LOG10.iter().any(|(q, _)| *q == quantity)
}

/// Where a scene's check puts the values it samples.
pub struct Sampler<'a> {
    pub(super) schedule: &'a Schedule,
    pub(super) series: &'a mut LaneSeries,
}

impl<'a> Sampler<'a> {
    pub fn new(schedule: &'a Schedule, series: &'a mut LaneSeries) -> Self {
        Sampler { schedule, series }
    }

    /// Whether the series are sampled at `tick`.
    #[inline]
    pub fn wants(&self, tick: u64) -> bool {
        self.series.wanted && self.schedule.samples(tick)
    }

    /// Records one row: a value per quantity, in [`Scene::quantities`] order.
    #[inline]
    pub fn push(&mut self, tick: u64, values: &[f64]) {
        self.series.push(self.schedule, tick, values);
    }
}
