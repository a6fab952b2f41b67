//! Reading recorded rate data: one numeric column of a CSV file, streamed.

use std::path::Path;

use crate::error::{Error, Result};

/// Reads the column `column` (by header name) of the CSV file at `path` as f64 values.
///
/// The first row is the header. Blank lines are skipped. Records are read one at a time, so
/// large files are not held twice.
///
/// # Errors
/// [`Error::Input`] naming the line and column of a missing, non-numeric or non-finite cell, a
/// missing column (listing those present), or an empty file; [`Error::Io`] when the file
/// cannot be opened.
pub fn read_column(path: &Path, column: &str) -> Result<Vec<f64>> {
    let bad = |message: String| Error::Input {
        path: path.to_path_buf(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
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
    let index = headers.iter().position(|h| h == column).ok_or_else(|| {
        bad(format!(
            "no column named {column:?}; the header has: {}",
            headers.iter().collect::<Vec<_>>().join(", ")
        ))
    })?;
    let mut values = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        let more = reader
            .read_record(&mut record)
            .map_err(|e| bad(format!("unreadable record: {e}")))?;
        if !more {
            break;
        }
        let line = record.position().map(|p| p.line()).unwrap_or(0);
        if record.iter().all(|cell| cell.is_empty()) {
            continue;
        }
        let cell = record.get(index).unwrap_or("");
        if cell.is_empty() {
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
        values.push(value);
    }
    if values.is_empty() {
        return Err(bad("the file has a header but no samples".into()));
    }
    Ok(values)
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
}
