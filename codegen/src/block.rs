//! [`Block`]: one RTL module's verification vectors and everything its testbench needs to
//! know — the DUT, its parameters and ROMs, the signals and when each is checked.

use gyrofx_job::pipeline::Pipeline;
use gyrofx_model::fx::Format;

/// When an output is compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timing {
    /// Combinational from the state: checked for the current sample, before the clock edge
    /// that takes it (not on reset samples).
    Combinational,
    /// A register updated by the sample's `ce`: checked 1 clock after it.
    Registered,
}

/// A signal of the vector files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Signal {
    /// Port name.
    pub name: &'static str,
    /// Its format (flags are `u1.0`, indices `u<n>.0`).
    pub format: Format,
    /// A 1-bit flag (`std_logic` in VHDL) rather than a vector (an index of any width, even
    /// 1 bit, is an `unsigned` there).
    pub flag: bool,
    /// The unit of a signed signal's real value, the suffix of its CSV column (`dps`: °/s;
    /// `fs`: full-scale units); empty where the code is all there is to say (DAC codes).
    pub unit: &'static str,
}

impl Signal {
    /// A signal.
    pub fn new(name: &'static str, format: Format) -> Self {
        Signal {
            name,
            format,
            flag: false,
            unit: "dps",
        }
    }

    /// The same signal with its real value in `unit` (empty: no real value).
    pub fn with_unit(self, unit: &'static str) -> Self {
        Signal { unit, ..self }
    }

    /// A 1-bit flag.
    pub fn flag(name: &'static str) -> Self {
        Signal {
            flag: true,
            ..Signal::new(name, Format::new(false, 1, 0).expect("1 bit"))
        }
    }

    /// An unsigned index of `bits` bits.
    pub fn index(name: &'static str, bits: u32) -> Self {
        Signal::new(
            name,
            Format::new(false, bits.max(1), 0).expect("small width"),
        )
    }

    /// Whether it carries a real value worth printing (not a flag or an index).
    pub fn is_real(&self) -> bool {
        self.format.signed
    }

    /// The unit of the real-value CSV column beside its code, if it has one.
    pub fn csv_unit(&self) -> Option<&'static str> {
        (self.is_real() && !self.unit.is_empty()).then_some(self.unit)
    }
}

/// An output and how it is checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    /// The signal.
    pub signal: Signal,
    /// When it is compared.
    pub timing: Timing,
    /// Compared only where this (registered flag) output is expected 1.
    pub gate: Option<&'static str>,
    /// A one-clock pulse: must be 0 on idle clocks (registered outputs that are not pulses
    /// must hold their value there).
    pub pulse: bool,
}

impl Output {
    /// A combinational output.
    pub fn combinational(signal: Signal) -> Self {
        Output {
            signal,
            timing: Timing::Combinational,
            gate: None,
            pulse: false,
        }
    }

    /// A registered output that holds between samples.
    pub fn registered(signal: Signal) -> Self {
        Output {
            signal,
            timing: Timing::Registered,
            gate: None,
            pulse: false,
        }
    }

    /// A registered one-clock pulse.
    pub fn pulse(signal: Signal) -> Self {
        Output {
            pulse: true,
            ..Output::registered(signal)
        }
    }

    /// A registered output compared only where `gate` is expected 1.
    pub fn gated(signal: Signal, gate: &'static str) -> Self {
        Output {
            gate: Some(gate),
            ..Output::registered(signal)
        }
    }
}

/// A DUT parameter and its Verilog value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Param {
    /// Parameter name in the RTL.
    pub name: String,
    /// The localparam's type in the include: `integer`, a range like `[3:0]`, or empty for a
    /// string.
    pub kind: String,
    /// The Verilog literal.
    pub value: String,
    /// The VHDL generic's type: `integer`, `string` or `std_logic_vector`.
    pub vhdl_type: &'static str,
    /// The VHDL-2008 literal (bit vectors as sized hex, e.g. `4x"5"`).
    pub vhdl_value: String,
    /// What it is.
    pub comment: String,
}

impl Param {
    /// An integer parameter.
    pub fn integer(name: &str, value: i64, comment: impl Into<String>) -> Self {
        Param {
            name: name.to_string(),
            kind: "integer".into(),
            value: value.to_string(),
            vhdl_type: "integer",
            vhdl_value: value.to_string(),
            comment: comment.into(),
        }
    }

