//! A recording's data read back value by value, and the comparison of two series: what
//! `physlab reproduce` and `physlab diff` report. Every component of every entity is read, on
//! the `sim_time` timeline (static data has no time), with Rerun's own decoder.

use std::collections::BTreeMap;
use std::path::Path;

use rerun::external::arrow::array::{Array, AsArray as _};
use rerun::external::arrow::datatypes::{
    DataType, Float32Type, Float64Type, Int8Type, Int16Type, Int32Type, Int64Type, UInt8Type,
    UInt16Type, UInt32Type, UInt64Type,
};
use rerun::external::re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

use crate::error::Error;

/// One logged row of one component: its `sim_time` in ns (`None` for static data), every number
/// it holds (floats widened to f64 exactly, integers converted), and every text.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub time: Option<i64>,
    pub nums: Vec<f64>,
    pub texts: Vec<String>,
}

/// (entity path, component) → rows, in time order (rows at the same time in logging order).
pub type Contents = BTreeMap<(String, String), Vec<Row>>;

/// Reads every component of every entity (not the properties, not the blueprint).
pub fn read_contents(path: &Path) -> Result<Contents, Error> {
    let fail = |what: String| Error::Usage(format!("{}: {what}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| fail(format!("cannot open it: {e}")))?;
    let sim_time = rerun::TimelineName::from("sim_time");
    let mut contents = Contents::new();
    for msg in DecoderApp::decode_lazy(std::io::BufReader::new(file)) {
        let msg = msg.map_err(|e| fail(format!("the recording is corrupt or truncated: {e}")))?;
        let LogMsg::ArrowMsg(store_id, arrow_msg) = msg else {
            continue;
        };
        if !store_id.is_recording() {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(&arrow_msg)
            .map_err(|e| fail(format!("a chunk cannot be decoded: {e}")))?;
        let entity = chunk.entity_path().to_string();
        if entity.starts_with("/__properties") {
            continue;
        }
        let times = chunk.timelines().get(&sim_time).map(|c| c.times_raw());
        for descriptor in chunk.component_descriptors() {
            let Some(list) = chunk.components().get_array(descriptor.component) else {
                continue;
            };
            let rows = contents
                .entry((entity.clone(), descriptor.component.as_str().to_string()))
                .or_default();
            for i in 0..chunk.num_rows() {
                if list.is_null(i) {
                    continue;
                }
                let mut row = Row {
                    time: times.and_then(|t| t.get(i).copied()),
                    nums: Vec::new(),
                    texts: Vec::new(),
                };
                flatten(list.value(i).as_ref(), &mut row.nums, &mut row.texts);
                rows.push(row);
            }
        }
    }
    for rows in contents.values_mut() {
        rows.sort_by_key(|r| r.time); // stable: same-time rows keep their logging order
    }
    Ok(contents)
}

/// Every number and text an arrow array holds, depth first.
fn flatten(a: &dyn Array, nums: &mut Vec<f64>, texts: &mut Vec<String>) {
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

/// How two series of the same entity and component compare.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeriesDiff {
    pub rows_a: usize,
    pub rows_b: usize,
    /// Rows paired by time (equal `sim_time`, in order within a time).
    pub paired: usize,
    /// Times that only one of them holds (beyond the compared span, if one was given).
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
        let b = self.first_other.as_ref().map(|d| d.0);
        match (a, b) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

/// Compares two series row by row, pairing rows by time. A value differs when |b − a| exceeds
/// `tolerance` × the series' scale (with tolerance 0: when its bits differ). Rows after
/// `until` (ns of `sim_time`) are left out on both sides.
pub fn compare(a: &[Row], b: &[Row], tolerance: f64, until: Option<i64>) -> SeriesDiff {
    let keep = |r: &&Row| until.is_none_or(|u| r.time.is_none_or(|t| t <= u));
    let a: Vec<&Row> = a.iter().filter(keep).collect();
    let b: Vec<&Row> = b.iter().filter(keep).collect();
    let largest_finite = |rows: &[&Row]| {
        rows.iter()
            .flat_map(|r| &r.nums)
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let mut scale = largest_finite(&a);
    if scale == 0.0 {
        scale = largest_finite(&b);
    }
    let mut out = SeriesDiff {
        rows_a: a.len(),
        rows_b: b.len(),
        scale,
        ..SeriesDiff::default()
    };
    let bound = tolerance * scale;
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (ra, rb) = (a[i], b[j]);
        if ra.time != rb.time {
            out.unpaired += 1;
            if ra.time < rb.time {
                i += 1;
            } else {
                j += 1;
            }
            continue;
        }
        out.paired += 1;
        if (ra.texts != rb.texts || ra.nums.len() != rb.nums.len()) && out.first_other.is_none() {
            let what = if ra.texts != rb.texts {
                format!("text {:?} vs {:?}", ra.texts.join(" "), rb.texts.join(" "))
            } else {
                format!("{} values vs {}", ra.nums.len(), rb.nums.len())
            };
            out.first_other = Some((ra.time, what));
        }
        for (&x, &y) in ra.nums.iter().zip(&rb.nums) {
            let d = Difference {
                time: ra.time,
                a: x,
                b: y,
            };
            let size = d.abs();
            let beyond = if tolerance == 0.0 {
                x.to_bits() != y.to_bits()
            } else {
                size.is_nan() || size > bound // NaN against a number is beyond any bound
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
        i += 1;
        j += 1;
    }
    out.unpaired += (a.len() - i) + (b.len() - j);
    out
}

/// A time on `sim_time` in seconds, exactly as stored (ns), or "static".
pub fn time_text(t: Option<i64>) -> String {
    match t {
        Some(ns) => {
            let (sign, ns) = if ns < 0 {
                ("-", ns.unsigned_abs())
            } else {
                ("", ns as u64)
            };
            let fraction = format!("{:09}", ns % 1_000_000_000);
            let fraction = fraction.trim_end_matches('0');
            let dot = if fraction.is_empty() { "" } else { "." };
            format!("t = {sign}{}{dot}{fraction} s", ns / 1_000_000_000)
        }
        None => "static".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(values: &[(i64, f64)]) -> Vec<Row> {
        values
            .iter()
            .map(|&(t, v)| Row {
                time: Some(t),
                nums: vec![v],
                texts: vec![],
            })
            .collect()
    }

    #[test]
    fn finds_the_first_difference_beyond_the_tolerance_and_the_largest() {
        let a = rows(&[(0, 1.0), (10, 2.0), (20, -4.0), (30, 0.0)]);
        let b = rows(&[(0, 1.0), (10, 2.0 + 1e-15), (20, -4.5), (30, 0.0)]);
        let d = compare(&a, &b, 0.0, None);
        assert_eq!(d.first.as_ref().unwrap().time, Some(10));
        assert_eq!(d.largest.as_ref().unwrap().time, Some(20));
        assert_eq!(d.largest.as_ref().unwrap().abs(), 0.5);
        assert!(!d.same());
        // Relative to the series' scale 4: 1e-15 passes 1e-3, 0.5 does not.
        let d = compare(&a, &b, 1e-3, None);
        assert_eq!(d.first.as_ref().unwrap().time, Some(20));
        assert!(!compare(&a, &b, 0.2, None).bit_identical());
        assert!(compare(&a, &b, 0.2, None).same());
        // Left out after `until`, and a missing row is a difference.
        assert!(compare(&a, &b, 0.0, Some(5)).bit_identical());
        assert_eq!(time_text(Some(1_460_000_000)), "t = 1.46 s");
        assert_eq!(time_text(Some(3_000_000_000)), "t = 3 s");
        assert_eq!(time_text(Some(-5)), "t = -0.000000005 s");
        assert_eq!(compare(&a, &b[..3], 0.0, Some(30)).unpaired, 1);
    }
}
