//! The comparison of two recordings series by series, read in step, and of two series: what
//! `physlab reproduce` and `physlab diff` report.

use std::cell::Cell;
use std::collections::{BTreeMap, VecDeque};
use std::path::Path;
use std::rc::Rc;

use super::read::{Messages, unusable};
pub use super::rows::RowView;
pub use super::rows::{Contents, Key, LoggedRow, SeriesIndex, index_series, read_contents};
use super::rows::{Held, SeriesRows, message_series};

/// The most bytes of chunks `compare_files` holds while their rows wait for partners (1 GiB):
/// two recordings of the same run hold about a chunk per series; two whose series come in
/// different orders would hold up to both files, and are refused past this.
const MAX_WAITING_BYTES: usize = 1 << 30;

/// How two recordings are read against each other by [`compare_files`].
pub struct StreamSpec<'a> {
    /// A fraction of each series' scale (0: bit for bit).
    pub tolerance: f64,
    /// Entities left out of the comparison (wall-clock timings).
    pub skip: &'a dyn Fn(&str) -> bool,
    /// B's entity path parts renamed (from, to): one method's lanes paired with another's.
    pub rename_b: Option<(String, String)>,
    /// B's timed rows compared only as far as A's go, series by series (A cut short).
    pub cap_b: bool,
}

/// What [`compare_files`] found: per series, the timed rows' comparison and the static rows'.
#[derive(Debug, Default)]
pub struct Streamed {
    pub index_a: BTreeMap<Key, SeriesIndex>,
    pub index_b: BTreeMap<Key, SeriesIndex>,
    pub timed: BTreeMap<Key, SeriesDiff>,
    pub statics: BTreeMap<Key, SeriesDiff>,
}

/// One kind of rows of one series (timed or static) being compared: the rows waiting for their
/// partner on the other side, as blocks of the chunks they came in, and the comparison so far,
/// each value judged against the tolerance × the series' scale (with tolerance 0: its bits).
struct Queues {
    qa: VecDeque<SeriesRows>,
    qb: VecDeque<SeriesRows>,
    out: SeriesDiff,
    tolerance: f64,
    bound: f64,
    /// Whether both files have such rows: if not, every row is unpaired and none waits.
    shared: bool,
}

impl Queues {
    fn new(tolerance: f64, scale: f64, shared: bool) -> Self {
        Queues {
            qa: VecDeque::new(),
            qb: VecDeque::new(),
            out: SeriesDiff {
                scale,
                ..SeriesDiff::default()
            },
            tolerance,
            bound: tolerance * scale,
            shared,
        }
    }

    /// Takes one side's rows: counted, queued while they wait for a partner, and paired as far
    /// as both sides go (timed pairs handed to `on_pair`). Returns the rows the queues hold
    /// now, minus before, per side.
    fn take(
        &mut self,
        from_a: bool,
        rows: SeriesRows,
        on_pair: &mut Pairs,
    ) -> anyhow::Result<(isize, isize)> {
        let n = rows.len();
        if from_a {
            self.out.rows_a += n;
        } else {
            self.out.rows_b += n;
        }
        if !self.shared {
            self.out.unpaired += n;
            return Ok((0, 0));
        }
        let before = (queued_rows(&self.qa), queued_rows(&self.qb));
        if n > 0 {
            if from_a { &mut self.qa } else { &mut self.qb }.push_back(rows);
        }
        self.merge(on_pair)?;
        // A drained queue gives its room back: hundreds of series each keeping a queue's room
        // would hold more than the rows ever waiting at once.
        for queue in [&mut self.qa, &mut self.qb] {
            if queue.is_empty() {
                *queue = VecDeque::new();
            }
        }
        Ok((
            queued_rows(&self.qa) as isize - before.0 as isize,
            queued_rows(&self.qb) as isize - before.1 as isize,
        ))
    }