    /// A string parameter (a file name).
    pub fn string(name: &str, value: &str, comment: impl Into<String>) -> Self {
        Param {
            name: name.to_string(),
            kind: String::new(),
            value: format!("\"{value}\""),
            vhdl_type: "string",
            vhdl_value: format!("\"{value}\""),
            comment: comment.into(),
        }
    }

    /// A bit-vector parameter of `width` bits from its unsigned value.
    pub fn bits(name: &str, width: u32, value: u128, comment: impl Into<String>) -> Self {
        Param {
            name: name.to_string(),
            kind: format!("[{}:0]", width - 1),
            value: format!("{width}'h{value:x}"),
            vhdl_type: "std_logic_vector",
            vhdl_value: format!("{width}x\"{value:x}\""),
            comment: comment.into(),
        }
    }

    /// The width and fraction of `format` as `<PREFIX>_W` and `<PREFIX>_F`.
    pub fn format(prefix: &str, format: Format, what: &str) -> [Param; 2] {
        [
            Param::integer(
                &format!("{prefix}_W"),
                format.width.into(),
                format!("{what}: {format}"),
            ),
            Param::integer(
                &format!("{prefix}_F"),
                format.frac.into(),
                format!("{what}: {format}"),
            ),
        ]
    }
}

/// Most codes in a row (`rst`, inputs, outputs) of any block.
pub const MAX_STRIDE: usize = 64;

/// Where a streamed block's rows go, one at a time, in order.
pub trait RowSink: Send + Sync + std::fmt::Debug {
    /// One row: its codes (`rst`, inputs, outputs) and its extra-column values.
    fn row(&mut self, codes: &[i64], extra: &[f64]);
    /// After the last row: the files written, with their SHA-256s.
    ///
    /// # Errors
    /// Write errors.
    fn finish(self: Box<Self>) -> gyrofx_job::error::Result<Vec<crate::package::FileEntry>>;
}

/// A block's rows: kept, or streamed to a sink.
#[derive(Debug)]
enum Rows {
    Memory { codes: Vec<i64>, extra: Vec<f64> },
    Streamed(Box<dyn RowSink>),
    Finished,
}

/// One block's vectors.
#[derive(Debug)]
pub struct Block {
    /// Folder and file prefix, e.g. `kf`.
    pub name: &'static str,
    /// The DUT module, e.g. `gyrofx_kf`.
    pub module: &'static str,
    /// What the block is (one line, for the README).
    pub title: &'static str,
    /// DUT parameters.
    pub params: Vec<Param>,
    /// ROM images the DUT reads (file name, content).
    pub roms: Vec<(String, String)>,
    /// Images a synthesis run adds under the file names its submodules' parameter defaults
    /// give (file name, content): yosys elaborates every module with its own defaults while
    /// reading it, and a submodule reads its ROM image then.
    pub elaboration_images: Vec<(String, String)>,
    /// Inputs driven each sample (after `rst`).
    pub inputs: Vec<Signal>,
    /// Outputs and how they are checked.
    pub outputs: Vec<Output>,
    /// Names of the extra real-valued CSV columns, one value each per row (NaN prints empty);
    /// declared before the first row.
    pub extra: Vec<&'static str>,
    /// Where the rows go.
    rows: Rows,
    /// Rows pushed.
    count: usize,
    /// The files the rows were streamed to, after [`Block::finish_rows`].
    written: Vec<crate::package::FileEntry>,
    /// Its pipeline ([`gyrofx_job::pipeline`]): when the registered outputs show a sample (the
    /// testbench waits `settle_clocks` with `ce` low after the clock that follows `ce`) and how
    /// soon the next sample may come.
    pub pipeline: Pipeline,
    /// Whether the module has `clk`, `rst` and `ce` ports (a combinational block has none).
    pub clocked: bool,
    /// What its DPI-C testbench takes from it (`None`: it has no golden model to call).
    pub dpi: Option<DpiParts>,
    /// Its cocotb test module (`None`: it has no golden model to check against): the block's
    /// own `cocotb_test.py`, written to the package as `cocotb/test_<name>.py` with its
    /// pipeline constants set ([`crate::cocotb`]).
    pub cocotb_test: Option<&'static str>,
}

