//! A block's vector files row by row: [`RowLayout`] formats one row of the stimulus hex, the
//! expected hex and the CSV twin (the one formatter of those files, whether the rows are kept
//! or streamed), and [`StagedRows`] streams a block's rows into its files in a staging folder
//! on a thread of its own, hashing each file as it is written — so `generate` holds a batch of
//! rows per block, not the run.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;

use gyrofx_model::fx::Format;
use sha2::{Digest, Sha256};

use crate::block::{Block, RowSink, Signal};
use crate::output_folder;
use crate::package::FileEntry;
use crate::testbench::header;
use crate::text::{push_hex, Provenance};
use gyrofx_job::error::{Error, Result};

/// The signals, gates and extra columns of a block's vector files.
#[derive(Clone, Debug)]
pub struct RowLayout {
    inputs: Vec<Signal>,
    outputs: Vec<Signal>,
    /// Per signal (inputs, then outputs), the row index (after `rst`) of its gate.
    gate_of: Vec<Option<usize>>,
    extra: Vec<&'static str>,
}

impl RowLayout {
    /// The layout of `block`'s files.
    pub fn of(block: &Block) -> Self {
        let gate_of = block
            .inputs
            .iter()
            .map(|_| None)
            .chain(block.outputs.iter().map(|o| {
                o.gate.and_then(|gate| {
                    block
                        .outputs
                        .iter()
                        .position(|other| other.signal.name == gate)
                        .map(|p| block.inputs.len() + p)
                })
            }))
            .collect();
        RowLayout {
            inputs: block.inputs.clone(),
            outputs: block.outputs.iter().map(|o| o.signal.clone()).collect(),
            gate_of,
            extra: block.extra.clone(),
        }
    }

    /// The stimulus file's two header lines.
    pub fn stimulus_header(&self, provenance: &Provenance) -> String {
        let fields: Vec<&Signal> = self.inputs.iter().collect();
        format!("{}\n{}\n", provenance.line("//"), header(&fields, true))
    }

    /// The expected file's two header lines.
    pub fn expected_header(&self, provenance: &Provenance) -> String {
        let fields: Vec<&Signal> = self.outputs.iter().collect();
        format!("{}\n{}\n", provenance.line("//"), header(&fields, false))
    }

    /// The CSV's comment and header lines: sample, rst, then per signal its code (and for
    /// signed signals its real value, the column named with the unit: `_dps` °/s, `_fs`
    /// full-scale units; none for DAC codes), then the extra columns.
    pub fn csv_header(&self, provenance: &Provenance) -> String {
        let mut csv = provenance.line("#");
        csv.push_str("\nsample,rst");
        for s in self.inputs.iter().chain(&self.outputs) {
            let _ = write!(csv, ",{}", s.name);
            if let Some(unit) = s.csv_unit() {
                let _ = write!(csv, ",{}_{unit}", s.name);
            }
        }
        for name in &self.extra {
            let _ = write!(csv, ",{name}");
        }
        csv.push('\n');
        csv
    }

    /// Appends the stimulus line of `row` (`rst`, inputs, outputs).
    pub fn stimulus_line(&self, row: &[i64], out: &mut String) {
        let bit = Format::new(false, 1, 0).expect("1 bit");
        push_hex(out, i128::from(row[0]), bit);
        for (code, s) in row[1..].iter().zip(&self.inputs) {
            out.push(' ');
            push_hex(out, i128::from(*code), s.format);
        }
        out.push('\n');
    }

    /// Appends the expected line of `row`.
    pub fn expected_line(&self, row: &[i64], out: &mut String) {
        let outputs = &row[1 + self.inputs.len()..];
        for (i, (code, s)) in outputs.iter().zip(&self.outputs).enumerate() {
            if i > 0 {
                out.push(' ');
            }
            push_hex(out, i128::from(*code), s.format);
        }
        out.push('\n');
    }

