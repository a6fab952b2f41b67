//! The common case of a column read without a line-by-line pass: unquoted cells, `\n` or
//! `\r\n` line ends, no byte-order mark, UTF-8 text. The file is read in blocks cut at line
//! ends, each block's lines parsed on every core; it gives exactly what the general reader
//! ([`super::read_by_lines`]) gives, and hands the file over to it (`None`) as soon as it meets
//! anything else (a quote, a lone `\r`, a BOM, a NUL byte, a line too long, bytes that are not
//! UTF-8), so that reader's precise errors name the line.

use std::path::Path;

use crate::error::{Error, Result};

use super::lines::{classify, Kind};
use super::{
    blank_row, cell_count, cell_value, decimal, no_column, no_samples, too_many_values,
    MAX_LINE_BYTES, MAX_VALUES,
};

/// Bytes read at a time (plus the partial line carried over).
const BLOCK: usize = 8 << 20;

/// What [`read`] found: the values and the gaps skipped, or `None` to hand the file over.
type Read = Option<(Vec<f64>, usize)>;

/// The column `column` of the file at `path`, or `None` when the general reader must read it.
pub(super) fn read(path: &Path, column: &str, gaps: bool) -> Result<Read> {
    read_in_blocks(path, column, gaps, BLOCK)
}

/// The header's facts a data line is parsed with.
#[derive(Clone, Copy)]
struct Layout<'a> {
    /// The wanted cell's index.
    index: usize,
    /// Commas in a row of the header's cell count.
    commas: usize,
    column: &'a str,
    header: &'a [String],
    gaps: bool,
}

/// What one part of a block held, once parsed (its values went to the vector it was given).
#[derive(Default)]
struct Part {
    skipped: usize,
    /// Lines gone through: all of the part's unless it stopped.
    lines: u64,
    /// Whether the part holds a data row (which ends a run of blank rows before the part).
    has_data: bool,
    /// Blank rows at the part's end, not yet followed by data: the first one's offset in the
    /// part (0 for its first line), and how many.
    blank: Option<(u64, usize)>,
    /// A line the general reader must read, or a bad one, whichever came first.
    stop: Option<Stop>,
}

enum Stop {
    Foreign,
    Bad(Error),
}

impl Part {
    /// A data row at `offset` ends the blank rows before it: gaps when gaps are allowed, else
    /// the error of the first. False when the part stops there.
    fn end_blank_rows(
        &mut self,
        first_line: u64,
        gaps: bool,
        bad: &dyn Fn(String) -> Error,
    ) -> bool {
        self.has_data = true;
        if let Some((offset, count)) = self.blank.take() {
            if !gaps {
                self.stop = Some(Stop::Bad(bad(blank_row(first_line + offset))));
                return false;
            }
            self.skipped += count;
        }
        true
    }

    /// Takes one line (without its line end) at `offset` by the general rules; false when the
    /// part stops there.
    fn take(
        &mut self,
        line: &[u8],
        offset: u64,
        first_line: u64,
        layout: Layout,
        bad: &dyn Fn(String) -> Error,
        values: &mut Vec<f64>,
    ) -> bool {
        let Some(text) = plain_text(line) else {
            self.stop = Some(Stop::Foreign);
            return false;
        };
        match classify(line) {
            Kind::Comment | Kind::End => return true,
            Kind::Blank => {
                self.blank.get_or_insert((offset, 0)).1 += 1;
                return true;
            }
            Kind::Text => {}
        }
        let number = first_line + offset;
        if !self.end_blank_rows(first_line, layout.gaps, bad) {
            return false;
        }
        let row: Vec<&str> = text.split(',').map(str::trim).collect();
        if row.len() != layout.header.len() {
            let cells: Vec<&[u8]> = row.iter().map(|c| c.as_bytes()).collect();
            self.stop = Some(Stop::Bad(bad(cell_count(
                number,
                row.len(),
                layout.header,
                &cells,
            ))));
            return false;
        }
        match cell_value(row[layout.index], number, layout.column, layout.gaps, bad) {
            Ok(Some(value)) => values.push(value),
            Ok(None) => self.skipped += 1,
            Err(e) => {
                self.stop = Some(Stop::Bad(e));
                return false;
            }
        }
        true
    }
}

