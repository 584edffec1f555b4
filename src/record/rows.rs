//! A recording's data read back value by value: every component of every entity on the
//! `sim_time` timeline (static data has no time), with Rerun's own decoder, a chunk's rows held
//! as the chunk holds them and flattened one at a time.

use std::collections::BTreeMap;
use std::path::Path;

use rerun::external::arrow::array::{Array, AsArray as _, ListArray};
use rerun::external::arrow::buffer::ScalarBuffer;
use rerun::external::arrow::datatypes::{
    DataType, Float32Type, Float64Type, Int8Type, Int16Type, Int32Type, Int64Type, UInt8Type,
    UInt16Type, UInt32Type, UInt64Type,
};
use rerun::log::{Chunk, LogMsg};

use super::read::each_message;

/// One logged row of one component: its `sim_time` in ns (`None` for static data), every number
/// it holds (floats widened to f64 exactly, integers converted), and every text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoggedRow {
    pub time: Option<i64>,
    pub nums: Vec<f64>,
    pub texts: Vec<String>,
}

/// (entity path, component) → rows, in time order (rows at the same time in logging order).
pub type Contents = BTreeMap<(String, String), Vec<LoggedRow>>;

/// An (entity path, component) pair: one series.
pub type Key = (String, String);

/// One component's rows in one chunk, as the chunk holds them: its list array and `sim_time`
/// column are shared with the decoded chunk, not copied, and a row is flattened only when it is
/// read ([`SeriesRows::row`]). Null rows are skipped.
#[derive(Clone)]
pub(super) struct SeriesRows {
    pub(super) list: ListArray,
    /// `None` for static data.
    pub(super) times: Option<ScalarBuffer<i64>>,
    /// The next row to take, and the end of the rows (the chunk's row count).
    pub(super) next: usize,
    pub(super) end: usize,
}

impl SeriesRows {
    pub(super) fn new(list: ListArray, times: Option<ScalarBuffer<i64>>, end: usize) -> Self {
        let mut rows = SeriesRows {
            end: end.min(list.len()),
            list,
            times,
            next: 0,
        };
        rows.skip_nulls();
        rows
    }

