//! Numbers as text, in one place, so that a value reads the same in a message, a table, a
//! recording's text and a document: as typed (`shown`), to significant digits (`sig`), to a
//! fixed number of decimals without trailing zeros (`trim_number`), durations and sizes for the
//! progress notices.

/// `x` in plain form where `|x|` is in `plain` (and at 0, ∞ and NaN), in exponent form outside
/// (1e155, 1e-9): every digit kept, without hundreds of zeros.
fn plain_within(x: f64, plain: std::ops::Range<f64>) -> String {
    if x == 0.0 || !x.is_finite() || plain.contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A value as given, in exponent form when long (1e155, 1e-9), so that a message keeps every
/// digit without three hundred of them.
pub fn shown(x: f64) -> String {
    plain_within(x, 1e-4..1e6)
}

/// A vector as given, x,y,z, each component as [`shown`].
pub fn shown_vector(v: glam::DVec3) -> String {
    format!("{},{},{}", shown(v.x), shown(v.y), shown(v.z))
}

/// A range's end as a person writes it: 0, 0.5, 1e6.
pub fn bound(x: f64) -> String {
    plain_within(x, 1e-3..1e4)
}

/// `x` ≠ 0, finite, in fixed point with `digits` significant digits: 4.04, 0.00447.
fn fixed_sig(x: f64, digits: usize) -> String {
    let exponent = x.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
    format!("{x:.decimals$}")
}

/// A time scale [s] to three significant digits: 4.04, 0.00447.
pub fn seconds(t: f64) -> String {
    if !t.is_finite() || t <= 0.0 {
        return format!("{t}");
    }
    fixed_sig(t, 3)
}

/// A number to `digits` significant digits: fixed point between 1e-3 and 1e6 (17.27051,
/// 0.001234568), exponent form outside (6.198721e8, 4.4e-7), so that no digit a reader needs is
/// lost to a fixed number of decimals.
pub fn sig(x: f64, digits: usize) -> String {
    let digits = digits.max(1);
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if (-3..6).contains(&(x.abs().log10().floor() as i32)) {
        fixed_sig(x, digits)
    } else {
        format!("{x:.*e}", digits - 1)
    }
}

/// Two values to the digits that tell them apart, and one more: 1.0471975512 and
/// 1.0471975522 for a difference of 1e-9, 0.52 and 0.61 for one of 0.09 (at least three
/// digits; at most seventeen, which tell any two doubles apart).
pub fn sig_pair(a: f64, b: f64) -> (String, String) {
    let scale = a.abs().max(b.abs());
    let apart = (b - a).abs();
    let mut digits = if apart > 0.0 && scale.is_finite() && apart.is_finite() {
        ((scale / apart).log10().ceil() as usize + 1).clamp(3, 17)
    } else {
        3
    };
    while digits < 17 && a.to_bits() != b.to_bits() && sig(a, digits) == sig(b, digits) {
        digits += 1;
    }
    (sig(a, digits), sig(b, digits))
}

/// In exponent form with four significant digits.
pub fn sci(x: f64) -> String {
    format!("{x:.3e}")
}

/// A number with at most `decimals` decimals and no trailing zeros: 59.99999999999999 → "60".
pub fn trim_number(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if !s.contains('.') {
        return s;
    }
    match s.trim_end_matches('0').trim_end_matches('.') {
        "-0" => "0".to_string(),
        t => t.to_string(),
    }
}

/// A count with its noun: "1 substep", "2 substeps", "3 entities".
pub fn plural(n: impl Into<u64>, noun: &str) -> String {
    match (n.into(), noun.strip_suffix('y')) {
        (1, _) => format!("1 {noun}"),
        (n, Some(stem)) => format!("{n} {stem}ies"),
        (n, None) => format!("{n} {noun}s"),
    }
}

/// A duration rounded for reading: "45 s", "3 min 05 s", "7 h 12 min".
pub fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {:02} s", s / 60, s % 60),
        _ => format!("{} h {:02} min", s / 3600, (s % 3600) / 60),
    }
}

/// The remaining time [s] as a progress bar shows it: "12s", "3m 05s".
pub fn eta(left: f64) -> String {
    let left = left.max(0.0).round() as u64;
    if left < 60 {
        format!("{left}s")
    } else {
        format!("{}m {:02}s", left / 60, left % 60)
    }
}

/// A size rounded for reading: "120 MB", "3.4 GB".
pub fn size(bytes: f64) -> String {
    if bytes < 1e9 {
        format!("{:.0} MB", bytes / 1e6)
    } else {
        format!("{:.1} GB", bytes / 1e9)
    }
}

/// Seconds since the Unix epoch as "2026-11-27 05:40:01 UTC" (the proleptic Gregorian calendar,
/// days to dates by Howard Hinnant's `civil_from_days`).
pub fn utc(seconds: i64) -> String {
    let (days, s) = (seconds.div_euclid(86_400), seconds.rem_euclid(86_400));
    let (era, doe) = (
        (days + 719_468).div_euclid(146_097),
        (days + 719_468).rem_euclid(146_097),
    );
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let (d, m) = (
        doy - (153 * mp + 2) / 5 + 1,
        if mp < 10 { mp + 3 } else { mp - 9 },
    );
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02} UTC",
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}
