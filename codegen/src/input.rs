//! Reading recorded rate data: one numeric column of a CSV file, or several columns row by
//! row ([`Columns`]), streamed.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

mod decimal;

/// Reads the column `column` (by header name) of the CSV file at `path` as f64 values.
///
/// The first row that is not a `#` comment is the header. Blank lines are skipped, so every
/// CSV file `gyrofx generate` writes is valid input. Records are read one at a time, so
/// large files are not held twice.
///
/// # Errors
/// [`Error::Input`] naming the line and column of a missing, non-numeric or non-finite cell, a
/// missing column (listing those present), or an empty file; [`Error::Io`] when the file
/// cannot be opened.
pub fn read_column(path: &Path, column: &str) -> Result<Vec<f64>> {
    read(path, column, false).map(|(values, _)| values)
}

/// [`read_column`], but rows whose cell is empty (a gap, e.g. a reset row in gyrofx's vector
/// CSVs) are skipped instead of refused. Returns the values and the number of rows skipped.
///
/// # Errors
/// As [`read_column`], except for empty cells.
pub fn read_column_with_gaps(path: &Path, column: &str) -> Result<(Vec<f64>, usize)> {
    read(path, column, true)
}

/// The header of the CSV file at `path`: the cells of its first line that is neither blank nor
/// a `#` comment, trimmed.
///
/// # Errors
/// [`Error::Io`] when the file cannot be read, [`Error::Input`] when it has no header line.
pub fn read_header(path: &Path) -> Result<Vec<String>> {
    use std::io::BufRead;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    for line in std::io::BufReader::new(file).lines() {
        let line = line.map_err(|e| Error::io(path, e))?;
        let line = line.trim_start_matches('\u{feff}').trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        return Ok(line
            .split(',')
            .map(|cell| cell.trim().trim_matches('"').to_string())
            .collect());
    }
    Err(Error::Input {
        path: path.to_path_buf(),
        message: "the file is empty: expected a header line naming the columns".into(),
    })
}

fn read(path: &Path, column: &str, gaps: bool) -> Result<(Vec<f64>, usize)> {
    match read_plain(path, column, gaps)? {
        Some(result) => Ok(result),
        None => read_csv(path, column, gaps),
    }
}

/// Chosen columns of a CSV file, row by row, without holding the file: for inputs that name
/// several columns at once (a recording's two gyros and its mode). The same rules as
/// [`read_header`] and [`read_column`]: the first line that is neither blank nor a `#` comment
/// is the header, blank and comment lines are skipped, cells are split at commas and trimmed
/// of spaces and surrounding quotes, and a missing, non-numeric or non-finite cell is an error
/// naming its line (as an editor counts it) and column. At most 8 columns at a time.
pub struct Columns<R: std::io::BufRead> {
    path: PathBuf,
    names: Vec<String>,
    indices: Vec<usize>,
    reader: R,
    line: Vec<u8>,
    /// Lines read so far.
    line_number: u64,
}

impl Columns<std::io::BufReader<std::fs::File>> {
    /// The columns `names` (header names) of the CSV file at `path`.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be opened; [`Error::Input`] for an empty file or a
    /// missing column (listing those present).
    pub fn open(path: &Path, names: &[&str]) -> Result<Self> {
        let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        Columns::from_reader(path, std::io::BufReader::new(file), names)
    }
}

/// The cells of a line without its line end.
fn cells(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| *b == b',').map(|cell| {
        let cell = cell.trim_ascii();
        cell.strip_prefix(b"\"")
            .and_then(|c| c.strip_suffix(b"\""))
            .unwrap_or(cell)
    })
}

