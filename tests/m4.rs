//! M4 aggregation (`physlab::scene::m4`): the reduced series checked against plain
//! rasterisations of every step.

use physlab::scene::m4::*;
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
    assert!(M4::new(10, 4, &[]).is_err() && M4::new(10, 4, &[false; MAX_VALUES + 1]).is_err());
}