    /// Appends the CSV line of row `k`. A gated output's cells are empty where its gate is 0;
    /// NaN extra values print empty.
    pub fn csv_line(
        &self,
        k: usize,
        row: &[i64],
        extra: &[f64],
        out: &mut String,
        buffers: &mut (itoa::Buffer, ryu::Buffer),
    ) {
        let (int, real) = buffers;
        out.push_str(int.format(k));
        out.push(',');
        out.push_str(int.format(row[0]));
        for ((index, code), s) in row[1..]
            .iter()
            .enumerate()
            .zip(self.inputs.iter().chain(&self.outputs))
        {
            // A gated output means nothing where its gate is 0: an empty cell, not a 0.
            let shown = self.gate_of[index].is_none_or(|g| row[1 + g] == 1);
            out.push(',');
            if shown {
                out.push_str(int.format(*code));
            }
            if s.csv_unit().is_some() {
                out.push(',');
                if shown {
                    push_real(out, real, s.format.to_f64(i128::from(*code)));
                }
            }
        }
        for value in extra {
            out.push(',');
            push_real(out, real, *value);
        }
        out.push('\n');
    }
}

/// Appends `value` in the shortest form that reads back exactly (ryu: the same digits on
/// every platform); NaN as an empty cell.
pub(crate) fn push_real(out: &mut String, buffer: &mut ryu::Buffer, value: f64) {
    if !value.is_nan() {
        out.push_str(buffer.format(value));
    }
}

/// A file being written and hashed at once.
struct HashedFile {
    relative: String,
    path: PathBuf,
    writer: std::io::BufWriter<std::fs::File>,
    hasher: Sha256,
    bytes: usize,
}

impl HashedFile {
    fn create(root: &Path, relative: String) -> Result<Self> {
        let path = root.join(&relative);
        if let Some(folder) = path.parent() {
            output_folder::create_below(root, folder).map_err(|e| Error::io(folder, e))?;
        }
        let file = std::fs::File::create(&path).map_err(|e| Error::io(&path, e))?;
        Ok(HashedFile {
            relative,
            writer: std::io::BufWriter::with_capacity(1 << 18, file),
            path,
            hasher: Sha256::new(),
            bytes: 0,
        })
    }

    fn write(&mut self, text: &str) -> Result<()> {
        self.hasher.update(text.as_bytes());
        self.bytes += text.len();
        self.writer
            .write_all(text.as_bytes())
            .map_err(|e| Error::io(&self.path, e))
    }

    fn finish(mut self) -> Result<FileEntry> {
        self.writer.flush().map_err(|e| Error::io(&self.path, e))?;
        Ok(FileEntry {
            path: self.relative,
            sha256: gyrofx_job::hash::digest_hex(&self.hasher.finalize()),
            bytes: self.bytes,
        })
    }
}

/// Rows per batch handed to a block's writer thread.
const BATCH_ROWS: usize = 4096;

/// A batch of rows: codes and extra values, row-major, and the index of its first row.
struct Batch {
    first: usize,
    codes: Vec<i64>,
    extra: Vec<f64>,
}

/// Streams a block's rows into `<block>/<block>_stimulus.hex`, `_expected.hex` and (with the
/// CSV) `_vectors.csv` under a staging folder, formatted and hashed on a thread of its own.
/// Without files ([`StagedRows::discard`]) the rows are only counted: the blocks a package
/// leaves out.
pub struct StagedRows {
    stride: usize,
    extra: usize,
    batch: Batch,
    sender: Option<SyncSender<Batch>>,
    writer: Option<JoinHandle<Result<Vec<FileEntry>>>>,
}

impl std::fmt::Debug for StagedRows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StagedRows")
            .field("stride", &self.stride)
            .field("streaming", &self.sender.is_some())
            .finish()
    }
}