    pub(super) fn skip_nulls(&mut self) {
        while self.next < self.end && self.list.is_null(self.next) {
            self.next += 1;
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.next >= self.end
    }

    /// The rows left.
    pub(super) fn len(&self) -> usize {
        (self.next..self.end)
            .filter(|&i| !self.list.is_null(i))
            .count()
    }

    /// Keeps at most `n` of the rows left.
    pub(super) fn truncate(&mut self, n: usize) {
        let mut kept = 0;
        let mut i = self.next;
        while i < self.end && kept < n {
            if !self.list.is_null(i) {
                kept += 1;
            }
            i += 1;
        }
        self.end = i;
    }

    pub(super) fn time(&self) -> Option<i64> {
        self.times.as_ref().and_then(|t| t.get(self.next).copied())
    }

    /// The next row, written into `out` (its buffers reused).
    pub(super) fn row(&self, out: &mut LoggedRow) {
        out.time = self.time();
        out.nums.clear();
        out.texts.clear();
        flatten(
            self.list.value(self.next).as_ref(),
            &mut out.nums,
            &mut out.texts,
        );
    }

    pub(super) fn advance(&mut self) {
        self.next += 1;
        self.skip_nulls();
    }

    /// Every row left, each its own [`LoggedRow`].
    pub(super) fn into_rows(mut self) -> Vec<LoggedRow> {
        let mut out = Vec::new();
        while !self.is_empty() {
            let mut row = LoggedRow::default();
            self.row(&mut row);
            out.push(row);
            self.advance();
        }
        out
    }
}

/// One message's series in logging order: every component of every entity of a recording
/// chunk (not the properties, not the blueprint), sharing the chunk's arrays. `Err` says what is
/// wrong.
pub(super) fn message_series(msg: LogMsg) -> Result<Vec<(Key, SeriesRows)>, String> {
    let LogMsg::ArrowMsg(store_id, arrow_msg) = msg else {
        return Ok(Vec::new());
    };
    if !store_id.is_recording() {
        return Ok(Vec::new());
    }
    let chunk =
        Chunk::from_arrow_msg(&arrow_msg).map_err(|e| format!("a chunk cannot be decoded: {e}"))?;
    let entity = chunk.entity_path().to_string();
    if entity.starts_with("/__properties") {
        return Ok(Vec::new());
    }
    let sim_time = rerun::TimelineName::from("sim_time");
    let times = chunk
        .timelines()
        .get(&sim_time)
        .map(|c| c.times_buffer().clone());
    let mut out = Vec::new();
    for descriptor in chunk.component_descriptors() {
        let Some(list) = chunk.components().get_array(descriptor.component) else {
            continue;
        };
        let rows = SeriesRows::new(list.clone(), times.clone(), chunk.num_rows());
        out.push((
            (entity.clone(), descriptor.component.as_str().to_string()),
            rows,
        ));
    }
    Ok(out)
}

/// Reads every component of every entity (not the properties, not the blueprint), the whole
/// file into memory: for small recordings and tests; `diff` and `reproduce` stream instead
/// ([`compare_files`]). An unusable file is a usage error naming it, a stop request
/// `Error::Interrupted` (see [`each_message`]).
pub fn read_contents(path: &Path) -> anyhow::Result<Contents> {
    let mut contents = Contents::new();
    each_message(path, |msg| {
        for (key, rows) in message_series(msg)? {
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

/// Every series of a recording with its row counts and scale, read message by message, a row
/// at a time.
pub fn index_series(path: &Path) -> anyhow::Result<BTreeMap<Key, SeriesIndex>> {
    let mut index: BTreeMap<Key, SeriesIndex> = BTreeMap::new();
    let mut row = LoggedRow::default();
    each_message(path, |msg| {
        for (key, mut rows) in message_series(msg)? {
            let entry = index.entry(key).or_default();
            let (count, scale) = if rows.times.is_some() {
                (&mut entry.timed, &mut entry.scale)
            } else {
                (&mut entry.statics, &mut entry.static_scale)
            };
            while !rows.is_empty() {
                rows.row(&mut row);
                *count += 1;
                for v in row.nums.iter().filter(|v| v.is_finite()) {
                    *scale = scale.max(v.abs());
                }
                rows.advance();
            }
        }
        Ok(())
    })?;
    Ok(index)
}

/// Every number and text an arrow array holds, depth first.
pub(super) fn flatten(a: &dyn Array, nums: &mut Vec<f64>, texts: &mut Vec<String>) {
    macro_rules! numbers {
        ($t:ty) => {{
            let p = a.as_primitive::<$t>();
            for i in 0..p.len() {
                nums.push(if p.is_null(i) {
                    f64::NAN
                } else {
                    p.value(i) as f64
                });
            }
        }};
    }
    match a.data_type() {
        DataType::Null => {}
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
            nums.extend((0..b.len()).map(|i| f64::from(u8::from(b.value(i)))));
        }
        DataType::Utf8 => {
            let s = a.as_string::<i32>();
            texts.extend((0..s.len()).map(|i| s.value(i).to_string()));
        }
        DataType::LargeUtf8 => {
            let s = a.as_string::<i64>();
            texts.extend((0..s.len()).map(|i| s.value(i).to_string()));
        }
        DataType::List(_) => {
            let l = a.as_list::<i32>();
            for i in (0..l.len()).filter(|&i| !l.is_null(i)) {
                flatten(l.value(i).as_ref(), nums, texts);
            }
        }
        DataType::LargeList(_) => {
            let l = a.as_list::<i64>();
            for i in (0..l.len()).filter(|&i| !l.is_null(i)) {
                flatten(l.value(i).as_ref(), nums, texts);
            }
        }
        DataType::FixedSizeList(..) => {
            let l = a.as_fixed_size_list();
            for i in (0..l.len()).filter(|&i| !l.is_null(i)) {
                flatten(l.value(i).as_ref(), nums, texts);
            }
        }
        DataType::Struct(_) => {
            for column in a.as_struct().columns() {
                flatten(column.as_ref(), nums, texts);
            }
        }
        DataType::Binary => {
            let b = a.as_binary::<i32>();
            for i in 0..b.len() {
                nums.extend(b.value(i).iter().map(|&x| f64::from(x)));
            }
        }
        _ => texts.push(format!("{a:?}")),
    }
}