impl<R: std::io::BufRead> Columns<R> {
    /// As [`Columns::open`] on the bytes of `reader`; `path` names them in errors.
    ///
    /// # Errors
    /// As [`Columns::open`].
    pub fn from_reader(path: &Path, reader: R, names: &[&str]) -> Result<Self> {
        assert!(names.len() <= 8, "at most 8 columns at a time");
        let mut columns = Columns {
            path: path.to_path_buf(),
            names: names.iter().map(|n| n.to_string()).collect(),
            indices: Vec::new(),
            reader,
            line: Vec::new(),
            line_number: 0,
        };
        if !columns.next_line()? {
            return Err(Error::Input {
                path: path.to_path_buf(),
                message: "the file is empty: expected a header line naming the columns".into(),
            });
        }
        let header: Vec<String> = cells(&columns.line)
            .map(|c| String::from_utf8_lossy(c).into_owned())
            .collect();
        columns.indices = names
            .iter()
            .map(|name| {
                header
                    .iter()
                    .position(|h| h == name)
                    .ok_or_else(|| Error::Input {
                        path: path.to_path_buf(),
                        message: no_column(
                            name,
                            &header.iter().map(String::as_str).collect::<Vec<_>>(),
                        ),
                    })
            })
            .collect::<Result<Vec<usize>>>()?;
        Ok(columns)
    }

    /// Reads up to the next line that is neither blank nor a comment (into `self.line`, its
    /// line end and a leading byte-order mark removed); false at the end of the file.
    fn next_line(&mut self) -> Result<bool> {
        loop {
            self.line.clear();
            let read = self
                .reader
                .read_until(b'\n', &mut self.line)
                .map_err(|e| Error::io(&self.path, e))?;
            if read == 0 {
                return Ok(false);
            }
            self.line_number += 1;
            while matches!(self.line.last(), Some(b'\n' | b'\r')) {
                self.line.pop();
            }
            if self.line_number == 1 && self.line.starts_with("\u{feff}".as_bytes()) {
                self.line.drain(..3);
            }
            let text = self.line.trim_ascii();
            if !text.is_empty() && !text.starts_with(b"#") && cells(text).any(|c| !c.is_empty()) {
                return Ok(true);
            }
        }
    }

    /// The next data row's values into `values` (one per column, in the order named); its line
    /// number, or `None` at the end of the file.
    ///
    /// # Errors
    /// A bad cell or an unreadable file, naming the line and column.
    pub fn next_row(&mut self, values: &mut [f64]) -> Result<Option<u64>> {
        if !self.next_line()? {
            return Ok(None);
        }
        let line = self.line_number;
        let bad = |message: String| Error::Input {
            path: self.path.clone(),
            message,
        };
        let mut wanted = [&b""[..]; 8];
        let last = self.indices.iter().max().copied().unwrap_or(0);
        for (i, cell) in cells(&self.line).enumerate().take(last + 1) {
            for (slot, index) in wanted.iter_mut().zip(&self.indices) {
                if *index == i {
                    *slot = cell;
                }
            }
        }
        for (((value, bytes), name), _) in values
            .iter_mut()
            .zip(wanted)
            .zip(&self.names)
            .zip(&self.indices)
        {
            let cell = std::str::from_utf8(bytes).map_err(|_| {
                bad(format!(
                    "line {line}, column {name:?}: the cell is not UTF-8 text"
                ))
            })?;
            *value = cell_value(cell, line, name, false, &bad)?
                .expect("a cell without gaps has a value");
        }
        Ok(Some(line))
    }

    /// The reader underneath.
    pub fn into_inner(self) -> R {
        self.reader
    }
}

/// What one cell holds: a value, or `None` for a gap that is skipped.
fn cell_value(
    cell: &str,
    line: u64,
    column: &str,
    gaps: bool,
    bad: &(dyn Fn(String) -> Error + Sync),
) -> Result<Option<f64>> {
    if cell.is_empty() {
        if gaps {
            return Ok(None);
        }
        return Err(bad(format!(
            "line {line}, column {column:?}: the cell is empty"
        )));
    }
    let value: f64 = cell.parse().map_err(|_| {
        bad(format!(
            "line {line}, column {column:?}: {cell:?} is not a number"
        ))
    })?;
    if !value.is_finite() {
        return Err(bad(format!(
            "line {line}, column {column:?}: {cell} is not allowed: values must be finite"
        )));
    }
    Ok(Some(value))
}