impl StagedRows {
    /// Opens `block`'s vector files under `root` (the staging folder) and starts its writer.
    ///
    /// # Errors
    /// When a file cannot be created.
    pub fn open(block: &Block, root: &Path, csv: bool, provenance: &Provenance) -> Result<Self> {
        let layout = RowLayout::of(block);
        let file = |what: &str| format!("{}/{}", block.name, block.file(what));
        let mut stimulus = HashedFile::create(root, file("stimulus.hex"))?;
        let mut expected = HashedFile::create(root, file("expected.hex"))?;
        stimulus.write(&layout.stimulus_header(provenance))?;
        expected.write(&layout.expected_header(provenance))?;
        let mut table = match csv {
            true => {
                let mut f = HashedFile::create(root, file("vectors.csv"))?;
                f.write(&layout.csv_header(provenance))?;
                Some(f)
            }
            false => None,
        };
        let stride = block.stride();
        let extra = block.extra.len();
        let (sender, receiver) = sync_channel::<Batch>(2);
        let writer = std::thread::spawn(move || -> Result<Vec<FileEntry>> {
            let mut text = [String::new(), String::new(), String::new()];
            let mut buffers = (itoa::Buffer::new(), ryu::Buffer::new());
            for batch in receiver {
                for t in &mut text {
                    t.clear();
                }
                let rows = batch.codes.chunks_exact(stride);
                for (i, row) in rows.enumerate() {
                    layout.stimulus_line(row, &mut text[0]);
                    layout.expected_line(row, &mut text[1]);
                    if table.is_some() {
                        let values = &batch.extra[i * extra..(i + 1) * extra];
                        layout.csv_line(batch.first + i, row, values, &mut text[2], &mut buffers);
                    }
                }
                stimulus.write(&text[0])?;
                expected.write(&text[1])?;
                if let Some(f) = table.as_mut() {
                    f.write(&text[2])?;
                }
            }
            let mut entries = vec![stimulus.finish()?, expected.finish()?];
            if let Some(f) = table {
                entries.push(f.finish()?);
            }
            Ok(entries)
        });
        Ok(StagedRows {
            stride,
            extra,
            batch: Batch {
                first: 0,
                codes: Vec::with_capacity(BATCH_ROWS * stride),
                extra: Vec::with_capacity(BATCH_ROWS * extra),
            },
            sender: Some(sender),
            writer: Some(writer),
        })
    }

    /// A sink that only counts (no files).
    pub fn discard(block: &Block) -> Self {
        StagedRows {
            stride: block.stride(),
            extra: block.extra.len(),
            batch: Batch {
                first: 0,
                codes: Vec::new(),
                extra: Vec::new(),
            },
            sender: None,
            writer: None,
        }
    }

    /// Hands the batch to the writer (a writer that failed has dropped its end: its error is
    /// reported by `finish`).
    fn send(&mut self) {
        let rows = self.batch.codes.len() / self.stride.max(1);
        let next = Batch {
            first: self.batch.first + rows,
            codes: Vec::with_capacity(BATCH_ROWS * self.stride),
            extra: Vec::with_capacity(BATCH_ROWS * self.extra),
        };
        let full = std::mem::replace(&mut self.batch, next);
        if let Some(sender) = &self.sender {
            if sender.send(full).is_err() {
                self.sender = None;
            }
        }
    }
}

impl RowSink for StagedRows {
    fn row(&mut self, codes: &[i64], extra: &[f64]) {
        if self.writer.is_none() {
            return;
        }
        self.batch.codes.extend_from_slice(codes);
        self.batch.extra.extend_from_slice(extra);
        if self.batch.codes.len() >= BATCH_ROWS * self.stride {
            self.send();
        }
    }

    fn finish(mut self: Box<Self>) -> Result<Vec<FileEntry>> {
        let Some(writer) = self.writer.take() else {
            return Ok(Vec::new());
        };
        if !self.batch.codes.is_empty() {
            self.send();
        }
        self.sender = None;
        writer.join().expect("the vector writer does not panic")
    }
}

impl Drop for StagedRows {
    /// On an error path (no `finish`): ends the writer before the staging folder goes.
    fn drop(&mut self) {
        self.sender = None;
        if let Some(writer) = self.writer.take() {
            let _ = writer.join();
        }
    }
}
