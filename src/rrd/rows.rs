//! A recording's data read back value by value: every component of every entity on the
//! `sim_time` timeline (static data has no time), a chunk's rows held as the chunk holds them
//! and each row's values read in place from the chunk's arrays ([`RowView`]), never copied out.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::Path;
use std::rc::Rc;

use rerun::external::arrow::array::{
    Array, ArrayRef, AsArray as _, GenericListArray, ListArray, OffsetSizeTrait,
};
use rerun::external::arrow::buffer::ScalarBuffer;
use rerun::external::arrow::datatypes::{
    DataType, Float32Type, Float64Type, Int8Type, Int16Type, Int32Type, Int64Type, UInt8Type,
    UInt16Type, UInt32Type, UInt64Type,
};

use super::read::{ChunkMessage, each_chunk};

/// One logged row of one component: its `sim_time` in ns (`None` for static data), every number
/// it holds (floats widened to f64 exactly, integers converted), and every text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoggedRow {
    pub time: Option<i64>,
    pub nums: Vec<f64>,
    pub texts: Vec<String>,
}

/// An (entity path, component) pair: one series.
pub type Key = (String, String);

/// Each series' rows, in time order (rows at the same time in logging order).
pub type Contents = BTreeMap<Key, Vec<LoggedRow>>;

/// One component's rows in one chunk, sharing the chunk's list array and `sim_time` column (a
/// row is read in place, [`SeriesRows::view`]); null rows are skipped.
#[derive(Clone)]
pub(super) struct SeriesRows {
    pub(super) list: ListArray,
    /// `None` for static data.
    pub(super) times: Option<ScalarBuffer<i64>>,
    /// The next row to take, and the end of the rows (the chunk's row count).
    pub(super) next: usize,
    pub(super) end: usize,
    /// Its message's bytes, counted while any of its rows wait (see [`Held`]).
    pub(super) held: Option<Rc<Held>>,
}

/// A message's decompressed bytes, counted in a shared total while any of its rows are held:
/// the count drops when the last of them is.
pub(super) struct Held {
    bytes: usize,
    total: Rc<Cell<usize>>,
}

impl Held {
    pub(super) fn new(bytes: usize, total: &Rc<Cell<usize>>) -> Rc<Self> {
        total.set(total.get() + bytes);
        let total = total.clone();
        Rc::new(Held { bytes, total })
    }
}

impl Drop for Held {
    fn drop(&mut self) {
        self.total.set(self.total.get() - self.bytes);
    }
}

impl SeriesRows {
    pub(super) fn new(list: ListArray, times: Option<ScalarBuffer<i64>>, end: usize) -> Self {
        let mut rows = SeriesRows {
            end: end.min(list.len()),
            list,
            times,
            next: 0,
            held: None,
        };
        rows.skip_nulls();
        rows
    }

    pub(super) fn skip_nulls(&mut self) {
        let next = self.left().next();
        self.next = next.unwrap_or(self.end);
    }

    /// The indices of the rows left (null rows skipped).
    fn left(&self) -> impl Iterator<Item = usize> + '_ {
        (self.next..self.end).filter(|&i| !self.list.is_null(i))
    }

    pub(super) fn is_empty(&self) -> bool {
        self.next >= self.end
    }

    /// The rows left.
    pub(super) fn len(&self) -> usize {
        self.left().count()
    }

    /// Keeps at most `n` of the rows left.
    pub(super) fn truncate(&mut self, n: usize) {
        let end = self.left().nth(n);
        self.end = end.unwrap_or(self.end);
    }

    pub(super) fn time(&self) -> Option<i64> {
        self.times.as_ref().and_then(|t| t.get(self.next).copied())
    }

    /// The next row, its values in place in the chunk's arrays.
    pub(super) fn view(&self) -> RowView {
        RowView::new(self.time(), &self.list.value(self.next))
    }

    pub(super) fn advance(&mut self) {
        self.next += 1;
        self.skip_nulls();
    }

    /// Every row left, each its own [`LoggedRow`].
    pub(super) fn into_rows(mut self) -> Vec<LoggedRow> {
        let mut out = Vec::new();
        while !self.is_empty() {
            let view = self.view();
            out.push(LoggedRow {
                time: view.time,
                nums: view.nums().collect(),
                texts: view.texts,
            });
            self.advance();
        }
        out
    }
}

