//! Numbers on the command line: a negative one joined to the option before it, and a count
//! that is negative or too large said as what is wrong; and an argument that is not UTF-8.

/// A count or an index given as a negative number (`--pinned -1`), which clap reports only as
/// "invalid digit found in string", or as one too large for it, which clap reports as "number
/// too large to fit in target type": said as what is wrong, with the flag, the value and the
/// range. Every count takes at most 2^63 − 1 (what a scene file holds: `RangedU64`), or
/// 2^32 − 1 where it is a `u32`.
pub(super) fn count_error(e: &clap::Error, command: &clap::Command) -> Option<String> {
    use clap::error::{ContextKind, ContextValue};
    use std::num::{IntErrorKind, ParseIntError};
    if e.kind() != clap::error::ErrorKind::ValueValidation {
        return None;
    }
    let (Some(ContextValue::String(arg)), Some(ContextValue::String(value))) = (
        e.get(ContextKind::InvalidArg),
        e.get(ContextKind::InvalidValue),
    ) else {
        return None;
    };
    // In a list of indices (`--pinned 0,-3`, whose items parse as integers) the first wrong
    // item is the one named.
    let source = std::error::Error::source(e).and_then(|s| s.downcast_ref::<ParseIntError>());
    let items = || {
        value
            .split(',')
            .take(if source.is_some() { usize::MAX } else { 1 })
    };
    let flag = arg.split_whitespace().next().unwrap_or(arg);
    let negative = items().find(|v| v.starts_with('-') && v[1..].parse::<u128>().is_ok());
    if let Some(negative) = negative {
        return Some(format!("{flag} {negative}: must be a whole number ≥ 0"));
    }
    if source?.kind() != &IntErrorKind::PosOverflow {
        return None;
    }
    let too_large = |v: &&str| v.trim().parse::<i64>().is_err() && v.trim().parse::<u128>().is_ok();
    let item = items().find(too_large).unwrap_or(value);
    let long = flag.trim_start_matches('-');
    let takes_u32 = std::iter::once(command)
        .chain(
            command
                .get_subcommands()
                .flat_map(|c| std::iter::once(c).chain(c.get_subcommands())),
        )
        .flat_map(|c| c.get_arguments())
        .find(|a| a.get_long() == Some(long))
        .is_some_and(|a| a.get_value_parser().type_id() == std::any::TypeId::of::<u32>());
    let max = if takes_u32 {
        u64::from(u32::MAX)
    } else {
        i64::MAX as u64
    };
    Some(format!(
        "{flag} {item}: must be a whole number from 0 to {max}"
    ))
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

/// An argument that is not UTF-8, which clap reports only as "invalid UTF-8 was detected in one
/// or more arguments": said with the option it is given to (the one before it, or its
/// `--name=`), the value as a shell word (`$'\xff'`) and what the option takes.
pub(super) fn not_utf8(e: &clap::Error, args: &[std::ffi::OsString]) -> Option<String> {
    use std::os::unix::ffi::OsStrExt as _;
    if e.kind() != clap::error::ErrorKind::InvalidUtf8 {
        return None;
    }
    let i = args.iter().position(|a| a.to_str().is_none())?;
    let bytes = args[i].as_bytes();
    let (flag, value) = match bytes.iter().position(|&b| b == b'=') {
        Some(eq) if bytes.starts_with(b"--") => {
            (String::from_utf8_lossy(&bytes[..eq]), &bytes[eq + 1..])
        }
        _ => {
            let before = (i > 1).then(|| args[i - 1].to_string_lossy());
            (
                before
                    .filter(|b| b.starts_with('-'))
                    .unwrap_or("argument".into()),
                bytes,
            )
        }
    };
    let value = crate::shell::shell_word(value);
    Some(format!(
        "{flag} {value}: not UTF-8 text; options other than file paths take UTF-8"
    ))
}
