//! Reading recorded rate data: one numeric column of a CSV file, or several columns row by
//! row ([`Columns`]), streamed, in bounded memory.
//!
//! Every reader of gyrofx takes the same CSV, by the same rules:
//! - The input is a regular file: a pipe, FIFO, device (`/dev/zero`) or folder is refused
//!   at once, since some inputs are read twice and none may be read without end.
//! - Lines end with `\n` or `\r\n`; a line is at most [`MAX_LINE_BYTES`] long; a NUL byte or
//!   a `\r` inside a line is refused (the file is not CSV text).
//! - `#` comment lines (after spaces) are skipped anywhere. The first other line that is not
//!   blank is the header; cells are split at commas and trimmed of spaces and surrounding
//!   quotes (a quoted cell cannot hold a comma).
//! - Every data row has exactly as many cells as the header: a row with more or fewer is an
//!   error naming its line, so a decimal comma (`10,25`) is never read as `10`.
//! - A blank row (only spaces, or only empty cells) inside the data is an error where a value
//!   is required, and a counted gap where gaps are allowed ([`read_column_with_gaps`]), as an
//!   empty cell is: a blank line never silently shifts the samples after it. Blank lines at the
//!   end of the file are ignored.
//! - A column read holds at most [`MAX_VALUES`] values.

use std::path::Path;

use crate::error::{Error, Result};

mod decimal;
mod lines;
mod plain;

use lines::{cells, Kind, Lines};

/// The longest line a reader takes, its line end not counted: 1 MiB. A CSV line of numbers is
/// a few hundred bytes; a longer one is a file without line ends (or not a CSV file at all),
/// refused before it fills memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// The most values one column read holds: 2^28 (268 435 456, 2 GiB as f64), 15 days of a
/// 200 Hz record; a larger record is refused before it exhausts memory.
pub const MAX_VALUES: usize = 1 << 28;

/// The largest text file read whole (a config): 1 MiB.
pub const MAX_TEXT_BYTES: u64 = 1 << 20;

/// Opens the file at `path` for reading, refusing anything but a regular file.
///
/// # Errors
/// [`Error::Io`] when it cannot be opened; [`Error::Input`] when it is a folder, a pipe, a
/// FIFO, a socket or a device.
pub fn open(path: &Path) -> Result<std::fs::File> {
    // Checked before opening: opening a FIFO waits for a writer.
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        return std::fs::File::open(path).map_err(|e| Error::io(path, e));
    }
    let what = file_kind(&meta);
    Err(Error::Input {
        path: path.to_path_buf(),
        message: format!(
            "is {what}, not a regular file: gyrofx reads its inputs from files (some twice, \
             and none without end); save the data to a file first"
        ),
    })
}

/// What a file that is not a regular file is, in words.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = meta.file_type();
        if kind.is_fifo() {
            return "a pipe or FIFO";
        }
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