/// One message's series in logging order: every component of every entity of a recording
/// chunk (not the properties, not the blueprint), sharing the chunk's arrays.
pub(super) fn message_series(msg: ChunkMessage) -> Vec<(Key, SeriesRows)> {
    if !msg.recording {
        return Vec::new();
    }
    let chunk = msg.chunk;
    let entity = chunk.entity_path().to_string();
    if entity.starts_with("/__properties") {
        return Vec::new();
    }
    let sim_time = rerun::TimelineName::from("sim_time");
    let times = chunk
        .timelines()
        .get(&sim_time)
        .map(|c| c.times_buffer().clone());
    let rows = |d: &rerun::ComponentDescriptor| {
        let list = chunk.components().get_array(d.component)?;
        let rows = SeriesRows::new(list.clone(), times.clone(), chunk.num_rows());
        Some(((entity.clone(), d.component.as_str().to_string()), rows))
    };
    chunk.component_descriptors().filter_map(rows).collect()
}

/// Every component of every entity (not the properties, not the blueprint), the whole file in
/// memory: for tests (`diff` and `reproduce` stream); errors as [`each_chunk`]'s.
pub fn read_contents(path: &Path) -> anyhow::Result<Contents> {
    let mut contents = Contents::new();
    each_chunk(path, |msg| {
        for (key, rows) in message_series(msg) {
            contents.entry(key).or_default().extend(rows.into_rows());
        }
        Ok(())
    })?;
    for rows in contents.values_mut() {
        rows.sort_by_key(|r| r.time); // stable: same-time rows keep their logging order
    }
    Ok(contents)
}

/// What one pass over a recording learns of each series, in memory that grows with the number
/// of series only.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesIndex {
    /// Rows on `sim_time`, and static rows.
    pub timed: usize,
    pub statics: usize,
    /// The largest finite |value| of the timed rows, and of the static ones: the scales
    /// tolerances are relative to.
    pub scale: f64,
    pub static_scale: f64,
}

/// Every series of a recording with its row counts and scale, read a row at a time.
pub fn index_series(path: &Path) -> anyhow::Result<BTreeMap<Key, SeriesIndex>> {
    let mut index: BTreeMap<Key, SeriesIndex> = BTreeMap::new();
    each_chunk(path, |msg| {
        for (key, mut rows) in message_series(msg) {
            let entry = index.entry(key).or_default();
            let (count, scale) = if rows.times.is_some() {
                (&mut entry.timed, &mut entry.scale)
            } else {
                (&mut entry.statics, &mut entry.static_scale)
            };
            while !rows.is_empty() {
                *count += 1;
                for v in rows.view().nums().filter(|v| v.is_finite()) {
                    *scale = scale.max(v.abs());
                }
                rows.advance();
            }
        }
        Ok(())
    })?;
    Ok(index)
}

/// One row's numbers as the arrays that hold them, read in place depth first (lists element by
/// element, structs column by column; floats widened to f64 exactly, integers converted, a null
/// read as NaN, a boolean as 0 or 1, a byte string byte by byte), and its texts.
pub struct RowView {
    time: Option<i64>,
    leaves: Vec<ArrayRef>,
    texts: Vec<String>,
}

impl RowView {
    pub(super) fn new(time: Option<i64>, row: &ArrayRef) -> Self {
        let mut view = RowView {
            time,
            leaves: Vec::new(),
            texts: Vec::new(),
        };
        view.add(row);
        view
    }

    pub fn time(&self) -> Option<i64> {
        self.time
    }