/// What only the block knows of its DPI-C testbench (`crate::dpi` puts these into the frame
/// every block shares): how its golden model in libgyrofx_capi is called and checked. Each
/// block keeps the SystemVerilog of its parts beside its module (`dpi_imports.svh`,
/// `dpi_step.sv`).
#[derive(Clone, Copy, Debug)]
pub struct DpiParts {
    /// The `import "DPI-C"` lines of the model functions it calls (trailing newline ignored).
    pub imports: &'static str,
    /// The statements that create its model handles from `plan`.
    pub handles: &'static str,
    /// The per-sample body of the stimulus loop (after the driver set `ce`; `k` counts
    /// samples), from the block as the package has it (its latency may depend on the config).
    pub step: fn(&Block) -> String,
    /// Its valid-qualified output stream, if its outputs come as one.
    pub stream: Option<DpiStream>,
    /// Samples a run takes by default.
    pub samples: usize,
}

/// A valid-qualified output stream, checked against the model whatever the latency.
#[derive(Clone, Copy, Debug)]
pub struct DpiStream {
    /// The valid flag.
    pub valid: &'static str,
    /// The output compared with the model's first value.
    pub value: &'static str,
    /// The output compared with its second value, if any.
    pub second: Option<&'static str>,
}

impl Block {
    /// Its Verilog port declarations, one per line, indented: `clk`, `rst`, `ce`, the inputs,
    /// the outputs (a wrapper or shell around the module declares these).
    pub fn port_declarations(&self) -> Vec<String> {
        let port = |direction: &str, signal: &Signal| {
            let signed = if signal.format.signed { "signed " } else { "" };
            let range = if signal.format.width > 1 {
                format!("[{}:0] ", signal.format.width - 1)
            } else {
                String::new()
            };
            format!("    {direction} wire {signed}{range}{}", signal.name)
        };
        let mut ports: Vec<String> = self
            .clock_ports()
            .iter()
            .map(|name| format!("    input wire {name}"))
            .collect();
        ports.extend(self.inputs.iter().map(|s| port("input", s)));
        ports.extend(self.outputs.iter().map(|o| port("output", &o.signal)));
        ports
    }

    /// The fewest clocks from one sample's `ce` to the next one's.
    pub fn clocks_per_sample(&self) -> u32 {
        self.pipeline.min_clocks_per_sample
    }

    /// Clocks the testbench waits, `ce` low, after the clock that follows `ce` before it
    /// compares the registered outputs.
    pub fn settle_clocks(&self) -> u32 {
        self.pipeline.settle_clocks()
    }

