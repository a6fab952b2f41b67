//! [`Block`]: one RTL module's verification vectors and everything its testbench needs to
//! know — the DUT, its parameters and ROMs, the signals and when each is checked.

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

/// One block's vectors.
#[derive(Clone, Debug, PartialEq)]
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
    /// Inputs driven each sample (after `rst`).
    pub inputs: Vec<Signal>,
    /// Outputs and how they are checked.
    pub outputs: Vec<Output>,
    /// Row-major codes: per row `rst`, the inputs, the outputs (every declared format is at
    /// most 64 bits wide).
    codes: Vec<i64>,
    /// Extra real-valued CSV columns (name, one value per row; NaN prints empty).
    pub extra: Vec<(&'static str, Vec<f64>)>,
    /// Clocks the testbench waits after the one that follows `ce` before it compares the
    /// registered outputs (0: they are valid 1 clock after `ce`): a pipelined block's extra
    /// latency. `ce` stays low meanwhile, so samples come every `2 + settle_clocks` clocks at
    /// most.
    pub settle_clocks: u32,
}

impl Block {
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
            inputs,
            outputs,
            codes: Vec::new(),
            extra: Vec::new(),
            settle_clocks: 0,
        }
    }

    /// Reserves room for `rows` more rows.
    pub fn reserve(&mut self, rows: usize) {
        self.codes.reserve(rows * self.stride());
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
        assert_eq!(inputs.len(), self.inputs.len(), "{}: inputs", self.name);
        assert_eq!(outputs.len(), self.outputs.len(), "{}: outputs", self.name);
        self.codes.push(i64::from(rst));
        for (code, s) in inputs.iter().zip(&self.inputs) {
            debug_assert!(
                s.format.contains(*code),
                "{} {} = {code}",
                self.name,
                s.name
            );
            self.codes.push(*code as i64);
        }
        for (code, o) in outputs.iter().zip(&self.outputs) {
            debug_assert!(
                o.signal.format.contains(*code),
                "{} {} = {code}",
                self.name,
                o.signal.name
            );
            self.codes.push(*code as i64);
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.codes.len() / self.stride()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.codes.is_empty()
    }

    /// Row `k`: `rst`, inputs, outputs.
    pub fn row(&self, k: usize) -> &[i64] {
        &self.codes[k * self.stride()..(k + 1) * self.stride()]
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
