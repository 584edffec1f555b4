//! Text for a terminal and a shell: arguments quoted so that bash reads them back byte for byte
//! ([`shell_word`], [`shell_words`]) and text from untrusted files escaped so that a terminal
//! shows it rather than acts on it ([`escaped`]).

/// The process's command line as one line of text, losslessly: arguments of plain characters
/// as they are, any other (spaces, quotes, control characters, bytes that are not UTF-8) in
/// shell ANSI-C quoting (`$'\xff\xfe.rrd'`), so that pasted into bash it gives the same bytes.
pub fn command_line() -> String {
    std::env::args_os()
        .map(|a| shell_word(std::os::unix::ffi::OsStrExt::as_bytes(a.as_os_str())))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A path as a terminal may show it ([`escaped`]): what physlab prints of a path it writes.
pub fn shown(path: &std::path::Path) -> String {
    escaped(&path.display().to_string()).into_owned()
}

/// A path as one shell word ([`shell_word`]).
pub fn shell_path(path: &std::path::Path) -> String {
    shell_word(std::os::unix::ffi::OsStrExt::as_bytes(path.as_os_str()))
}

/// One argument as a shell word that bash reads back byte for byte and a terminal shows as it
/// is: plain characters as they are, anything else in ANSI-C quoting (`$'a b'`,
/// `$'\xff.rrd'`), its unsafe characters escaped as [`escaped`] shows them. No word it makes
/// can run anything: `$(…)`, `;` and quotes stay inside the quotes.
pub fn shell_word(bytes: &[u8]) -> String {
    let plain = |c: char| c.is_alphanumeric() || "-_./=:,+@%^".contains(c);
    if let Ok(s) = std::str::from_utf8(bytes)
        && !s.is_empty()
        && s.chars().all(plain)
    {
        return s.to_string();
    }
    let mut out = String::from("$'");
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            match c {
                '\\' => out.push_str("\\\\"),
                '\'' => out.push_str("\\'"),
                c => push_shown(&mut out, c),
            }
        }
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02x}"));
        }
    }
    out.push('\'');
    out
}

/// The words [`shell_word`] made, read back (words joined by single spaces); `None` for text it
/// cannot have made. What a recording says its command was is rebuilt from these, never
/// copied.
pub fn shell_words(line: &str) -> Option<Vec<Vec<u8>>> {
    let mut words = Vec::new();
    let mut rest = line.as_bytes();
    while !rest.is_empty() {
        let mut word = Vec::new();
        if let Some(quoted) = rest.strip_prefix(b"$'") {
            let mut i = 0;
            loop {
                match *quoted.get(i)? {
                    b'\'' => break,
                    b'\\' => {
                        let (byte, used) = match *quoted.get(i + 1)? {
                            b'n' => (b'\n', 2),
                            b't' => (b'\t', 2),
                            b'r' => (b'\r', 2),
                            b @ (b'\\' | b'\'') => (b, 2),
                            b'x' => {
                                let hex = std::str::from_utf8(quoted.get(i + 2..i + 4)?).ok()?;
                                (u8::from_str_radix(hex, 16).ok()?, 4)
                            }
                            _ => return None,
                        };
                        word.push(byte);
                        i += used;
                    }
                    b => {
                        word.push(b);
                        i += 1;
                    }
                }
            }
            rest = &quoted[i + 1..];
        } else {
            let end = rest.iter().position(|&b| b == b' ').unwrap_or(rest.len());
            word.extend_from_slice(&rest[..end]);
            rest = &rest[end..];
            if shell_word(&word) != std::str::from_utf8(&word).ok()? {
                return None;
            }
        }
        words.push(word);
        match rest {
            [] => {}
            [b' ', more @ ..] if !more.is_empty() => rest = more,
            _ => return None,
        }
    }
    Some(words)
}

/// Text from a recording as a terminal may show it: every control character (ESC, a line
/// break, a C1 code) and every bidirectional override written out (`\x1b`, `\n`,
/// `\xe2\x80\xae`), so that no recording moves the cursor, clears the screen, retitles the
/// window or starts a line of its own. Everything `inspect`, `diff` and `reproduce` print
/// passes through it (entity paths come escaped by Rerun already).
pub fn escaped(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(unsafe_char) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        push_shown(&mut out, c);
    }
    out.into()
}

/// A character a terminal acts on rather than shows, that reorders what follows it (the bidi
/// marks, embeddings, overrides and isolates, U+061C included), or that is invisible or breaks a
/// line where nothing shows it (zero-width space and joiners, BOM, line and paragraph separators).
fn unsafe_char(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{061c}'
                | '\u{200b}'..='\u{200f}'
                | '\u{2028}'..='\u{202e}'
                | '\u{2066}'..='\u{2069}'
                | '\u{feff}'
        )
}

/// `c`, or its escape when it is unsafe: `\n`, `\t`, `\r`, else its UTF-8 bytes as `\xNN`
/// (what bash's `$'…'` reads back).
fn push_shown(out: &mut String, c: char) {
    match c {
        '\n' => out.push_str("\\n"),
        '\t' => out.push_str("\\t"),
        '\r' => out.push_str("\\r"),
        c if unsafe_char(c) => {
            for b in c.to_string().bytes() {
                out.push_str(&format!("\\x{b:02x}"));
            }
        }
        c => out.push(c),
    }
}