/// The whole text of the file at `path` (a config), at most [`MAX_TEXT_BYTES`] long.
///
/// # Errors
/// As [`open`]; [`Error::Input`] for a longer file, a NUL byte or text that is not UTF-8.
pub fn read_text(path: &Path) -> Result<String> {
    use std::io::Read;
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let mut bytes = Vec::new();
    open(path)?
        .take(MAX_TEXT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > MAX_TEXT_BYTES {
        return Err(bad(format!(
            "is longer than {MAX_TEXT_BYTES} bytes: gyrofx reads text files (configs) of at \
             most {MAX_TEXT_BYTES} bytes"
        )));
    }
    if let Some(at) = memchr::memchr(0, &bytes) {
        return Err(bad(format!(
            "byte {} is a NUL byte: this is not a text file",
            at + 1
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        bad(format!(
            "is not UTF-8 text (byte {} is not)",
            e.utf8_error().valid_up_to() + 1
        ))
    })
}

/// Reads the column `column` (by header name) of the CSV file at `path` as f64 values, by the
/// module's rules (the first row that is neither blank nor a `#` comment is the header). Most
/// files are read in blocks parsed on every core; any file holding quotes, a byte-order mark,
/// `\r` or text that is not UTF-8 is read line by line, with the same result.
///
/// # Errors
/// [`Error::Input`] naming the line and column of a missing, non-numeric or non-finite cell, a
/// row whose cell count is not the header's, a blank row inside the data, a missing column
/// (listing those present), an empty file, a line too long, a file that is not text or not a
/// regular file, or more than [`MAX_VALUES`] values; [`Error::Io`] when the file cannot be read.
pub fn read_column(path: &Path, column: &str) -> Result<Vec<f64>> {
    read(path, column, false).map(|(values, _)| values)
}

/// [`read_column`], but rows whose cell is empty and blank rows (gaps, e.g. a reset row in
/// gyrofx's vector CSVs) are skipped instead of refused. Returns the values and the number of
/// rows skipped, which the caller reports.
///
/// # Errors
/// As [`read_column`], except for empty cells and blank rows.
pub fn read_column_with_gaps(path: &Path, column: &str) -> Result<(Vec<f64>, usize)> {
    read(path, column, true)
}

/// The first `count` values of the column `column` of the CSV file at `path`, read line by
/// line up to them (by [`read_column`]'s rules; the rest of the file is not read). Fewer
/// values when the file ends first.
///
/// # Errors
/// As [`read_column`], for the lines read.
pub fn read_column_prefix(path: &Path, column: &str, count: usize) -> Result<Vec<f64>> {
    let mut columns = Columns::open(path, &[column])?;
    let mut values = Vec::with_capacity(count.min(1 << 20));
    let mut value = [0.0];
    while values.len() < count {
        match columns.next_row(&mut value)? {
            Some(_) => values.push(value[0]),
            None => break,
        }
    }
    Ok(values)
}

/// The header of the CSV file at `path`: the cells of its first line that is neither blank nor
/// a `#` comment, trimmed.
///
/// # Errors
/// As [`open`]; [`Error::Input`] when it has no header line or its first lines break the
/// module's rules.
pub fn read_header(path: &Path) -> Result<Vec<String>> {
    Ok(Columns::open(path, &[])?.header)
}

fn read(path: &Path, column: &str, gaps: bool) -> Result<(Vec<f64>, usize)> {
    match plain::read(path, column, gaps)? {
        Some(result) => Ok(result),
        None => read_by_lines(path, column, gaps),
    }
}

/// The general reader: line by line through [`Columns`], for any file the plain reader hands
/// over (and the reference the plain reader is tested against).
fn read_by_lines(path: &Path, column: &str, gaps: bool) -> Result<(Vec<f64>, usize)> {
    let mut columns = Columns::open(path, &[column])?;
    let mut values = Vec::new();
    let mut skipped = 0;
    let mut value = [0.0];
    while let Some(row) = columns.next_record(&mut value, gaps)? {
        match row {
            Row::Values(_) => {
                if values.len() == MAX_VALUES {
                    return Err(columns.lines.error(too_many_values()));
                }
                values.push(value[0]);
            }
            Row::Gaps { count, .. } => skipped += count,
        }
    }
    if values.is_empty() {
        return Err(columns.lines.error(no_samples()));
    }
    Ok((values, skipped))
}

/// The message for a file with a header and no value.
fn no_samples() -> String {
    "the file has a header but no samples".into()
}

/// The message for a column of more than [`MAX_VALUES`] values.
fn too_many_values() -> String {
    format!(
        "holds more than {MAX_VALUES} values in the column: gyrofx reads at most \
         {MAX_VALUES} samples of a record (cut it into parts)"
    )
}

/// The message for a blank row inside the data, where a value is required.
fn blank_row(line: u64) -> String {
    format!(
        "line {line} is blank (no value) but more data follows: a blank row would shift every \
         later sample; remove it, or give the missing value (blank lines at the end of the file \
         are ignored)"
    )
}

/// The message for a row of `found` cells under a header of `header.len()`, with a hint when
/// the extra cells look like the fractions of decimal commas.
fn cell_count(line: u64, found: usize, header: &[String], row: &[&[u8]]) -> String {
    let plural = |n: usize| if n == 1 { "cell" } else { "cells" };
    let mut message = format!(
        "line {line} has {found} {} but the header has {} ({}): every row must have one cell per \
         column",
        plural(found),
        header.len(),
        header.join(", "),
    );
    if found > header.len() && looks_like_decimal_commas(row) {
        message.push_str(
            "; the row looks like numbers written with a decimal comma (`10,25`): gyrofx reads \
             a decimal point (`10.25`) and a comma between cells",
        );
    }
    message
}

/// Whether some cell after the first is all digits and follows a cell that is a whole number:
/// `10,25` read as two cells.
fn looks_like_decimal_commas(row: &[&[u8]]) -> bool {
    // A quoted decimal comma (`"10,25"`) leaves a quote on each half.
    let unquoted =
        |cell: &[u8]| -> Vec<u8> { cell.iter().copied().filter(|b| *b != b'"').collect() };
    let whole = |cell: &[u8]| {
        let cell = unquoted(cell);
        let digits = cell.strip_prefix(b"-").unwrap_or(&cell);
        !digits.is_empty() && digits.iter().all(u8::is_ascii_digit)
    };
    let fraction = |cell: &[u8]| {
        let cell = unquoted(cell);
        !cell.is_empty() && cell.iter().all(u8::is_ascii_digit)
    };
    row.windows(2)
        .any(|pair| whole(pair[0]) && fraction(pair[1]))
}

/// Chosen columns of a CSV file, row by row, without holding the file: for inputs that name
/// several columns at once (a recording's two gyros and its mode), by the module's rules. At
/// most 8 columns at a time.
pub struct Columns<R: std::io::BufRead> {
    lines: Lines<R>,
    names: Vec<String>,
    indices: Vec<usize>,
    header: Vec<String>,
    /// Blank rows read since the last data row: the first one's line and how many.
    blank: Option<(u64, usize)>,
    /// The current line is a data row not yet handed out (it waited for the blank rows before
    /// it to be handed out as gaps).
    held: bool,
}

impl Columns<std::io::BufReader<std::fs::File>> {
    /// The columns `names` (header names) of the CSV file at `path`.
    ///
    /// # Errors
    /// As [`open`]; [`Error::Input`] for an empty file or a missing column (listing those
    /// present).
    pub fn open(path: &Path, names: &[&str]) -> Result<Self> {
        Columns::from_reader(path, std::io::BufReader::new(open(path)?), names)
    }
}

/// One step of [`Columns::next_record`].
enum Row {
    /// A data row's values, with its line.
    Values(u64),
    /// Rows skipped as gaps: a run of blank rows, or a row with an empty cell.
    Gaps { count: usize },
}

impl<R: std::io::BufRead> Columns<R> {
    /// As [`Columns::open`] on the bytes of `reader`; `path` names them in errors.
    ///
    /// # Errors
    /// As [`Columns::open`].
    pub fn from_reader(path: &Path, reader: R, names: &[&str]) -> Result<Self> {
        assert!(names.len() <= 8, "at most 8 columns at a time");
        let mut lines = Lines::new(path, reader);
        loop {
            match lines.next()? {
                Kind::End => {
                    return Err(lines.error(
                        "the file is empty: expected a header line naming the columns".into(),
                    ))
                }
                Kind::Comment | Kind::Blank => continue,
                Kind::Text => break,
            }
        }
        let header: Vec<String> = cells(lines.line())
            .map(|c| String::from_utf8_lossy(c).into_owned())
            .collect();
        let indices = names
            .iter()
            .map(|name| {
                header.iter().position(|h| h == name).ok_or_else(|| {
                    lines.error(no_column(
                        name,
                        &header.iter().map(String::as_str).collect::<Vec<_>>(),
                    ))
                })
            })
            .collect::<Result<Vec<usize>>>()?;
        Ok(Columns {
            lines,
            names: names.iter().map(|n| n.to_string()).collect(),
            indices,
            header,
            blank: None,
            held: false,
        })
    }

    /// The header's cells.
    pub fn header(&self) -> &[String] {
        &self.header
    }

    /// The next data row's values into `values` (one per column, in the order named); its line
    /// number, or `None` at the end of the file.
    ///
    /// # Errors
    /// A bad cell, a row whose cell count is not the header's, a blank row before more data, or
    /// an unreadable file, naming the line (and column).
    pub fn next_row(&mut self, values: &mut [f64]) -> Result<Option<u64>> {
        match self.next_record(values, false)? {
            Some(Row::Values(line)) => Ok(Some(line)),
            Some(Row::Gaps { .. }) => unreachable!("no gaps unless asked for"),
            None => Ok(None),
        }
    }

    /// The next data row, or with `gaps` the next run of gaps (blank rows, or a row whose
    /// wanted cell is empty).
    fn next_record(&mut self, values: &mut [f64], gaps: bool) -> Result<Option<Row>> {
        loop {
            if self.held {
                self.held = false;
                return self.parse_row(values, gaps).map(Some);
            }
            match self.lines.next()? {
                Kind::End => return Ok(None),
                Kind::Comment => {}
                Kind::Blank => {
                    let line = self.lines.number();
                    self.blank.get_or_insert((line, 0)).1 += 1;
                }
                Kind::Text => {
                    if let Some((line, count)) = self.blank.take() {
                        if !gaps {
                            return Err(self.lines.error(blank_row(line)));
                        }
                        self.held = true;
                        return Ok(Some(Row::Gaps { count }));
                    }
                    return self.parse_row(values, gaps).map(Some);
                }
            }
        }
    }

    /// The current line's wanted cells into `values`.
    fn parse_row(&self, values: &mut [f64], gaps: bool) -> Result<Row> {
        let line = self.lines.number();
        let row: Vec<&[u8]> = cells(self.lines.line()).collect();
        if row.len() != self.header.len() {
            return Err(self
                .lines
                .error(cell_count(line, row.len(), &self.header, &row)));
        }
        let bad = |message: String| self.lines.error(message);
        for ((value, index), name) in values.iter_mut().zip(&self.indices).zip(&self.names) {
            let cell = std::str::from_utf8(row[*index]).map_err(|_| {
                bad(format!(
                    "line {line}, column {name:?}: the cell is not UTF-8 text"
                ))
            })?;
            match cell_value(cell, line, name, gaps, &bad)? {
                Some(v) => *value = v,
                None => return Ok(Row::Gaps { count: 1 }),
            }
        }
        Ok(Row::Values(line))
    }

    /// The reader underneath.
    pub fn into_inner(self) -> R {
        self.lines.into_inner()
    }
}

/// What one cell holds: a value, or `None` for a gap that is skipped.
fn cell_value(
    cell: &str,
    line: u64,
    column: &str,
    gaps: bool,
    bad: &dyn Fn(String) -> Error,
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

#[cfg(test)]
mod tests;