/// A line's text, or `None` for one the general reader must read: a line too long, a quote,
/// a `\r`, a BOM, a NUL byte, bytes that are not UTF-8.
fn plain_text(line: &[u8]) -> Option<&str> {
    if line.len() > MAX_LINE_BYTES
        || line.contains(&b'"')
        || line.contains(&b'\r')
        || line.contains(&0)
        || line.starts_with(&[0xef, 0xbb, 0xbf])
    {
        return None;
    }
    std::str::from_utf8(line).ok()
}

/// Parses the lines of `bytes`, the first being line `first_line` of the file (0 when not yet
/// known: only errors need it), pushing their values onto `values`.
fn parse_part(
    bytes: &[u8],
    first_line: u64,
    layout: Layout,
    bad: &(dyn Fn(String) -> Error + Sync),
    values: &mut Vec<f64>,
) -> Part {
    let mut part = Part::default();
    // Most parts hold no quote, `\r`, NUL or byte 0xEF (a BOM's first) and are valid UTF-8:
    // checked once for the whole part (memchr and the ASCII fast path), not per line.
    let clean = !bytes.contains(&b'"')
        && !bytes.contains(&b'\r')
        && !bytes.contains(&0)
        && !bytes.contains(&0xef)
        && std::str::from_utf8(bytes).is_ok();
    let mut start = 0;
    let mut offset = 0;
    while start < bytes.len() {
        let end = memchr::memchr(b'\n', &bytes[start..]).map_or(bytes.len(), |p| start + p);
        let mut line = &bytes[start..end];
        start = end + 1;
        offset += 1;
        if !clean && line.last() == Some(&b'\r') {
            line = &line[..line.len() - 1];
        }
        // The usual row: the header's cell count and a plain decimal in the wanted cell,
        // parsed where it stands.
        if clean && line.len() <= MAX_LINE_BYTES {
            if let Some(value) = plain_value(line, layout) {
                if !part.end_blank_rows(first_line, layout.gaps, bad) {
                    break;
                }
                values.push(value);
                continue;
            }
        }
        if !part.take(line, offset - 1, first_line, layout, bad, values) {
            break;
        }
    }
    part.lines = offset;
    part
}

/// The wanted cell's value when `line` has the header's cell count and the cell is a plain
/// decimal the fast path reads exactly; `None` for anything else.
fn plain_value(line: &[u8], layout: Layout) -> Option<f64> {
    // One pass over the commas: up to the wanted cell, then counting the rest.
    let mut commas = memchr::memchr_iter(b',', line);
    let cell = if layout.index == 0 {
        0
    } else {
        commas.nth(layout.index - 1)? + 1
    };
    if layout.index + commas.count() != layout.commas {
        return None;
    }
    let (value, used) = decimal::parse_prefix(&line[cell..])?;
    matches!(line.get(cell + used), None | Some(b',')).then_some(value)
}

/// The lines of `bytes`, each with its `\n` (the last one may lack it).
fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    bytes.split_inclusive(|b| *b == b'\n')
}