    /// How many numbers the row holds.
    pub fn count(&self) -> usize {
        self.nums().count()
    }

    /// The row's numbers in order.
    pub fn nums(&self) -> impl Iterator<Item = f64> + '_ {
        self.leaves.iter().flat_map(|a| leaf_values(a.as_ref()))
    }

    pub fn texts(&self) -> &[String] {
        &self.texts
    }

    /// Adds `a`'s numeric arrays as leaves, its texts as texts.
    fn add(&mut self, a: &ArrayRef) {
        match a.data_type() {
            DataType::Null => {}
            // What `leaf_values` reads.
            t if t.is_integer() || matches!(t, DataType::Float32 | DataType::Float64) => {
                self.leaves.push(a.clone())
            }
            DataType::Boolean | DataType::Binary => self.leaves.push(a.clone()),
            DataType::Utf8 => {
                let s = a.as_string::<i32>();
                self.texts
                    .extend((0..s.len()).map(|i| s.value(i).to_string()));
            }
            DataType::LargeUtf8 => {
                let s = a.as_string::<i64>();
                self.texts
                    .extend((0..s.len()).map(|i| s.value(i).to_string()));
            }
            DataType::List(_) => self.add_list(a.as_list::<i32>()),
            DataType::LargeList(_) => self.add_list(a.as_list::<i64>()),
            DataType::FixedSizeList(..) => {
                let l = a.as_fixed_size_list();
                if l.null_count() == 0 {
                    let size = l.value_length() as usize;
                    self.add(&l.values().slice(0, l.len() * size));
                } else {
                    for i in (0..l.len()).filter(|&i| !l.is_null(i)) {
                        self.add(&l.value(i));
                    }
                }
            }
            DataType::Struct(_) => {
                for column in a.as_struct().columns() {
                    self.add(column);
                }
            }
            _ => self.texts.push(format!("{a:?}")),
        }
    }

    /// A list's elements: without nulls, its values array, which holds them in order (as for a
    /// fixed-size list).
    fn add_list<O: OffsetSizeTrait>(&mut self, l: &GenericListArray<O>) {
        if l.null_count() == 0 {
            let o = l.value_offsets();
            let (start, end) = (o[0].as_usize(), o[l.len()].as_usize());
            self.add(&l.values().slice(start, end - start));
        } else {
            for i in (0..l.len()).filter(|&i| !l.is_null(i)) {
                self.add(&l.value(i));
            }
        }
    }
}

/// A leaf array's numbers in order.
fn leaf_values(a: &dyn Array) -> Box<dyn Iterator<Item = f64> + '_> {
    macro_rules! numbers {
        ($t:ty) => {{
            let p = a.as_primitive::<$t>();
            Box::new((0..p.len()).map(move |i| {
                if p.is_null(i) {
                    f64::NAN
                } else {
                    p.value(i) as f64
                }
            }))
        }};
    }
    match a.data_type() {
        DataType::Float64 => numbers!(Float64Type),
        DataType::Float32 => numbers!(Float32Type),
        DataType::Int8 => numbers!(Int8Type),
        DataType::Int16 => numbers!(Int16Type),
        DataType::Int32 => numbers!(Int32Type),
        DataType::Int64 => numbers!(Int64Type),
        DataType::UInt8 => numbers!(UInt8Type),
        DataType::UInt16 => numbers!(UInt16Type),
        DataType::UInt32 => numbers!(UInt32Type),
        DataType::UInt64 => numbers!(UInt64Type),
        DataType::Boolean => {
            let b = a.as_boolean();
            Box::new((0..b.len()).map(|i| f64::from(u8::from(b.value(i)))))
        }
        DataType::Binary => {
            let b = a.as_binary::<i32>();
            Box::new((0..b.len()).flat_map(move |i| b.value(i).iter().map(|&x| f64::from(x))))
        }
        _ => Box::new(std::iter::empty()),
    }
}