fn no_column(column: &str, header: &[&str]) -> String {
    format!(
        "no column named {column:?}; the header has: {}",
        header.join(", ")
    )
}

/// Bytes the plain reader takes at a time (plus the partial line carried over).
const PLAIN_BLOCK: usize = 8 << 20;

/// What a line holds for the plain reader.
enum Line<'a> {
    /// Blank, a comment, or only empty cells.
    Skip,
    /// Text the plain reader does not handle (a quote, a lone `\r`, a BOM, not UTF-8).
    Foreign,
    /// A data or header line, without its line end.
    Text(&'a str),
}

fn classify(line: &[u8]) -> Line<'_> {
    let mut bytes = line;
    if let Some(rest) = bytes.strip_suffix(b"\n") {
        bytes = rest;
    }
    if let Some(rest) = bytes.strip_suffix(b"\r") {
        bytes = rest;
    }
    if bytes.contains(&b'"') || bytes.contains(&b'\r') || bytes.starts_with(&[0xef, 0xbb, 0xbf]) {
        return Line::Foreign;
    }
    if bytes.is_empty() || bytes[0] == b'#' {
        return Line::Skip;
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => Line::Text(text),
        Err(_) => Line::Foreign,
    }
}

/// The lines of `bytes`, each with its `\n` (the last one may lack it).
fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    bytes.split_inclusive(|b| *b == b'\n')
}

/// One part of a block, parsed (its values went to the vector it was given): its gaps, its
/// lines, and where it stopped.
struct Part {
    skipped: usize,
    /// Lines gone through: all of the part's unless it stopped.
    lines: u64,
    /// A foreign line (hand the file to the CSV reader) or a bad cell, whichever came first.
    stop: Option<Stop>,
}

enum Stop {
    Foreign,
    Bad(Error),
}

/// Parses the data lines of `bytes`, the first being line `first_line` of the file, pushing
/// their values onto `values`.
fn parse_part(
    bytes: &[u8],
    first_line: u64,
    index: usize,
    column: &str,
    gaps: bool,
    bad: &(dyn Fn(String) -> Error + Sync),
    values: &mut Vec<f64>,
) -> Part {
    let mut part = Part {
        skipped: 0,
        lines: 0,
        stop: None,
    };
    // Most parts hold no quote, no `\r`, no byte 0xEF (a BOM's first) and are valid UTF-8:
    // checked once for the whole part (memchr and the ASCII fast path), not per line.
    let clean = (!bytes.contains(&b'"') && !bytes.contains(&b'\r') && !bytes.contains(&0xef))
        .then(|| std::str::from_utf8(bytes).ok())
        .flatten();
    let take = |part: &mut Part, values: &mut Vec<f64>, offset: usize, line: Line| -> bool {
        let text = match line {
            Line::Skip => return true,
            Line::Foreign => {
                part.stop = Some(Stop::Foreign);
                return false;
            }
            Line::Text(text) => text,
        };
        let cell = text.split(',').nth(index).unwrap_or("").trim();
        // A line of empty cells is skipped, as the CSV crate skips it (checked only when the
        // cell read is empty: most lines are not).
        if cell.is_empty() && text.split(',').all(|cell| cell.trim().is_empty()) {
            return true;
        }
        match cell_value(cell, first_line + offset as u64, column, gaps, bad) {
            Ok(Some(value)) => values.push(value),
            Ok(None) => part.skipped += 1,
            Err(e) => {
                part.stop = Some(Stop::Bad(e));
                return false;
            }
        }
        true
    };
    match clean {
        Some(text) => {
            let bytes = text.as_bytes();
            let mut start = 0;
            let mut offset = 0;
            while start < bytes.len() {
                // The usual line, a plain decimal in the cell: parsed where it stands, in
                // one pass that also finds the line's end.
                let cell = if index == 0 {
                    Some(start)
                } else {
                    cell_start(bytes, start, index)
                };
                if let Some((value, end)) = cell.and_then(|cell| {
                    let (value, used) = decimal::parse_prefix(&bytes[cell..])?;
                    Some((value, cell + used))
                }) {
                    match bytes.get(end) {
                        None | Some(b'\n') => {
                            values.push(value);
                            start = end + 1;
                            offset += 1;
                            continue;
                        }
                        Some(b',') => {
                            values.push(value);
                            start = memchr::memchr(b'\n', &bytes[end..])
                                .map_or(bytes.len(), |p| end + p + 1);
                            offset += 1;
                            continue;
                        }
                        _ => {}
                    }
                }
                // Anything else (a comment, spaces, a gap, a bad cell) as the general path
                // takes it.
                let end = memchr::memchr(b'\n', &bytes[start..]).map_or(bytes.len(), |p| start + p);
                let line = &text[start..end];
                let line = if line.is_empty() || line.starts_with('#') {
                    Line::Skip
                } else {
                    Line::Text(line)
                };
                if !take(&mut part, values, offset, line) {
                    break;
                }
                start = end + 1;
                offset += 1;
            }
            part.lines = offset as u64;
        }
        None => {
            for (offset, line) in lines(bytes).enumerate() {
                if !take(&mut part, values, offset, classify(line)) {
                    break;
                }
                part.lines = offset as u64 + 1;
            }
        }
    }
    part
}