    /// `clk`, `rst`, `ce`, or none for a combinational block.
    pub fn clock_ports(&self) -> &'static [&'static str] {
        if self.clocked {
            &["clk", "rst", "ce"]
        } else {
            &[]
        }
    }

    /// An empty block.
    pub fn new(
        name: &'static str,
        module: &'static str,
        title: &'static str,
        inputs: Vec<Signal>,
        outputs: Vec<Output>,
    ) -> Self {
        Block {
            name,
            module,
            title,
            params: Vec::new(),
            roms: Vec::new(),
            elaboration_images: Vec::new(),
            inputs,
            outputs,
            extra: Vec::new(),
            rows: Rows::Memory {
                codes: Vec::new(),
                extra: Vec::new(),
            },
            count: 0,
            written: Vec::new(),
            pipeline: gyrofx_job::pipeline::ONE_CLOCK,
            clocked: true,
            dpi: None,
            cocotb_test: None,
        }
    }

    /// Sends every row from now on to `sink` instead of keeping it ([`Block::row`] then
    /// panics): the rows of a long run are written as they come, in bounded memory.
    ///
    /// # Panics
    /// When rows were pushed already.
    pub fn stream_to(&mut self, sink: Box<dyn RowSink>) {
        assert_eq!(self.count, 0, "{}: rows before the sink", self.name);
        self.rows = Rows::Streamed(sink);
    }

    /// Ends the rows; a sink's files are then listed by [`Block::written`].
    ///
    /// # Errors
    /// The sink's write errors.
    pub fn finish_rows(&mut self) -> gyrofx_job::error::Result<()> {
        let entries = self.end_rows()?;
        self.written.extend(entries);
        Ok(())
    }

    /// The files the rows were streamed to (none when they were kept), after
    /// [`Block::finish_rows`].
    pub fn written(&self) -> &[crate::package::FileEntry] {
        &self.written
    }

    fn end_rows(&mut self) -> gyrofx_job::error::Result<Vec<crate::package::FileEntry>> {
        match std::mem::replace(
            &mut self.rows,
            Rows::Memory {
                codes: Vec::new(),
                extra: Vec::new(),
            },
        ) {
            Rows::Memory { codes, extra } => {
                self.rows = Rows::Memory { codes, extra };
                Ok(Vec::new())
            }
            Rows::Streamed(sink) => {
                self.rows = Rows::Finished;
                sink.finish()
            }
            Rows::Finished => {
                self.rows = Rows::Finished;
                Ok(Vec::new())
            }
        }
    }

    /// Whether the rows are kept ([`Block::row`] works).
    pub fn is_in_memory(&self) -> bool {
        matches!(self.rows, Rows::Memory { .. })
    }

    /// Reserves room for `rows` more rows (kept rows only).
    pub fn reserve(&mut self, rows: usize) {
        let stride = self.stride();
        let extra = self.extra.len();
        if let Rows::Memory { codes, extra: e } = &mut self.rows {
            codes.reserve(rows * stride);
            e.reserve(rows * extra);
        }
    }

    /// Codes per row.
    pub fn stride(&self) -> usize {
        1 + self.inputs.len() + self.outputs.len()
    }

    /// Appends a row. Inputs and outputs in declaration order; debug builds check each code
    /// fits its format.
    ///
    /// # Panics
    /// When the counts do not match the declared signals.
    pub fn push(&mut self, rst: bool, inputs: &[i128], outputs: &[i128]) {
        self.push_with_extra(rst, inputs, outputs, &[]);
    }

    /// [`Block::push`] with the row's values of the [extra](Block::extra) CSV columns.
    ///
    /// # Panics
    /// When the counts do not match the declared signals and columns.
    pub fn push_with_extra(&mut self, rst: bool, inputs: &[i128], outputs: &[i128], extra: &[f64]) {
        assert_eq!(inputs.len(), self.inputs.len(), "{}: inputs", self.name);
        assert_eq!(outputs.len(), self.outputs.len(), "{}: outputs", self.name);
        assert_eq!(
            extra.len(),
            self.extra.len(),
            "{}: extra columns",
            self.name
        );
        let mut row = [0i64; MAX_STRIDE];
        assert!(
            self.stride() <= MAX_STRIDE,
            "{}: too many signals",
            self.name
        );
        row[0] = i64::from(rst);
        for ((slot, code), s) in row[1..].iter_mut().zip(inputs).zip(&self.inputs) {
            debug_assert!(
                s.format.contains(*code),
                "{} {} = {code}",
                self.name,
                s.name
            );
            *slot = *code as i64;
        }
        let first_output = 1 + self.inputs.len();
        for ((slot, code), o) in row[first_output..]
            .iter_mut()
            .zip(outputs)
            .zip(&self.outputs)
        {
            debug_assert!(
                o.signal.format.contains(*code),
                "{} {} = {code}",
                self.name,
                o.signal.name
            );
            *slot = *code as i64;
        }
        let row = &row[..self.stride()];
        match &mut self.rows {
            Rows::Memory { codes, extra: e } => {
                codes.extend_from_slice(row);
                e.extend_from_slice(extra);
            }
            Rows::Streamed(sink) => sink.row(row, extra),
            Rows::Finished => panic!("{}: a row after finish_rows", self.name),
        }
        self.count += 1;
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Row `k`: `rst`, inputs, outputs.
    ///
    /// # Panics
    /// When the rows were streamed ([`Block::stream_to`]).
    pub fn row(&self, k: usize) -> &[i64] {
        let stride = self.stride();
        match &self.rows {
            Rows::Memory { codes, .. } => &codes[k * stride..(k + 1) * stride],
            _ => panic!("{}: rows were streamed, not kept", self.name),
        }
    }

    /// Row `k`'s extra-column values.
    ///
    /// # Panics
    /// When the rows were streamed.
    pub fn extra_row(&self, k: usize) -> &[f64] {
        let width = self.extra.len();
        match &self.rows {
            Rows::Memory { extra, .. } => &extra[k * width..(k + 1) * width],
            _ => panic!("{}: rows were streamed, not kept", self.name),
        }
    }

    /// File names inside the block's folder.
    pub fn file(&self, what: &str) -> String {
        match what {
            "tb" => format!("tb_{}.v", self.module),
            "tb.vhd" => format!("tb_{}.vhd", self.module),
            other => format!("{}_{other}", self.name),
        }
    }
}