/// [`read`] with blocks of `block_size` bytes (tests cut files everywhere with small ones).
///
/// A reader thread reads the next block while the current one is parsed. Each block is cut
/// into one part per core at line ends; the first part's values go straight onto the result,
/// the others' through a buffer each that is kept from block to block. A part does not know
/// its first line number until the parts before it are counted: when one stops at a bad
/// cell, it is parsed again with its line number so the error names the file's line.
pub(super) fn read_in_blocks(
    path: &Path,
    column: &str,
    gaps: bool,
    block_size: usize,
) -> Result<Read> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let file = super::open(path)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get().min(8));
    let (full, blocks) = std::sync::mpsc::sync_channel::<std::io::Result<Option<Vec<u8>>>>(1);
    let (empty, spare) = std::sync::mpsc::channel::<Vec<u8>>();
    std::thread::scope(|scope| {
        scope.spawn(move || read_blocks(file, block_size.max(1), &full, &spare));
        let mut line_number = 0u64; // lines before the block
        let mut header: Option<(Vec<String>, usize)> = None;
        let mut values = Vec::new();
        let mut buffers: Vec<Vec<f64>> = vec![Vec::new(); cores.saturating_sub(1)];
        let mut skipped = 0;
        // Blank rows not yet followed by data: the first one's line and how many.
        let mut blank: Option<(u64, usize)> = None;
        for block in blocks {
            let Some(block) = block.map_err(|e| Error::io(path, e))? else {
                return Ok(None);
            };
            let mut rest = &block[..];
            // The header: the first line that is neither blank nor a comment.
            while header.is_none() {
                let Some(line) = lines(rest).next() else {
                    break;
                };
                rest = &rest[line.len()..];
                line_number += 1;
                let line = line.strip_suffix(b"\n").unwrap_or(line);
                let line = line.strip_suffix(b"\r").unwrap_or(line);
                let Some(text) = plain_text(line) else {
                    return Ok(None);
                };
                if classify(line) == Kind::Text {
                    let names: Vec<String> =
                        text.split(',').map(|h| h.trim().to_string()).collect();
                    let index = names.iter().position(|h| h == column).ok_or_else(|| {
                        bad(no_column(
                            column,
                            &names.iter().map(String::as_str).collect::<Vec<_>>(),
                        ))
                    })?;
                    header = Some((names, index));
                }
            }
            let Some((names, index)) = &header else {
                let _ = empty.send(block);
                continue;
            };
            let layout = Layout {
                index: *index,
                commas: names.len() - 1,
                column,
                header: names,
                gaps,
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
                        scope.spawn(move || parse_part(part, 0, layout, bad, buffer))
                    })
                    .collect();
                let mut parsed = vec![parse_part(first, 0, layout, bad, &mut values)];
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
                if part.has_data {
                    if let Some((line, count)) = blank.take() {
                        if !gaps {
                            return Err(bad(blank_row(line)));
                        }
                        skipped += count;
                    }
                }
                skipped += part.skipped;
                match part.stop {
                    None => {}
                    Some(Stop::Foreign) => return Ok(None),
                    Some(Stop::Bad(_)) => {
                        // Again, knowing its first line, for the error's line number.
                        let text = if number == 0 {
                            first
                        } else {
                            others[number - 1]
                        };
                        let again = parse_part(text, line_number + 1, layout, bad, &mut Vec::new());
                        return Err(match again.stop {
                            Some(Stop::Bad(e)) => e,
                            _ => unreachable!("a part parses the same twice"),
                        });
                    }
                }
                if let Some((offset, count)) = part.blank {
                    blank.get_or_insert((line_number + offset + 1, 0)).1 += count;
                }
                line_number += part.lines;
            }
            if values.len() > MAX_VALUES {
                return Err(bad(too_many_values()));
            }
            let _ = empty.send(block);
        }
        if header.is_none() {
            return Ok(None);
        }
        if values.is_empty() {
            return Err(bad(no_samples()));
        }
        Ok(Some((values, skipped)))
    })
}

/// Reads `file` in blocks of about `block_size` bytes that end at a line end (the last may
/// not), sending each on `full`; a block sent back on `spare` is reused. Sends `None` (hand
/// the file to the general reader) for a NUL byte or a line longer than [`MAX_LINE_BYTES`],
/// so that memory stays bounded on a file without line ends. Stops at the end of the file, at
/// a read error (sent), or when the receiver is gone.
fn read_blocks(
    mut file: std::fs::File,
    block_size: usize,
    full: &std::sync::mpsc::SyncSender<std::io::Result<Option<Vec<u8>>>>,
    spare: &std::sync::mpsc::Receiver<Vec<u8>>,
) {
    use std::io::Read;
    let mut carry: Vec<u8> = Vec::new();
    loop {
        let mut block = spare.try_recv().unwrap_or_default();
        block.clear();
        block.append(&mut carry);
        let carried = block.len();
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
        if block[carried..].contains(&0) {
            let _ = full.send(Ok(None));
            return;
        }
        if !eof {
            // Whole lines only; the rest waits for the next block.
            match memchr::memrchr(b'\n', &block) {
                Some(p) => carry.extend_from_slice(&block[p + 1..]),
                None => {
                    carry = block;
                    if carry.len() > MAX_LINE_BYTES + 2 {
                        let _ = full.send(Ok(None));
                        return;
                    }
                    continue;
                }
            }
            block.truncate(block.len() - carry.len());
        }
        if (!block.is_empty() && full.send(Ok(Some(block))).is_err()) || eof {
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