/// Where cell `index` (> 0) of the line starting at `start` begins: after its `index`-th
/// comma, or `None` when the line ends first.
fn cell_start(bytes: &[u8], start: usize, index: usize) -> Option<usize> {
    let mut commas = 0;
    for (i, b) in bytes[start..].iter().enumerate() {
        match b {
            b'\n' => return None,
            b',' => {
                commas += 1;
                if commas == index {
                    return Some(start + i + 1);
                }
            }
            _ => {}
        }
    }
    None
}

/// The common case without the CSV crate: unquoted cells, `\n` or `\r\n` line ends, no
/// byte-order mark. The file is read in blocks of [`PLAIN_BLOCK`] bytes cut at line ends;
/// each block's lines are split at commas and parsed on every core (errors still name the
/// first bad line of the file). `None` as soon as the file holds anything else: a quote, a
/// lone `\r`, a BOM; [`read_csv`] then reads it.
fn read_plain(path: &Path, column: &str, gaps: bool) -> Result<Option<(Vec<f64>, usize)>> {
    read_plain_in_blocks(path, column, gaps, PLAIN_BLOCK)
}

/// [`read_plain`] with blocks of `block_size` bytes (tests cut files everywhere with small
/// ones).
///
/// A reader thread reads the next block while the current one is parsed. Each block is cut
/// into one part per core at line ends; the first part's values go straight onto the result,
/// the others' through a buffer each that is kept from block to block. A part does not know
/// its first line number until the parts before it are counted: when one stops at a bad
/// cell, it is parsed again with its line number so the error names the file's line.
fn read_plain_in_blocks(
    path: &Path,
    column: &str,
    gaps: bool,
    block_size: usize,
) -> Result<Option<(Vec<f64>, usize)>> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get().min(8));
    let (full, blocks) = std::sync::mpsc::sync_channel::<std::io::Result<Vec<u8>>>(1);
    let (empty, spare) = std::sync::mpsc::channel::<Vec<u8>>();
    std::thread::scope(|scope| {
        scope.spawn(move || read_blocks(file, block_size.max(1), &full, &spare));
        let mut line_number = 0u64; // lines before the block
        let mut index: Option<usize> = None;
        let mut values = Vec::new();
        let mut buffers: Vec<Vec<f64>> = vec![Vec::new(); cores.saturating_sub(1)];
        let mut skipped = 0;
        for block in blocks {
            let block = block.map_err(|e| Error::io(path, e))?;
            let mut rest = &block[..];
            // The header: the first line that is neither blank nor a comment.
            while index.is_none() {
                let Some(line) = lines(rest).next() else {
                    break;
                };
                rest = &rest[line.len()..];
                line_number += 1;
                match classify(line) {
                    Line::Skip => {}
                    Line::Foreign => return Ok(None),
                    Line::Text(text) => {
                        let header: Vec<&str> = text.split(',').map(str::trim).collect();
                        if header.iter().all(|h| h.is_empty()) {
                            return Ok(None);
                        }
                        index = Some(
                            header
                                .iter()
                                .position(|h| *h == column)
                                .ok_or_else(|| bad(no_column(column, &header)))?,
                        );
                    }
                }
            }
            let Some(index) = index else {
                let _ = empty.send(block);
                continue;
            };
            let parts = cut_at_lines(rest, cores);
            let bad = &bad;
            let (first, others) = parts
                .split_first()
                .map_or((&[][..], &[][..]), |(f, o)| (*f, o));
            let parsed: Vec<Part> = std::thread::scope(|scope| {
                let handles: Vec<_> = others
                    .iter()
                    .zip(buffers.iter_mut())
                    .map(|(part, buffer)| {
                        buffer.clear();
                        scope.spawn(move || parse_part(part, 0, index, column, gaps, bad, buffer))
                    })
                    .collect();
                let mut parsed = vec![parse_part(first, 0, index, column, gaps, bad, &mut values)];
                parsed.extend(
                    handles
                        .into_iter()
                        .map(|h| h.join().expect("parsing does not panic")),
                );
                parsed
            });
            for (number, part) in parsed.into_iter().enumerate() {
                if number > 0 {
                    values.extend_from_slice(&buffers[number - 1]);
                }
                skipped += part.skipped;
                match part.stop {
                    None => line_number += part.lines,
                    Some(Stop::Foreign) => return Ok(None),
                    Some(Stop::Bad(_)) => {
                        // Again, knowing its first line, for the error's line number.
                        let text = if number == 0 {
                            first
                        } else {
                            others[number - 1]
                        };
                        let again = parse_part(
                            text,
                            line_number + 1,
                            index,
                            column,
                            gaps,
                            bad,
                            &mut Vec::new(),
                        );
                        return Err(match again.stop {
                            Some(Stop::Bad(e)) => e,
                            _ => unreachable!("a part parses the same twice"),
                        });
                    }
                }
            }
            let _ = empty.send(block);
        }
        if index.is_none() {
            return Ok(None);
        }
        if values.is_empty() {
            return Err(bad("the file has a header but no samples".into()));
        }
        Ok(Some((values, skipped)))
    })
}

