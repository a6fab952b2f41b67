//! Reading recorded rate data: one numeric column of a CSV file, streamed.

use std::path::Path;

use crate::error::{Error, Result};

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

fn read(path: &Path, column: &str, gaps: bool) -> Result<(Vec<f64>, usize)> {
    match read_plain(path, column, gaps)? {
        Some(result) => Ok(result),
        None => read_csv(path, column, gaps),
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

/// One part of a block, parsed: its values and gaps, or where it stopped.
struct Part {
    values: Vec<f64>,
    skipped: usize,
    /// A foreign line (hand the file to the CSV reader) or a bad cell, whichever came first.
    stop: Option<Stop>,
}

enum Stop {
    Foreign,
    Bad(Error),
}

/// Parses the data lines of `bytes`, the first being line `first_line` of the file.
fn parse_part(
    bytes: &[u8],
    first_line: u64,
    index: usize,
    column: &str,
    gaps: bool,
    bad: &(dyn Fn(String) -> Error + Sync),
) -> Part {
    let mut part = Part {
        values: Vec::with_capacity(bytes.len() / 8),
        skipped: 0,
        stop: None,
    };
    // Most parts hold no quote, no `\r`, no byte 0xEF (a BOM's first) and are valid UTF-8:
    // checked once for the whole part (memchr and the ASCII fast path), not per line.
    let clean = (!bytes.contains(&b'"') && !bytes.contains(&b'\r') && !bytes.contains(&0xef))
        .then(|| std::str::from_utf8(bytes).ok())
        .flatten();
    let mut take = |offset: usize, line: Line| -> bool {
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
            Ok(Some(value)) => part.values.push(value),
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
            for (offset, line) in text.split_inclusive('\n').enumerate() {
                let line = line.strip_suffix('\n').unwrap_or(line);
                let line = if line.is_empty() || line.starts_with('#') {
                    Line::Skip
                } else {
                    Line::Text(line)
                };
                if !take(offset, line) {
                    break;
                }
            }
        }
        None => {
            for (offset, line) in lines(bytes).enumerate() {
                if !take(offset, classify(line)) {
                    break;
                }
            }
        }
    }
    part
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
fn read_plain_in_blocks(
    path: &Path,
    column: &str,
    gaps: bool,
    block_size: usize,
) -> Result<Option<(Vec<f64>, usize)>> {
    use std::io::Read;
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get().min(8));
    let mut block: Vec<u8> = Vec::with_capacity(block_size + (1 << 16));
    let mut carry: Vec<u8> = Vec::new();
    let mut line_number = 0u64; // lines before the block
    let mut index: Option<usize> = None;
    let mut values = Vec::new();
    let mut skipped = 0;
    let mut eof = false;
    while !eof {
        block.clear();
        block.append(&mut carry);
        let start = block.len();
        block.resize(start + block_size.max(1), 0);
        let mut filled = start;
        while filled < block.len() {
            let read = file
                .read(&mut block[filled..])
                .map_err(|e| Error::io(path, e))?;
            if read == 0 {
                eof = true;
                break;
            }
            filled += read;
        }
        block.truncate(filled);
        // Whole lines only; the rest waits for the next block.
        let cut = if eof {
            block.len()
        } else {
            match block.iter().rposition(|b| *b == b'\n') {
                Some(p) => p + 1,
                None => {
                    carry = std::mem::take(&mut block);
                    continue;
                }
            }
        };
        carry.extend_from_slice(&block[cut..]);
        let mut rest = &block[..cut];
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
            continue;
        };
        // Parts cut at line ends, each with the number of its first line.
        let mut parts = Vec::with_capacity(cores);
        let mut first_line = line_number + 1;
        let target = rest.len().div_ceil(cores).max(1);
        while !rest.is_empty() {
            let end = if rest.len() <= target {
                rest.len()
            } else {
                rest[target..]
                    .iter()
                    .position(|b| *b == b'\n')
                    .map_or(rest.len(), |p| target + p + 1)
            };
            let (part, tail) = rest.split_at(end);
            let count = part.iter().filter(|b| **b == b'\n').count() as u64
                + u64::from(!part.ends_with(b"\n"));
            parts.push((part, first_line));
            first_line += count;
            rest = tail;
        }
        line_number = first_line - 1;
        let bad = &bad;
        let parsed: Vec<Part> = std::thread::scope(|scope| {
            let handles: Vec<_> = parts
                .iter()
                .map(|(part, first)| {
                    scope.spawn(move || parse_part(part, *first, index, column, gaps, bad))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("parsing does not panic"))
                .collect()
        });
        for part in parsed {
            values.extend_from_slice(&part.values);
            skipped += part.skipped;
            match part.stop {
                None => {}
                Some(Stop::Foreign) => return Ok(None),
                Some(Stop::Bad(e)) => return Err(e),
            }
        }
    }
    if index.is_none() {
        return Ok(None);
    }
    if values.is_empty() {
        return Err(bad("the file has a header but no samples".into()));
    }
    Ok(Some((values, skipped)))
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
        ];
        let header = prop_oneof![
            Just("t,rate_dps\n"),
            Just(" t , rate_dps \r\n"),
            Just("# generated\nt,rate_dps\n"),
            Just("t,other\n"),
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