    /// The comparison, with the rows still waiting counted as unpaired.
    fn finish(mut self) -> SeriesDiff {
        self.out.unpaired += queued_rows(&self.qa) + queued_rows(&self.qb);
        self.out
    }

    /// Pairs the two sides' rows by time from the front, as far as both go: a row whose time
    /// the other side has passed has no partner. Rows are in time order on each side. Each row
    /// is read in place.
    fn merge(&mut self, on_pair: &mut Pairs) -> anyhow::Result<()> {
        while let (Some(ra), Some(rb)) = (self.qa.front(), self.qb.front()) {
            let (ta, tb) = (ra.time(), rb.time());
            if ta == tb {
                let (ra, rb) = (ra.view(), rb.view());
                self.pair(&ra, &rb);
                on_pair(&ra, &rb)?;
                advance(&mut self.qa);
                advance(&mut self.qb);
            } else {
                self.out.unpaired += 1;
                advance(if ta < tb { &mut self.qa } else { &mut self.qb });
            }
        }
        Ok(())
    }

    fn pair(&mut self, ra: &RowView, rb: &RowView) {
        let out = &mut self.out;
        out.paired += 1;
        let (na, nb) = (ra.count(), rb.count());
        if (ra.texts() != rb.texts() || na != nb) && out.first_other.is_none() {
            let what = if ra.texts() != rb.texts() {
                format!(
                    "text {:?} vs {:?}",
                    ra.texts().join(" "),
                    rb.texts().join(" ")
                )
            } else {
                format!("{na} values vs {nb}")
            };
            out.first_other = Some((ra.time(), what));
        }
        for (index, (x, y)) in ra.nums().zip(rb.nums()).enumerate() {
            let d = Difference {
                time: ra.time(),
                index,
                a: x,
                b: y,
            };
            let size = d.abs();
            let beyond = if self.tolerance == 0.0 {
                x.to_bits() != y.to_bits()
            } else {
                size.is_nan() || size > self.bound // NaN against a number is beyond any bound
            };
            if beyond && out.first.is_none() {
                out.first = Some(d.clone());
            }
            let bigger = match &out.largest {
                None => true,
                Some(l) => size > l.abs() || (size.is_nan() && !l.abs().is_nan()),
            };
            if bigger {
                out.largest = Some(d);
            }
        }
    }
}

/// One series being compared.
struct ComparedSeries {
    timed: Queues,
    statics: Queues,
    /// B's timed rows taken so far, and how many may be (A's count, when capped).
    taken_b: usize,
    cap_b: Option<usize>,
}

/// `entity` with its path part `from` renamed `to` (B's lanes paired with A's), if asked.
pub fn renamed(entity: &str, rename: &Option<(String, String)>) -> String {
    match rename {
        Some((from, to)) => entity
            .split('/')
            .map(|part| if part == from { to.as_str() } else { part })
            .collect::<Vec<_>>()
            .join("/"),
        None => entity.to_string(),
    }
}

/// Compares two recordings series by series while reading them in step, so that memory holds
/// what one has read ahead of the other (about a chunk per series when they were logged in the
/// same order), never a whole file. Each timed pair of rows is also handed to `on_pair`.
/// Rows of one series must come in time order within each file, as physlab logs them.
pub fn compare_files(
    a: &Path,
    b: &Path,
    spec: &StreamSpec,
    on_pair: &mut KeyedPairs,
) -> anyhow::Result<Streamed> {
    compare_within(a, b, spec, on_pair, MAX_WAITING_BYTES)
}

