//! Text files read one line at a time, the same way by every reader: a UTF-8 byte-order mark at
//! the start is skipped, a line that is not UTF-8 (binary data, NUL bytes of a truncated write)
//! is an error naming the file and line, CR LF and LF both end a line, and what a message echoes
//! of a file's content is short and printable ([`shown`]).

use anyhow::{bail, Context, Result};
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// Longest line accepted [bytes]: a data row is far shorter; a file without line ends (binary
/// data, one huge line) stops here instead of filling memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// At most 40 characters of `s`, control characters and escape codes escaped, `…` when cut: what
/// a message shows of a field or a name read from a file or an option.
pub fn shown(s: &str) -> String {
    let mut out: String = s
        .chars()
        .take(40)
        .collect::<String>()
        .escape_debug()
        .collect();
    if s.chars().nth(40).is_some() {
        out.push('…');
    }
    out
}

/// One line of a file: its text, number (1-based) and the file's name as messages show it.
#[derive(Debug, Clone, Copy)]
pub struct Line<'a> {
    /// The text, without its line end.
    pub text: &'a str,
    /// Line number, from 1.
    pub no: usize,
    /// The file's name.
    pub file: &'a str,
}

/// Largest description-like input read whole [bytes] (scenarios, format descriptions, noise
/// files, Jacobian points): 16 MiB.
pub const MAX_SMALL_FILE: u64 = 16 << 20;

/// Reads a small text input whole (a scenario, a description, a JSON file): refused when it is
/// not a regular file (a device or a pipe would be read forever), larger than
/// [`MAX_SMALL_FILE`], or not UTF-8; `what` names it in messages.
pub fn read_small_text(path: &Path, what: &str) -> Result<String> {
    let meta = std::fs::metadata(path)
        .with_context(|| format!("{what} {}: cannot read", path.display()))?;
    if !meta.is_file() {
        bail!(
            "{what} {}: not a regular file (a directory, device or pipe)",
            path.display()
        );
    }
    if meta.len() > MAX_SMALL_FILE {
        bail!(
            "{what} {}: {} bytes, more than the {} MiB such a file can be",
            path.display(),
            meta.len(),
            MAX_SMALL_FILE >> 20
        );
    }
    let bytes =
        std::fs::read(path).with_context(|| format!("{what} {}: cannot read", path.display()))?;
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    match std::str::from_utf8(bytes) {
        Ok(t) => Ok(t.to_string()),
        Err(e) => {
            let line = bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            bail!("{}:{line}: not UTF-8 text ({what})", path.display())
        }
    }
}

/// A message made safe to print whatever it echoes: control characters and escape codes escaped
/// (line breaks kept), runs of more than 20 digits (a 1e308 printed in full) shown in scientific
/// notation, any word over 200 characters cut, and the whole cut at 4000 characters.
pub fn printable_message(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len().min(4100));
    for (k, line) in msg.split('\n').enumerate() {
        if k > 0 {
            out.push('\n');
        }
        let mut word = String::new();
        let flush = |word: &mut String, out: &mut String| {
            let digits = word.chars().filter(|c| c.is_ascii_digit()).count();
            if digits > 20 {
                let num = word.trim_end_matches(['.', ',', ';', ':']);
                if let Ok(v) = num.parse::<f64>() {
                    let rest = word[num.len()..].to_string();
                    out.push_str(&format!("{v:e}{rest}"));
                    word.clear();
                    return;
                }
            }
            if word.chars().count() > 200 {
                let cut: String = word.chars().take(200).collect();
                out.push_str(&cut);
                out.push('…');
            } else {
                out.push_str(word);
            }
            word.clear();
        };
        for c in line.chars() {
            if c == ' ' {
                flush(&mut word, &mut out);
                out.push(' ');
            } else if c.is_control() || c == '\u{feff}' {
                word.extend(c.escape_debug());
            } else {
                word.push(c);
            }
        }
        flush(&mut word, &mut out);
        if out.len() > 4000 {
            break;
        }
    }
    if out.len() > 4000 {
        let mut end = 4000;
        while !out.is_char_boundary(end) {
            end -= 1;
        }
        out.truncate(end);
        out.push_str("… (message cut)");
    }
    out
}

