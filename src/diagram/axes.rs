//! Log axes in decades: their range, the ticks at every power of ten and the faint lines
//! between, and the labels.

use std::ops::Range;

use plotters::prelude::*;

/// 10ᵏ with a superscript exponent.
pub fn decade_label(k: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if k < 0 {
        s.push('⁻');
    }
    for d in k.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
}

/// The decades spanning `values` (log10, whole decades, at least one).
pub(super) fn decades(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .map(f64::log10)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let (lo, hi) = ((lo - 0.02).floor(), (hi + 0.02).ceil());
    lo..hi.max(lo + 1.0)
}

/// Ticks at every decade (every second or third one when there are many, labelled), faint
/// lines at 2…9 × 10ᵏ when the axis spans few decades.
pub fn log_axis(range: Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let (lo, hi) = (range.start as i32, range.end as i32);
    let span = hi - lo;
    let step = match span {
        17.. => 3,
        10..=16 => 2,
        _ => 1,
    };
    let bold: Vec<f64> = (lo..=hi)
        .filter(|k| (k - lo) % step == 0)
        .map(f64::from)
        .collect();
    let light: Vec<f64> = if span <= 9 {
        (lo..hi)
            .flat_map(|k| (2..10).map(move |m| f64::from(k) + f64::from(m).log10()))
            .collect()
    } else {
        (lo..=hi).map(f64::from).collect()
    };
    (bold, light)
}

/// A linear axis over log10 values (or category indices) with the ticks given: bold ones
/// labelled, light ones drawn faint.
#[derive(Clone)]
pub(super) struct Ticks {
    pub(super) range: Range<f64>,
    pub(super) bold: Vec<f64>,
    pub(super) light: Vec<f64>,
}

impl Ticks {
    pub(super) fn decades(range: Range<f64>) -> Self {
        let (bold, light) = log_axis(range.clone());
        Ticks { range, bold, light }
    }
}

impl Ranged for Ticks {
    type ValueType = f64;
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.range.start) / (self.range.end - self.range.start);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }
}

pub(super) fn label_of(v: &f64) -> String {
    decade_label(v.round() as i32)
}