/// [`compare_files`], refusing the files once more than `max_waiting` bytes of chunks wait.
pub(super) fn compare_within(
    a: &Path,
    b: &Path,
    spec: &StreamSpec,
    on_pair: &mut KeyedPairs,
    max_waiting: usize,
) -> anyhow::Result<Streamed> {
    let rename = |key: Key| -> Key { (renamed(&key.0, &spec.rename_b), key.1) };
    let index_a = index_series(a)?;
    let index_b: BTreeMap<Key, SeriesIndex> = index_series(b)?
        .into_iter()
        .map(|(k, v)| (rename(k), v))
        .collect();
    let mut lanes = compared_series(&index_a, &index_b, spec);
    let (mut ma, mut mb) = (Messages::open(a)?, Messages::open(b)?);
    let waiting = Rc::new(Cell::new(0));
    let (mut done_a, mut done_b) = (false, false);
    // Rows waiting in the queues, per side: read from the side that is behind.
    let (mut queued_a, mut queued_b) = (0usize, 0usize);
    while !(done_a && done_b) {
        let from_a = !done_a && (done_b || queued_a <= queued_b);
        let (messages, done) = if from_a {
            (&mut ma, &mut done_a)
        } else {
            (&mut mb, &mut done_b)
        };
        let Some(msg) = messages.next_chunk()? else {
            *done = true;
            continue;
        };
        let held = Held::new(msg.bytes, &waiting);
        let series = messages.guarded(|| message_series(msg))?;
        for (key, mut rows) in series {
            rows.held = Some(held.clone());
            let key = if from_a { key } else { rename(key) };
            let Some(lane) = lanes.get_mut(&key) else {
                continue; // skipped
            };
            let (queues, pairs): (_, &mut Pairs) = if rows.times.is_none() {
                (&mut lane.statics, &mut |_, _| Ok(()))
            } else {
                if !from_a {
                    if let Some(cap) = lane.cap_b {
                        rows.truncate(cap.saturating_sub(lane.taken_b));
                    }
                    lane.taken_b += rows.len();
                }
                (&mut lane.timed, &mut |ra, rb| on_pair(&key, ra, rb))
            };
            let (da, db) = queues.take(from_a, rows, pairs)?;
            queued_a = queued_a.saturating_add_signed(da);
            queued_b = queued_b.saturating_add_signed(db);
        }
        drop(held);
        if waiting.get() > max_waiting {
            let (this, other) = if from_a { (a, b) } else { (b, a) };
            let why = format!(
                "read against {}, its series come in so different an order that comparing them \
                 would hold more than {max_waiting} bytes of chunks waiting for their partners",
                other.display()
            );
            return Err(unusable(this, why));
        }
    }
    Ok(streamed(index_a, index_b, lanes))
}

/// Each series of either file (but those skipped), set to be compared.
fn compared_series(
    index_a: &BTreeMap<Key, SeriesIndex>,
    index_b: &BTreeMap<Key, SeriesIndex>,
    spec: &StreamSpec,
) -> BTreeMap<Key, ComparedSeries> {
    let mut lanes: BTreeMap<Key, ComparedSeries> = BTreeMap::new();
    for key in index_a.keys().chain(index_b.keys()) {
        if (spec.skip)(&key.0) || lanes.contains_key(key) {
            continue;
        }
        let (ia, ib) = (index_a.get(key), index_b.get(key));
        // One kind of rows: its scale (A's, or B's where A's is 0) and whether both have any.
        let queues = |rows: fn(&SeriesIndex) -> usize, scale: fn(&SeriesIndex) -> f64| {
            let scale = match ia.map_or(0.0, scale) {
                0.0 => ib.map_or(0.0, scale),
                s => s,
            };
            let shared = ia.map_or(0, rows) > 0 && ib.map_or(0, rows) > 0;
            Queues::new(spec.tolerance, scale, shared)
        };
        lanes.insert(
            key.clone(),
            ComparedSeries {
                timed: queues(|i| i.timed, |i| i.scale),
                statics: queues(|i| i.statics, |i| i.static_scale),
                taken_b: 0,
                cap_b: spec.cap_b.then(|| ia.map_or(0, |i| i.timed)),
            },
        );
    }
    lanes
}