/// The 1-based line of byte offset `start` in `text` (an offset at column 0 is on its own line,
/// not the one before).
pub fn line_at(text: &str, start: usize) -> usize {
    let end = start.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// A file's lines, numbered from 1, with the number of bytes read so far (for progress).
pub struct Lines<R> {
    reader: R,
    name: String,
    buf: Vec<u8>,
    lineno: usize,
    bytes_read: u64,
    total_bytes: u64,
}

impl Lines<BufReader<std::fs::File>> {
    /// Opens a regular file; `what` names the kind of file in messages ("IMU file", …).
    pub fn open(path: &Path, what: &str) -> Result<Self> {
        let meta = std::fs::metadata(path)
            .with_context(|| format!("cannot read {what} {}", path.display()))?;
        if !meta.is_file() {
            bail!(
                "{}: cannot read {what}: not a regular file (a directory, device or pipe)",
                path.display()
            );
        }
        let f = std::fs::File::open(path)
            .with_context(|| format!("cannot read {what} {}", path.display()))?;
        Ok(Lines::new(
            BufReader::with_capacity(1 << 16, f),
            &path.display().to_string(),
            meta.len(),
        ))
    }
}

impl<R: BufRead> Lines<R> {
    /// Lines of `reader`; `name` is the file's name in messages, `total_bytes` its size (0 when
    /// unknown).
    pub fn new(reader: R, name: &str, total_bytes: u64) -> Self {
        Lines {
            reader,
            name: name.to_string(),
            buf: Vec::new(),
            lineno: 0,
            bytes_read: 0,
            total_bytes,
        }
    }

    /// The file's name as messages show it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of the line last returned (1-based; 0 before the first).
    pub fn lineno(&self) -> usize {
        self.lineno
    }

    /// Fraction of the file read so far (0 when the size is unknown).
    pub fn fraction(&self) -> f64 {
        if self.total_bytes == 0 {
            0.0
        } else {
            (self.bytes_read as f64 / self.total_bytes as f64).min(1.0)
        }
    }

    /// The next line without its line end (and without a leading byte-order mark on line 1),
    /// or None at the end of the file.
    pub fn next_line(&mut self) -> Result<Option<Line<'_>>> {
        self.buf.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .with_context(|| format!("{}:{}: cannot read", self.name, self.lineno + 1))?;
        if n == 0 {
            return Ok(None);
        }
        self.lineno += 1;
        self.bytes_read += n as u64;
        if self.buf.len() > MAX_LINE_BYTES {
            bail!(
                "{}:{}: a line longer than {} bytes: not a text data file (binary data?)",
                self.name,
                self.lineno,
                MAX_LINE_BYTES
            );
        }
        while matches!(self.buf.last(), Some(b'\n' | b'\r')) {
            self.buf.pop();
        }
        let start = if self.lineno == 1 && self.buf.starts_with(b"\xEF\xBB\xBF") {
            3
        } else {
            0
        };
        let bytes = &self.buf[start..];
        if bytes.contains(&0) {
            bail!(
                "{}:{}: NUL bytes in the line: not a text data file (binary data, or a truncated write)",
                self.name,
                self.lineno
            );
        }
        // borrowed from the read buffer: no copy per line
        match std::str::from_utf8(bytes) {
            Ok(text) => Ok(Some(Line {
                text,
                no: self.lineno,
                file: &self.name,
            })),
            Err(e) => bail!(
                "{}:{}: not UTF-8 text at byte {} of the line (a binary file?)",
                self.name,
                self.lineno,
                e.valid_up_to() + 1
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bom_crlf_nul_and_binary_lines() {
        let text = b"\xEF\xBB\xBF1 2\r\n3 4\n";
        let mut l = Lines::new(&text[..], "f.txt", text.len() as u64);
        assert_eq!(l.next_line().unwrap().unwrap().text, "1 2");
        assert_eq!(l.next_line().unwrap().unwrap().text, "3 4");
        assert!(l.next_line().unwrap().is_none());
        assert!((l.fraction() - 1.0).abs() < 1e-12);
        let bad = b"1 2\n3\x004\n";
        let mut l = Lines::new(&bad[..], "f.txt", 0);
        l.next_line().unwrap();
        let e = l.next_line().unwrap_err().to_string();
        assert!(e.starts_with("f.txt:2: NUL bytes"), "{e}");
        let bad = b"\xff\xfe1\n";
        let e = Lines::new(&bad[..], "f.txt", 0)
            .next_line()
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("f.txt:1: not UTF-8"), "{e}");
    }

    #[test]
    fn messages_are_printable_and_short() {
        let m = printable_message("--prior `eps\u{1b}[2J=1`: bad");
        assert!(!m.contains('\u{1b}') && m.contains("\\u{1b}"), "{m}");
        let big = format!("--lat {}: out of range", 1e308);
        assert_eq!(printable_message(&big), "--lat 1e308: out of range");
        let long = "x".repeat(100_000);
        assert!(printable_message(&long).chars().count() <= 201);
        let many = "word ".repeat(5000);
        assert!(printable_message(&many).len() < 4100);
        assert_eq!(printable_message("a\nb"), "a\nb");
    }

    #[test]
    fn line_of_an_offset() {
        let t = "a = 1\nb = 2\nc = 3\n";
        assert_eq!(line_at(t, 0), 1);
        assert_eq!(line_at(t, 6), 2); // column 0 of line 2
        assert_eq!(line_at(t, 13), 3);
        assert_eq!(line_at(t, 999), 4);
    }

    #[test]
    fn shown_is_short_and_printable() {
        assert_eq!(shown("abc"), "abc");
        assert_eq!(shown("a\u{1b}[31mb"), "a\\u{1b}[31mb");
        let long = "x".repeat(100_000);
        assert_eq!(shown(&long).chars().count(), 41);
    }
}