/// Reads `file` in blocks of about `block_size` bytes that end at a line end (the last may
/// not), sending each on `full`; a block sent back on `spare` is reused. Stops at the end of
/// the file, at a read error (sent), or when the receiver is gone.
fn read_blocks(
    mut file: std::fs::File,
    block_size: usize,
    full: &std::sync::mpsc::SyncSender<std::io::Result<Vec<u8>>>,
    spare: &std::sync::mpsc::Receiver<Vec<u8>>,
) {
    use std::io::Read;
    let mut carry: Vec<u8> = Vec::new();
    loop {
        let mut block = spare.try_recv().unwrap_or_default();
        block.clear();
        block.append(&mut carry);
        // Into the block's spare capacity, not zeroed first; fewer bytes than asked for is
        // the end of the file (`read_to_end` reads until the limit or the end).
        block.reserve(block_size);
        let eof = match (&mut file).take(block_size as u64).read_to_end(&mut block) {
            Ok(read) => read < block_size,
            Err(e) => {
                let _ = full.send(Err(e));
                return;
            }
        };
        if !eof {
            // Whole lines only; the rest waits for the next block.
            match block.iter().rposition(|b| *b == b'\n') {
                Some(p) => carry.extend_from_slice(&block[p + 1..]),
                None => {
                    carry = block;
                    continue;
                }
            }
            block.truncate(block.len() - carry.len());
        }
        if (!block.is_empty() && full.send(Ok(block)).is_err()) || eof {
            return;
        }
    }
}

