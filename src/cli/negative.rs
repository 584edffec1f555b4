//! Negative numbers on the command line: joined to the option before them, and a negative
//! count said as what is wrong.

/// A negative number given to a count or an index (`--pinned -1`), which clap reports only as
/// "invalid digit found in string": said as what is wrong, with the flag and the value.
pub(super) fn negative_count(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    if e.kind() != clap::error::ErrorKind::ValueValidation {
        return None;
    }
    let (Some(ContextValue::String(arg)), Some(ContextValue::String(value))) = (
        e.get(ContextKind::InvalidArg),
        e.get(ContextKind::InvalidValue),
    ) else {
        return None;
    };
    // In a list of indices (`--pinned 0,-3`, whose items parse as integers) the first negative
    // item is the one named.
    let list = std::error::Error::source(e).is_some_and(|s| s.is::<std::num::ParseIntError>());
    let mut items = value.split(',').take(if list { usize::MAX } else { 1 });
    let negative = items.find(|v| v.starts_with('-') && v[1..].parse::<u128>().is_ok())?;
    let flag = arg.split_whitespace().next().unwrap_or(arg);
    Some(format!("{flag} {negative}: must be a whole number ≥ 0"))
}

/// `--flag -1e-3` as `--flag=-1e-3`: a long option followed by a negative number (or a
/// comma-separated list of numbers, `--wind -1,0,0`) takes it as its value. clap reads a
/// leading `-` as a flag unless the value looks like a plain number, and `1e-3` does not to
/// it; `allow_hyphen_values` would also swallow a real flag (`--dt -o x`). Only tokens that
/// parse as numbers are joined, so every flag is still a flag.
pub fn join_negative_values(
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let numeric = |s: &str| {
        s.starts_with('-')
            && s.len() > 1
            && s.split(',').all(|part| {
                let t = part.trim();
                !t.is_empty() && t.parse::<f64>().is_ok_and(f64::is_finite) && !t.starts_with("--")
            })
    };
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    let mut args = args.into_iter().peekable();
    while let Some(arg) = args.next() {
        let long_without_value = arg
            .to_str()
            .is_some_and(|a| a.starts_with("--") && a.len() > 2 && !a.contains('='));
        if long_without_value
            && let Some(next) = args.peek().and_then(|n| n.to_str())
            && numeric(next)
        {
            let mut joined = arg.clone();
            joined.push("=");
            joined.push(next);
            out.push(joined);
            args.next();
        } else {
            out.push(arg);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::join_negative_values;

    fn joined(args: &[&str]) -> Vec<String> {
        join_negative_values(args.iter().map(|a| a.into()))
            .into_iter()
            .map(|a| a.into_string().unwrap())
            .collect()
    }

    #[test]
    fn negative_numbers_after_a_long_option_are_its_value_and_flags_stay_flags() {
        assert_eq!(
            joined(&["p", "pendulum", "--theta0", "-1e-3", "--omega0", "-2.5E+1"]),
            ["p", "pendulum", "--theta0=-1e-3", "--omega0=-2.5E+1"]
        );
        assert_eq!(
            joined(&["p", "hair", "--wind", "-1,0,-3e2", "-q"]),
            ["p", "hair", "--wind=-1,0,-3e2", "-q"]
        );
        // Not numbers: left for clap (a missing value, a flag, stdout, a negative infinity).
        for args in [
            &["p", "pendulum", "--dt", "-o", "x"][..],
            &["p", "pendulum", "-o", "-"],
            &["p", "pendulum", "--dt", "--", "-1"],
            &["p", "pendulum", "--dt", "-inf"],
            &["p", "pendulum", "--dt=-1", "-1"],
        ] {
            assert_eq!(joined(args), args);
        }
    }
}