/// What the comparison found, per series.
fn streamed(
    index_a: BTreeMap<Key, SeriesIndex>,
    index_b: BTreeMap<Key, SeriesIndex>,
    lanes: BTreeMap<Key, ComparedSeries>,
) -> Streamed {
    let mut out = Streamed {
        index_a,
        index_b,
        ..Streamed::default()
    };
    for (key, lane) in lanes {
        let (timed, statics) = (lane.timed.finish(), lane.statics.finish());
        if statics.rows_a > 0 || statics.rows_b > 0 {
            out.statics.insert(key.clone(), statics);
        }
        if timed.rows_a > 0 || timed.rows_b > 0 {
            out.timed.insert(key, timed);
        }
    }
    out
}

/// What is done with each pair of rows at the same time.
pub type Pairs<'a> = dyn FnMut(&RowView, &RowView) -> anyhow::Result<()> + 'a;
/// The same, told the series.
pub type KeyedPairs<'a> = dyn FnMut(&Key, &RowView, &RowView) -> anyhow::Result<()> + 'a;

/// Moves a queue (blocks of a chunk's rows, in time order) past its next row.
fn advance(queue: &mut VecDeque<SeriesRows>) {
    if let Some(rows) = queue.front_mut() {
        rows.advance();
        if rows.is_empty() {
            queue.pop_front();
        }
    }
}

/// The rows waiting in a queue.
fn queued_rows(queue: &VecDeque<SeriesRows>) -> usize {
    queue.iter().map(SeriesRows::len).sum()
}

/// How two series of the same entity and component compare.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesDiff {
    pub rows_a: usize,
    pub rows_b: usize,
    /// Rows paired by time (equal `sim_time`, in order within a time).
    pub paired: usize,
    /// Times that only one of them holds .
    pub unpaired: usize,
    /// The largest finite |a| in A's series (|b| in B's if A's are all zero): the scale
    /// tolerances are relative to.
    pub scale: f64,
    /// The first paired row that differs beyond the tolerance: its time and the first value
    /// there (A's, B's) that does.
    pub first: Option<Difference>,
    /// The largest |b − a| over all paired values, where.
    pub largest: Option<Difference>,
    /// The first row whose texts or number of values differ (a change of shape, not of value).
    pub first_other: Option<(Option<i64>, String)>,
}

/// One value in both series, where it differs.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    pub time: Option<i64>,
    /// Which of the row's values (a point's coordinate: index / 3 is the point, index % 3 the
    /// axis).
    pub index: usize,
    pub a: f64,
    pub b: f64,
}

impl Difference {
    pub fn abs(&self) -> f64 {
        if self.a.to_bits() == self.b.to_bits() {
            0.0
        } else {
            (self.b - self.a).abs()
        }
    }
}

impl SeriesDiff {
    /// Nothing differs (beyond the tolerance) and every row has its partner.
    pub fn same(&self) -> bool {
        self.first.is_none()
            && self.first_other.is_none()
            && self.unpaired == 0
            && self.rows_a == self.rows_b
    }

    /// Whether every paired value is bit-identical.
    pub fn bit_identical(&self) -> bool {
        self.same() && self.largest.as_ref().is_none_or(|d| d.abs() == 0.0)
    }

    /// The first time where anything differs (values beyond tolerance, texts or shape).
    pub fn first_time(&self) -> Option<Option<i64>> {
        let a = self.first.as_ref().map(|d| d.time);
        a.into_iter()
            .chain(self.first_other.as_ref().map(|d| d.0))
            .min()
    }
}

/// A time on `sim_time` in seconds, exactly as stored (ns), or "static".
pub fn time_text(t: Option<i64>) -> String {
    match t {
        Some(ns) => {
            let sign = if ns < 0 { "-" } else { "" };
            let ns = ns.unsigned_abs();
            let fraction = format!("{:09}", ns % 1_000_000_000);
            let fraction = fraction.trim_end_matches('0');
            let dot = if fraction.is_empty() { "" } else { "." };
            format!("t = {sign}{}{dot}{fraction} s", ns / 1_000_000_000)
        }
        None => "static".to_string(),
    }
}