/// `bytes` cut into at most `parts` pieces of about equal length, each ending at a line end
/// (the last may not).
fn cut_at_lines(mut bytes: &[u8], parts: usize) -> Vec<&[u8]> {
    let target = bytes.len().div_ceil(parts.max(1)).max(1);
    let mut out = Vec::with_capacity(parts);
    while !bytes.is_empty() {
        let end = if bytes.len() <= target {
            bytes.len()
        } else {
            memchr::memchr(b'\n', &bytes[target..]).map_or(bytes.len(), |p| target + p + 1)
        };
        let (part, tail) = bytes.split_at(end);
        out.push(part);
        bytes = tail;
    }
    out
}

/// Any CSV the `csv` crate reads (quoted cells and all).
fn read_csv(path: &Path, column: &str, gaps: bool) -> Result<(Vec<f64>, usize)> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        // gyrofx's own CSV files start with a `# generated by` line.
        .comment(Some(b'#'))
        .flexible(true)
        .trim(csv::Trim::All)
        .from_reader(std::io::BufReader::new(file));
    let headers = reader
        .headers()
        .map_err(|e| bad(format!("cannot read the header line: {e}")))?
        .clone();
    if headers.is_empty() || headers.iter().all(|h| h.is_empty()) {
        return Err(bad(
            "the file is empty: expected a header line naming the columns".into(),
        ));
    }
    let index = headers
        .iter()
        .position(|h| h == column)
        .ok_or_else(|| bad(no_column(column, &headers.iter().collect::<Vec<_>>())))?;
    let mut values = Vec::new();
    let mut skipped = 0;
    // Byte records: only the one cell read is checked as UTF-8.
    let mut record = csv::ByteRecord::new();
    loop {
        let more = reader
            .read_byte_record(&mut record)
            .map_err(|e| bad(format!("unreadable record: {e}")))?;
        if !more {
            break;
        }
        let line = record.position().map(|p| p.line()).unwrap_or(0);
        if record.iter().all(|cell| cell.is_empty()) {
            continue;
        }
        let bytes = record.get(index).unwrap_or(b"");
        let cell = std::str::from_utf8(bytes).map_err(|_| {
            bad(format!(
                "line {line}, column {column:?}: the cell is not UTF-8 text"
            ))
        })?;
        match cell_value(cell, line, column, gaps, &bad)? {
            Some(value) => values.push(value),
            None => skipped += 1,
        }
    }
    if values.is_empty() {
        return Err(bad("the file has a header but no samples".into()));
    }
    Ok((values, skipped))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(text: &str) -> tempfile::NamedTempFile {
        let f = tempfile::NamedTempFile::new().unwrap();
        std::fs::write(f.path(), text).unwrap();
        f
    }

    #[test]
    fn reads_the_named_column() {
        let f = file("t,rate_dps\n0,1.5\n1,-2e-3\n\n2,3\n");
        assert_eq!(
            read_column(f.path(), "rate_dps").unwrap(),
            vec![1.5, -2e-3, 3.0]
        );
    }

    #[test]
    fn gaps_are_skipped_and_counted_only_when_asked() {
        let f = file("t,rate_dps\n0,1\n1,\n2,3\n");
        assert_eq!(
            read_column_with_gaps(f.path(), "rate_dps").unwrap(),
            (vec![1.0, 3.0], 1)
        );
        assert!(read_column(f.path(), "rate_dps").is_err());
    }

    #[test]
    fn columns_stream_the_named_columns_row_by_row_as_read_column_reads_each() {
        let text = "# made by hand\nt,a,\"b\",mode\r\n0,1.5,2,1\n\n1,-2e-3,4,0\n2,3,5e1,1\n";
        let f = file(text);
        let mut columns = Columns::open(f.path(), &["mode", "a", "b"]).unwrap();
        let mut rows = Vec::new();
        let mut values = [0.0; 3];
        while let Some(line) = columns.next_row(&mut values).unwrap() {
            rows.push((line, values));
        }
        let lines: Vec<u64> = rows.iter().map(|(l, _)| *l).collect();
        assert_eq!(lines, vec![3, 5, 6]);
        for (i, name) in ["mode", "a", "b"].iter().enumerate() {
            let column: Vec<f64> = rows.iter().map(|(_, v)| v[i]).collect();
            assert_eq!(column, read_column(f.path(), name).unwrap(), "{name}");
        }
        let missing = Columns::open(f.path(), &["a", "c"])
            .err()
            .unwrap()
            .to_string();
        assert!(missing.contains("no column named \"c\"") && missing.contains("t, a, b, mode"));
        let f = file("a,b\n1,2\n3,x\n");
        let mut columns = Columns::open(f.path(), &["a", "b"]).unwrap();
        assert_eq!(columns.next_row(&mut values[..2]).unwrap(), Some(2));
        let bad = columns.next_row(&mut values[..2]).unwrap_err().to_string();
        assert!(
            bad.contains("line 3, column \"b\": \"x\" is not a number"),
            "{bad}"
        );
        let f = file("a,b\n1\n");
        let mut columns = Columns::open(f.path(), &["a", "b"]).unwrap();
        let short = columns.next_row(&mut values[..2]).unwrap_err().to_string();
        assert!(
            short.contains("line 2, column \"b\": the cell is empty"),
            "{short}"
        );
    }

    /// Errors name the line as an editor shows it, comment lines counted.
    #[test]
    fn error_lines_count_comment_lines() {
        let f = file("# generated\nt,rate_dps\n# note\n0,1\n1,x\n");
        let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
        assert!(err.contains("line 5, column"), "{err}");
    }

    /// The first bad line is named whichever block and part it falls in, comment and blank
    /// lines counted; the values before it are read in order.
    #[test]
    fn errors_name_the_physical_line_across_blocks_and_parts() {
        let mut text = String::from("# generated\nt,rate_dps\n");
        let mut want = Vec::new();
        for line in 3..=2000 {
            match line {
                777 => text.push_str("7,x\n"),
                1500 => text.push_str("8,y\n"),
                l if l % 97 == 0 => text.push_str("# note\n"),
                l if l % 89 == 0 => text.push('\n'),
                l => {
                    text.push_str(&format!("{l},{l}.5\n"));
                    want.push(l as f64 + 0.5);
                }
            }
        }
        let f = file(&text);
        for block in [5, 64, 1000, 1 << 20] {
            let err = read_plain_in_blocks(f.path(), "rate_dps", false, block)
                .unwrap_err()
                .to_string();
            assert!(err.contains("line 777, column"), "blocks of {block}: {err}");
        }
        let clean = text.replace("7,x\n", "7,1\n").replace("8,y\n", "8,2\n");
        let f = file(&clean);
        for block in [5, 64, 1000, 1 << 20] {
            let (values, skipped) = read_plain_in_blocks(f.path(), "rate_dps", false, block)
                .unwrap()
                .unwrap();
            assert_eq!(skipped, 0);
            assert_eq!(values.len(), want.len() + 2, "blocks of {block}");
            let without: Vec<f64> = values
                .iter()
                .copied()
                .filter(|v| v.fract() != 0.0)
                .collect();
            assert_eq!(without, want, "blocks of {block}");
        }
    }

    #[test]
    fn comment_lines_are_skipped() {
        let f = file("# generated by gyrofx\nsample,rate_dps\n0,1\n# a note\n1,2\n");
        assert_eq!(read_column(f.path(), "rate_dps").unwrap(), vec![1.0, 2.0]);
    }

    #[test]
    fn errors_name_line_and_column() {
        let cases = [
            (
                "t,rate_dps\n0,1\n1,abc\n",
                "line 3, column \"rate_dps\": \"abc\" is not a number",
            ),
            (
                "t,rate_dps\n0,1\n1,NaN\n",
                "line 3, column \"rate_dps\": NaN is not allowed",
            ),
            ("t,rate_dps\n0,1\n1,inf\n", "line 3"),
            (
                "t,rate_dps\n0,1\n1,\n",
                "line 3, column \"rate_dps\": the cell is empty",
            ),
            (
                "t,rate_dps\n0,1\n1\n",
                "line 3, column \"rate_dps\": the cell is empty",
            ),
            (
                "t,x\n0,1\n",
                "no column named \"rate_dps\"; the header has: t, x",
            ),
            ("", "empty"),
            ("t,rate_dps\n", "no samples"),
        ];
        for (text, want) in cases {
            let f = file(text);
            let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
            assert!(err.contains(want), "{text:?}: {err}");
        }
    }

    /// The plain reader gives what the CSV crate gives (values, gaps, or the same error) on
    /// arbitrary files of plausible pieces: comments, blank and whitespace lines, CRLF, quoted
    /// cells (where it hands over), missing and empty cells, words, non-finite values.
    #[test]
    fn the_plain_reader_agrees_with_the_csv_reader() {
        use proptest::prelude::*;
        let piece = prop_oneof![
            Just("# note\n".to_string()),
            Just("\n".to_string()),
            Just("  \n".to_string()),
            Just(",\n".to_string()),
            Just("1,\n".to_string()),
            Just("2\n".to_string()),
            Just("3,x\n".to_string()),
            Just("4,inf\n".to_string()),
            Just("5,\"6.5\"\n".to_string()),
            Just("7, 8.25 \r\n".to_string()),
            (-1e6f64..1e6).prop_map(|v| format!("9,{v}\n")),
            (-1e6f64..1e6).prop_map(|v| format!("10,{v:e},extra\n")),
            // Beyond the fast decimal path (more than 19 digits, large exponents) or on it.
            any::<f64>()
                .prop_filter("finite", |v| v.is_finite())
                .prop_map(|v| format!("{v},{v:e}\n")),
            (-1e3f64..1e3).prop_map(|v| format!("{v:.3},{v:.6}\n")),
        ];
        let header = prop_oneof![
            Just("t,rate_dps\n"),
            Just(" t , rate_dps \r\n"),
            Just("# generated\nt,rate_dps\n"),
            Just("t,other\n"),
            Just("rate_dps,t\n"),
            Just(""),
        ];
        proptest!(ProptestConfig::with_cases(300), |(
            head in header,
            body in proptest::collection::vec(piece, 0..12),
            gaps in any::<bool>(),
            block in 1usize..40,
        )| {
            let text = format!("{head}{}", body.concat());
            let f = file(&text);
            // The CSV crate does not count comment lines in its line numbers; the plain
            // reader names the physical line: compare the messages without them.
            let unnumbered = |e: Error| {
                let text = e.to_string();
                match text.split_once("line ") {
                    Some((head, tail)) => {
                        format!("{head}line _{}", tail.trim_start_matches(|c: char| c.is_ascii_digit()))
                    }
                    None => text,
                }
            };
            let csv = read_csv(f.path(), "rate_dps", gaps).map_err(unnumbered);
            let ours = read(f.path(), "rate_dps", gaps).map_err(unnumbered);
            prop_assert_eq!(&ours, &csv, "{:?}", text);
            // Blocks cut anywhere (the header, a line, a CRLF) give the same.
            let cut = match read_plain_in_blocks(f.path(), "rate_dps", gaps, block) {
                Ok(Some(result)) => Ok(result),
                Ok(None) => read_csv(f.path(), "rate_dps", gaps),
                Err(e) => Err(e),
            }
            .map_err(unnumbered);
            prop_assert_eq!(cut, csv, "{:?} in blocks of {}", text, block);
        });
    }
}
