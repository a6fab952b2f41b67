//! Lines of a text file, one at a time, in bounded memory: the layer every CSV reader of
//! gyrofx stands on, so that a file without line ends, a file of NUL bytes or a line end that
//! gyrofx does not read fails on its first bad line instead of filling memory.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

use super::MAX_LINE_BYTES;

/// What a line holds, once its line end (and on line 1 a byte-order mark) is removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// The file has no more lines.
    End,
    /// A `#` comment (after leading spaces).
    Comment,
    /// Only spaces, or only empty cells (`,,`): a row without a value.
    Blank,
    /// Anything else: a header or a data row.
    Text,
}

/// A reader's lines, each at most [`MAX_LINE_BYTES`] long.
pub(super) struct Lines<R> {
    path: PathBuf,
    reader: R,
    /// The current line, without its line end.
    line: Vec<u8>,
    /// Lines read so far: the current line's number as an editor counts it.
    number: u64,
}

impl<R: BufRead> Lines<R> {
    /// The lines of `reader`; `path` names it in errors.
    pub(super) fn new(path: &Path, reader: R) -> Self {
        Lines {
            path: path.to_path_buf(),
            reader,
            line: Vec::new(),
            number: 0,
        }
    }

    /// The current line, without its line end.
    pub(super) fn line(&self) -> &[u8] {
        &self.line
    }

    /// The current line's number (1 for the first).
    pub(super) fn number(&self) -> u64 {
        self.number
    }

    /// The reader underneath.
    pub(super) fn into_inner(self) -> R {
        self.reader
    }

    /// An input error about this file.
    pub(super) fn error(&self, message: String) -> Error {
        Error::Input {
            path: self.path.clone(),
            message,
        }
    }

    /// Reads the next line and says what it holds.
    ///
    /// # Errors
    /// A line longer than [`MAX_LINE_BYTES`], a NUL byte (the file is not text), a carriage
    /// return that does not end a line, or a read error.
    pub(super) fn next(&mut self) -> Result<Kind> {
        self.line.clear();
        let mut ended = false;
        let mut read_any = false;
        while !ended {
            let buffer = self
                .reader
                .fill_buf()
                .map_err(|e| Error::io(&self.path, e))?;
            if buffer.is_empty() {
                break;
            }
            read_any = true;
            let (take, end) = match memchr::memchr(b'\n', buffer) {
                Some(at) => (at + 1, true),
                None => (buffer.len(), false),
            };
            let chunk = &buffer[..take];
            if let Some(at) = memchr::memchr(0, chunk) {
                let column = self.line.len() + at + 1;
                return Err(self.error(not_text(self.number + 1, column)));
            }
            self.line.extend_from_slice(chunk);
            self.reader.consume(take);
            ended = end;
            // The line end and a `\r` before it are not counted.
            if self.line.len() > MAX_LINE_BYTES + 2 {
                return Err(self.error(too_long(self.number + 1)));
            }
        }
        if !read_any {
            return Ok(Kind::End);
        }
        self.number += 1;
        if self.line.last() == Some(&b'\n') {
            self.line.pop();
        }
        if self.line.last() == Some(&b'\r') {
            self.line.pop();
        }
        if self.line.len() > MAX_LINE_BYTES {
            return Err(self.error(too_long(self.number)));
        }
        if self.number == 1 && self.line.starts_with("\u{feff}".as_bytes()) {
            self.line.drain(..3);
        }
        if self.line.contains(&b'\r') {
            return Err(self.error(lone_carriage_return(self.number)));
        }
        Ok(classify(&self.line))
    }
}

/// What `line` (without its line end) holds.
pub(super) fn classify(line: &[u8]) -> Kind {
    let text = line.trim_ascii();
    if text.starts_with(b"#") {
        Kind::Comment
    } else if cells(text).all(<[u8]>::is_empty) {
        Kind::Blank
    } else {
        Kind::Text
    }
}

/// The cells of a line without its line end: split at commas, trimmed of spaces and of the
/// quotes around them. A quoted cell cannot hold a comma.
pub(super) fn cells(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| *b == b',').map(|cell| {
        let cell = cell.trim_ascii();
        cell.strip_prefix(b"\"")
            .and_then(|c| c.strip_suffix(b"\""))
            .unwrap_or(cell)
    })
}

/// The message for a line longer than [`MAX_LINE_BYTES`].
pub(super) fn too_long(line: u64) -> String {
    format!(
        "line {line} is longer than {MAX_LINE_BYTES} bytes: this is not a CSV file of numbers \
         (a file without line ends?); gyrofx reads lines of at most {MAX_LINE_BYTES} bytes"
    )
}

/// The message for a NUL byte.
pub(super) fn not_text(line: u64, column: usize) -> String {
    format!(
        "line {line}, byte {column} is a NUL byte: this is not a text file; gyrofx reads CSV \
         text (UTF-8 or ASCII)"
    )
}

/// The message for a `\r` that does not end a line.
pub(super) fn lone_carriage_return(line: u64) -> String {
    format!(
        "line {line} holds a carriage return (\\r) that does not end the line: gyrofx reads \
         lines ended by \\n or \\r\\n (convert old Mac line ends with `tr '\\r' '\\n'`)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &[u8]) -> Result<Vec<(Kind, Vec<u8>)>> {
        let mut lines = Lines::new(
            Path::new("x.csv"),
            std::io::BufReader::with_capacity(7, text),
        );
        let mut out = Vec::new();
        loop {
            let kind = lines.next()?;
            if kind == Kind::End {
                return Ok(out);
            }
            out.push((kind, lines.line().to_vec()));
        }
    }

    #[test]
    fn lines_are_classified_without_their_line_ends() {
        let got = kinds(b"\xef\xbb\xbfa,b\r\n # note\n\n , \n1,2\n\"3\",\n4,5").unwrap();
        let want: Vec<(Kind, &[u8])> = vec![
            (Kind::Text, b"a,b"),
            (Kind::Comment, b" # note"),
            (Kind::Blank, b""),
            (Kind::Blank, b" , "),
            (Kind::Text, b"1,2"),
            (Kind::Text, b"\"3\","),
            (Kind::Text, b"4,5"),
        ];
        let got: Vec<(Kind, &[u8])> = got.iter().map(|(k, l)| (*k, &l[..])).collect();
        assert_eq!(got, want);
    }

    #[test]
    fn long_lines_nul_bytes_and_lone_carriage_returns_are_refused() {
        let long = vec![b'1'; MAX_LINE_BYTES + 1];
        let err = kinds(&long).unwrap_err().to_string();
        assert!(err.contains("line 1 is longer than 1048576 bytes"), "{err}");
        let mut exact = vec![b'1'; MAX_LINE_BYTES];
        exact.extend_from_slice(b"\r\n2\n");
        assert_eq!(kinds(&exact).unwrap().len(), 2);
        let mut late = b"a\nb\n".to_vec();
        late.extend(std::iter::repeat_n(b'x', 3 * MAX_LINE_BYTES));
        let err = kinds(&late).unwrap_err().to_string();
        assert!(err.contains("line 3 is longer"), "{err}");
        let err = kinds(b"a,b\n1,\0\n").unwrap_err().to_string();
        assert!(err.contains("line 2, byte 3 is a NUL byte"), "{err}");
        let err = kinds(&vec![0u8; 1 << 16]).unwrap_err().to_string();
        assert!(err.contains("line 1, byte 1 is a NUL byte"), "{err}");
        let err = kinds(b"a,b\r1,2\r").unwrap_err().to_string();
        assert!(err.contains("line 1 holds a carriage return"), "{err}");
    }
}
