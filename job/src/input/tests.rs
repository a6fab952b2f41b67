use super::*;

fn file(text: &str) -> tempfile::NamedTempFile {
    bytes_file(text.as_bytes())
}

fn bytes_file(bytes: &[u8]) -> tempfile::NamedTempFile {
    let f = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(f.path(), bytes).unwrap();
    f
}

fn error_of(text: &str, gaps: bool) -> String {
    let f = file(text);
    read(f.path(), "rate_dps", gaps).unwrap_err().to_string()
}

#[test]
fn reads_the_named_column() {
    let f = file("t,rate_dps\n0,1.5\n1,-2e-3\n2,3\n\n \n");
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

/// A blank row inside the data would shift every later sample: an error where values are
/// required, counted gaps where gaps are allowed; at the end of the file it is ignored.
#[test]
fn blank_rows_inside_the_data_are_refused_or_counted_never_dropped() {
    for text in [
        "rate_dps\n1\n\n2\n",
        "rate_dps\n1\n  \n2\n",
        "t,rate_dps\n0,1\n,\n1,2\n",
    ] {
        let err = error_of(text, false);
        assert!(err.contains("line 3 is blank"), "{text:?}: {err}");
        let f = file(text);
        assert_eq!(
            read_column_with_gaps(f.path(), "rate_dps").unwrap(),
            (vec![1.0, 2.0], 1),
            "{text:?}"
        );
    }
    let f = file("rate_dps\n1\n\n# note\n\n2\n3\n\n\n");
    assert_eq!(
        read_column_with_gaps(f.path(), "rate_dps").unwrap(),
        (vec![1.0, 2.0, 3.0], 2)
    );
    let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
    assert!(err.contains("line 3 is blank"), "{err}");
    let f = file("# comment\n\nrate_dps\n\n1\n2\n\n");
    let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
    assert!(err.contains("line 4 is blank"), "{err}");
}

/// A row with more or fewer cells than the header is an error naming its line; a decimal
/// comma gets a hint.
#[test]
fn rows_must_have_the_headers_cell_count() {
    let err = error_of("rate_dps\n10.5\n10,25\n", false);
    assert!(
        err.contains("line 3 has 2 cells but the header has 1 (rate_dps)")
            && err.contains("decimal comma"),
        "{err}"
    );
    let err = error_of("t,rate_dps\n0,\"10,25\"\n", true);
    assert!(
        err.contains("line 2 has 3 cells") && err.contains("decimal comma"),
        "{err}"
    );
    let err = error_of("t,rate_dps,x\n0,1,2\n1,2\n", true);
    assert!(
        err.contains("line 3 has 2 cells but the header has 3 (t, rate_dps, x)")
            && !err.contains("decimal"),
        "{err}"
    );
    let err = error_of("t,rate_dps\n0,1.5,abc\n", false);
    assert!(
        err.contains("line 2 has 3 cells") && !err.contains("decimal"),
        "{err}"
    );
}

#[test]
fn columns_stream_the_named_columns_row_by_row_as_read_column_reads_each() {
    let text = "# made by hand\nt,a,\"b\",mode\r\n0,1.5,2,1\n# note\n1,-2e-3,4,0\n2,3,5e1,1\n\n";
    let f = file(text);
    let mut columns = Columns::open(f.path(), &["mode", "a", "b"]).unwrap();
    assert_eq!(columns.header(), ["t", "a", "b", "mode"]);
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
        short.contains("line 2 has 1 cell but the header has 2"),
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

/// The first bad line is named whichever block and part it falls in, comment lines counted;
/// the values before it are read in order.
#[test]
fn errors_name_the_physical_line_across_blocks_and_parts() {
    let mut text = String::from("# generated\nt,rate_dps\n");
    let mut want = Vec::new();
    for line in 3..=2000 {
        match line {
            777 => text.push_str("7,x\n"),
            1500 => text.push_str("8,y\n"),
            l if l % 97 == 0 => text.push_str("# note\n"),
            l if l % 89 == 0 => text.push_str("  # indented note\n"),
            l => {
                text.push_str(&format!("{l},{l}.5\n"));
                want.push(l as f64 + 0.5);
            }
        }
    }
    let f = file(&text);
    for block in [5, 64, 1000, 1 << 20] {
        let err = plain::read_in_blocks(f.path(), "rate_dps", false, block)
            .unwrap_err()
            .to_string();
        assert!(err.contains("line 777, column"), "blocks of {block}: {err}");
    }
    let clean = text.replace("7,x\n", "7,1\n").replace("8,y\n", "8,2\n");
    let f = file(&clean);
    for block in [5, 64, 1000, 1 << 20] {
        let (values, skipped) = plain::read_in_blocks(f.path(), "rate_dps", false, block)
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
            "line 3 has 1 cell but the header has 2",
        ),
        (
            "t,x\n0,1\n",
            "no column named \"rate_dps\"; the header has: t, x",
        ),
        ("", "empty"),
        ("\n\n# only a comment\n", "empty"),
        ("t,rate_dps\n", "no samples"),
        ("t,rate_dps\r0,1\r", "line 1 holds a carriage return"),
    ];
    for (text, want) in cases {
        let err = error_of(text, false);
        assert!(err.contains(want), "{text:?}: {err}");
    }
}

/// A file without line ends, or of NUL bytes, is refused on its first line in bounded memory,
/// by both readers and by the header reader; so is a file that is not a regular file.
#[test]
fn files_that_are_not_csv_text_are_refused_early() {
    let long = vec![b'7'; 3 * MAX_LINE_BYTES];
    let f = bytes_file(&long);
    for err in [
        read_column(f.path(), "rate_dps").unwrap_err().to_string(),
        read_header(f.path()).unwrap_err().to_string(),
    ] {
        assert!(err.contains("line 1 is longer than 1048576 bytes"), "{err}");
    }
    let mut late = b"t,rate_dps\n0,1\n".to_vec();
    late.extend(std::iter::repeat_n(b'1', 2 * MAX_LINE_BYTES));
    let f = bytes_file(&late);
    for block in [1 << 10, 1 << 20, 8 << 20] {
        let handed_over = plain::read_in_blocks(f.path(), "rate_dps", false, block).unwrap();
        assert!(handed_over.is_none(), "blocks of {block}");
    }
    let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
    assert!(err.contains("line 3 is longer"), "{err}");
    let f = bytes_file(&vec![0u8; 2 * MAX_LINE_BYTES]);
    let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
    assert!(err.contains("line 1, byte 1 is a NUL byte"), "{err}");
    let f = bytes_file(b"t,rate_dps\n0,1\n1,2\0\n");
    let err = read_column(f.path(), "rate_dps").unwrap_err().to_string();
    assert!(err.contains("line 3, byte 4 is a NUL byte"), "{err}");
    #[cfg(unix)]
    for path in ["/dev/zero", "/dev/null"] {
        let err = read_column(Path::new(path), "rate_dps")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("is a character device, not a regular file"),
            "{err}"
        );
        let err = read_text(Path::new(path)).unwrap_err().to_string();
        assert!(err.contains("is a character device"), "{err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let err = read_header(dir.path()).unwrap_err().to_string();
    assert!(err.contains("is a folder, not a regular file"), "{err}");
}

#[test]
fn text_files_are_read_whole_up_to_their_limit() {
    let f = file("seed = 1\n");
    assert_eq!(read_text(f.path()).unwrap(), "seed = 1\n");
    let f = bytes_file(&vec![b'#'; MAX_TEXT_BYTES as usize + 1]);
    let err = read_text(f.path()).unwrap_err().to_string();
    assert!(err.contains("is longer than 1048576 bytes"), "{err}");
    let f = bytes_file(b"seed = 1\n\0");
    assert!(read_text(f.path())
        .unwrap_err()
        .to_string()
        .contains("byte 10 is a NUL byte"));
    let f = bytes_file(b"seed = \xff\n");
    assert!(read_text(f.path())
        .unwrap_err()
        .to_string()
        .contains("not UTF-8"));
}

#[test]
fn a_prefix_reads_only_the_rows_it_needs() {
    let f = file("rate_dps\n1\n2\n3\nx\n");
    assert_eq!(
        read_column_prefix(f.path(), "rate_dps", 2).unwrap(),
        vec![1.0, 2.0]
    );
    assert!(read_column_prefix(f.path(), "rate_dps", 4).is_err());
    let f = file("rate_dps\n1\n2\n");
    assert_eq!(
        read_column_prefix(f.path(), "rate_dps", 5).unwrap(),
        vec![1.0, 2.0]
    );
}

#[test]
fn decimal_commas_are_recognised_only_as_such() {
    let row = |cells: &[&str]| -> bool {
        let bytes: Vec<&[u8]> = cells.iter().map(|c| c.as_bytes()).collect();
        looks_like_decimal_commas(&bytes)
    };
    assert!(row(&["10", "25"]));
    assert!(row(&["0", "-3", "125"]));
    assert!(!row(&["1.5", "x"]));
    assert!(!row(&["1", ""]));
    assert!(!row(&["abc", "25"]));
}

/// The plain reader gives what the general reader gives (values, gaps, or the same error,
/// line numbers included) on arbitrary files of plausible pieces: comments, blank and
/// whitespace lines, CRLF, quoted cells (where it hands over), rows of too few or too many
/// cells, empty cells, words, non-finite values, NUL bytes and lone carriage returns.
#[test]
fn the_plain_reader_agrees_with_the_general_reader() {
    use proptest::prelude::*;
    let piece = prop_oneof![
        Just("# note\n".to_string()),
        Just("  # indented\n".to_string()),
        Just("\n".to_string()),
        Just("  \n".to_string()),
        Just(",\n".to_string()),
        Just("1,\n".to_string()),
        Just("2\n".to_string()),
        Just("3,x\n".to_string()),
        Just("4,inf\n".to_string()),
        Just("5,\"6.5\"\n".to_string()),
        Just("7, 8.25 \r\n".to_string()),
        Just("10,25,5\n".to_string()),
        Just("11,2\0\n".to_string()),
        Just("12,3\r13,4\n".to_string()),
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
        Just("\n t,rate_dps\n"),
        Just("t,other\n"),
        Just("rate_dps,t\n"),
        Just("rate_dps\n"),
        Just(""),
    ];
    proptest!(ProptestConfig::with_cases(400), |(
        head in header,
        body in proptest::collection::vec(piece, 0..12),
        gaps in any::<bool>(),
        block in 1usize..40,
    )| {
        let text = format!("{head}{}", body.concat());
        let f = file(&text);
        let general = read_by_lines(f.path(), "rate_dps", gaps).map_err(|e| e.to_string());
        let ours = read(f.path(), "rate_dps", gaps).map_err(|e| e.to_string());
        prop_assert_eq!(&ours, &general, "{:?}", text);
        // Blocks cut anywhere (the header, a line, a CRLF) give the same.
        let cut = match plain::read_in_blocks(f.path(), "rate_dps", gaps, block) {
            Ok(Some(result)) => Ok(result),
            Ok(None) => read_by_lines(f.path(), "rate_dps", gaps),
            Err(e) => Err(e),
        }
        .map_err(|e| e.to_string());
        prop_assert_eq!(cut, general, "{:?} in blocks of {}", text, block);
    });
}
