//! The control word: what the folded loop's datapath does in one clock. Each field drives one
//! multiplexer or one write enable of `hdl/gyrofx_gyro_loop_serial.v`; the schedule is a
//! sequence of these words, one a clock, stored in the schedule ROM (`SCHEDULE_FILE`).
//!
//! Bit layout (LSB first), [`Control::encode`]:
//!
//! | bits | field | meaning |
//! |------|-------|---------|
//! | 0–2 | `rom` | [`RomRead`]: the NCO reference read this clock |
//! | 3 | `advance` | the NCO accumulator advances by this sample's frequency word |
//! | 4–7 | `a` | [`ASource`]: the multiplier's `a` operand (0: no product issued) |
//! | 8–10 | `limb` | which 15-bit limb of `a` |
//! | 11 | `top` | the limb is `a`'s top (signed) limb |
//! | 12–14 | `b` | [`BSource`]: the multiplier's `b` operand |
//! | 15–18 | `tap` | compensator tap index, for `b` = tap |
//! | 19–22 | `x` | [`AccX`]: the accumulator's base |
//! | 23–26 | `y` | [`AccY`]: the accumulator's addend |
//! | 27 | `read` | a RAM read this clock |
//! | 28–34 | `read_address` | its word |
//! | 35–37 | `gate` | [`ReadGate`]: when it reads as 0 (or the PLL preset) |
//! | 38–41 | `seen` | for the `seen` gate: 0 until this many decimations since reset |
//! | 42 | `write` | a RAM write this clock |
//! | 43–49 | `write_address` | its word |
//! | 50–52 | `data` | [`WriteData`]: what is written |
//! | 53–56 | `quantize` | [`Quantize`]: the quantization point that fires |
//! | 57 | `rom_gyro` | whose NCO the sine ROM read uses (0 gyro A, 1 gyro B: [`Control::rom_gyro`]) |
//! | 58 | `advance_gyro` | whose NCO advances |
//! | 59 | `issue_gyro` | whose operands the multiplier takes |
//! | 60 | `accumulate_gyro` | whose registers and constants the accumulator's `x`, `y` read |
//! | 61 | `read_gyro` | whose mode switch the read's gate follows |
//! | 62 | `quantize_gyro` | whose register the quantization point loads |
//! | 63 | `decimating_write` | the RAM write acts only in a decimating sample |
//!
//! The gyro fields are 0 in a one-gyro schedule; in the folded pair (both gyros on one
//! datapath, [`super::Schedule::pair`]) each unit's field names the gyro whose template
//! placed the unit's work in that clock.
//!
//! A product's weight (its limb's `2^(15·limb)` and a PI's alignment, which follows from
//! its `b`, [`BSource::alignment`]) travels with it down the multiplier's pipeline, so the
//! accumulator's `y` = product needs no field of its own.

/// Width of a limb of the multiplier's operands, bits: the serial chain's, for the same reason
/// (15 unsigned bits fit a signed 16×16 multiplier, one SB_MAC16 or DSP48 slice, with a zero
/// sign bit).
pub use crate::serial::isa::LIMB_BITS;

/// Width of the control word, bits.
pub const CONTROL_BITS: u32 = 64;

/// Width of a RAM address field, bits.
pub const ADDRESS_BITS: u32 = 7;

macro_rules! field_enum {
    ($(#[$meta:meta])* $name:ident { $($(#[$vmeta:meta])* $variant:ident = $value:expr),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum $name {
            $($(#[$vmeta])* $variant = $value),*
        }

        impl $name {
            /// The field's code.
            pub const fn code(self) -> u64 {
                self as u64
            }
        }
    };
}

field_enum!(
    /// The NCO reference read from the sine ROM; the value is the `b` operand from the next
    /// clock on. The cosine read of an NCO also stores its truncation error (error feedback).
    RomRead {
        /// No read.
        #[default]
        None = 0,
        /// The drive reference's sine (the drive demodulator's I).
        DriveSin = 1,
        /// The drive reference's cosine (Q).
        DriveCos = 2,
        /// The transmit reference's cosine (the DAC's carrier).
        TransmitCos = 3,
        /// The sense reference's sine.
        SenseSin = 4,
        /// The sense reference's cosine.
        SenseCos = 5,
    }
);

field_enum!(
    /// The multiplier's `a` operand (sign-extended, split into 15-bit limbs).
    ASource {
        /// No product this clock.
        #[default]
        None = 0,
        /// The driven axis's ADC code.
        AdcDrive = 1,
        /// The sensed axis's ADC code.
        AdcSense = 2,
        /// The drive demodulator's `Q`: the PLL's error.
        DriveQ = 3,
        /// The AGC's error `e_A`.
        AmplitudeError = 4,
        /// The AGC's output: the drive amplitude.
        Amplitude = 5,
        /// The CIC output `c` of this decimation.
        Cic = 6,
        /// The RAM read register (the compensator's delay line).
        Read = 7,
        /// The compensator's output, for the `1/SF` product.
        CicOutput = 8,
    }
);

field_enum!(
    /// The multiplier's `b` operand.
    BSource {
        /// The last sine ROM read, with its sign.
        #[default]
        Reference = 0,
        /// The PLL's `ki`.
        PllKi = 1,
        /// The PLL's `kp`.
        PllKp = 2,
        /// The AGC's `ki`.
        AgcKi = 3,
        /// The AGC's `kp`.
        AgcKp = 4,
        /// Compensator tap `tap`.
        Tap = 5,
        /// This mode's `1/SF` of the rate.
        RateCoefficient = 6,
        /// This mode's `1/SF` of the quadrature.
        QuadratureCoefficient = 7,
    }
);

field_enum!(
    /// The accumulator's base: `acc <= x + y`.
    AccX {
        /// The accumulator itself (accumulate; with `y` = zero, hold).
        #[default]
        Keep = 0,
        /// Zero (a new sum).
        Zero = 1,
        /// The RAM read register.
        Read = 2,
        /// The RAM read register `<< k`: a demodulator state at the update's fraction bits.
        ReadLowpass = 3,
        /// This mode's AGC setpoint.
        Setpoint = 4,
        /// The RAM read register aligned as the PLL's update needs its integrator.
        PllIntegrator = 5,
        /// The integrator register aligned as the PLL's output sum needs it.
        PllSum = 6,
        /// As `PllIntegrator`, for the AGC.
        AgcIntegrator = 7,
        /// As `PllSum`, for the AGC.
        AgcSum = 8,
    }
);

field_enum!(
    /// The accumulator's addend.
    AccY {
        /// Zero.
        #[default]
        Zero = 0,
        /// The product of the limb issued [`PRODUCT_LATENCY`] clocks ago, at its weight.
        Product = 1,
        /// Minus the RAM read register.
        NegRead = 2,
        /// The demodulator product `p`, aligned to the state's fraction bits.
        DemodProduct = 3,
        /// Minus the demodulator output of the state register (`−I`).
        NegDemodOutput = 4,
        /// The demodulator output of the state register (the CIC's input).
        DemodOutput = 5,
        /// The RAM read register of the clock before (the previous integrator).
        PreviousRead = 6,
        /// Minus the RAM read register `>> s` (the lock filter's leak).
        NegReadShifted = 7,
        /// The drive demodulator's `Q`.
        DriveQ = 8,
        /// The AGC's error.
        AmplitudeError = 9,
    }
);

field_enum!(
    /// When a RAM read returns 0 instead of the word: the clears of a mode switch and a reset,
    /// without a clock spent clearing the RAM.
    ReadGate {
        /// Never.
        #[default]
        None = 0,
        /// In a sample that switches mode (demodulator states, AGC integrator, lock filters).
        Switch = 1,
        /// In a sample that switches mode, the PLL's preset (clamped) instead, for the
        /// accumulator's [`AccX::PllIntegrator`]: the preset is an operand of its own, chosen
        /// with the operand a clock early, so the read register itself holds the word (which
        /// its other readers see).
        Preset = 2,
        /// In the first sample after reset (CIC integrators).
        First = 3,
        /// Until `seen` decimations since reset (CIC combs, compensator delay line).
        Seen = 4,
    }
);

field_enum!(
    /// What a RAM write stores (sign-extended to the RAM's width). A quantized state is
    /// written from the register its point loaded, the clock after, so that no clock runs a
    /// quantizer into the RAM's write multiplexer.
    WriteData {
        /// The accumulator, wrapped to the CIC register width.
        #[default]
        AccCic = 0,
        /// The accumulator, a lock filter's `z`.
        AccLock = 1,
        /// The demodulator state register `y`.
        DemodState = 2,
        /// The PI integrator register `v` (the PLL's or the AGC's, one of them held shifted
        /// left so that both output sums take `v` at one alignment: the RAM holds it so too).
        Integrator = 3,
        /// The RAM read register (the delay lines' shift).
        Read = 4,
        /// The CIC output register `c`.
        Cic = 5,
        /// The accumulator, a compensator's partial sum (wrapped to the sum's exact width).
        AccFir = 6,
    }
);

field_enum!(
    /// The quantization point (or check) that fires this clock, and the register it loads.
    Quantize {
        /// None.
        #[default]
        None = 0,
        /// Demodulator product `p` ← accumulator.
        DemodProduct = 1,
        /// Demodulator state register ← accumulator.
        DemodState = 2,
        /// `Q` of the drive demodulator ← the state register's output point.
        DriveQ = 3,
        /// AGC error ← accumulator (`setpoint − I`).
        AmplitudeError = 4,
        /// PLL integrator register ← accumulator, clamped.
        PllIntegrator = 5,
        /// NCO frequency word of the next sample ← accumulator (PLL output).
        PllOutput = 6,
        /// AGC integrator register ← accumulator, clamped.
        AgcIntegrator = 7,
        /// Drive amplitude ← accumulator (AGC output).
        AgcOutput = 8,
        /// DAC code ← accumulator: the delay line shifts and `dac_x`/`dac_y` load.
        Dac = 9,
        /// CIC output `c` ← accumulator (the comb chain).
        Cic = 10,
        /// Compensator output ← accumulator.
        CicOutput = 11,
        /// `rate` ← accumulator.
        Rate = 12,
        /// `quadrature` ← accumulator; `out_valid` pulses on the next clock.
        Quadrature = 13,
        /// The phase lock filter's check ← accumulator.
        LockQ = 14,
        /// The amplitude lock filter's check ← accumulator: the lock count and `locked` load.
        LockA = 15,
    }
);

/// A RAM read: the word, and when it reads as 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Read {
    /// Word address.
    pub address: u8,
    /// When the read returns 0 (or the PLL preset).
    pub gate: ReadGate,
    /// For [`ReadGate::Seen`]: decimations since reset below which it returns 0.
    pub seen: u8,
    /// Whose mode switch the gate follows (0 gyro A, 1 gyro B).
    pub gyro: u8,
}

/// A RAM write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Write {
    /// Word address.
    pub address: u8,
    /// What is written.
    pub data: WriteData,
    /// Only in a decimating sample (the pair's snapshot of a CIC's last integrator).
    pub decimating: bool,
}

/// Clocks from a product's issue to the clock whose accumulation adds it: the operand
/// registers, the multiplier's output registers, then the weighted sum `pp` (each one
/// register, so that no clock runs a multiplexer into a multiplier or a multiplier into the
/// accumulator's adder).
pub const PRODUCT_LATENCY: u32 = 3;

/// A product issued to the multiplier: one limb of `a` times all of `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Issue {
    /// The `a` operand.
    pub a: ASource,
    /// Which limb of `a` (0: least significant).
    pub limb: u8,
    /// Whether it is `a`'s top limb (signed).
    pub top: bool,
    /// The `b` operand.
    pub b: BSource,
    /// The tap, for [`BSource::Tap`].
    pub tap: u8,
    /// Whose operands (0 gyro A, 1 gyro B).
    pub gyro: u8,
}

impl BSource {
    /// The PI alignment a product with this `b` takes (the index of the folded loop's
    /// alignment shifts: 0 none, 1 PLL `ki`, 2 PLL `kp`, 3 AGC `ki`, 4 AGC `kp`), when the
    /// product has fewer fraction bits than the sum it enters.
    pub const fn alignment(self) -> usize {
        match self {
            BSource::PllKi => 1,
            BSource::PllKp => 2,
            BSource::AgcKi => 3,
            BSource::AgcKp => 4,
            _ => 0,
        }
    }
}

/// An accumulator operation `acc <= x + y`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Accumulate {
    /// Base.
    pub x: AccX,
    /// Addend.
    pub y: AccY,
    /// Whose registers and constants `x` and `y` read (0 gyro A, 1 gyro B).
    pub gyro: u8,
}

/// One clock of the schedule. `None` fields leave their unit idle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Control {
    /// Sine ROM read.
    pub rom: RomRead,
    /// NCO accumulator advance.
    pub advance: bool,
    /// Multiplier issue.
    pub issue: Option<Issue>,
    /// Accumulator operation.
    pub accumulate: Option<Accumulate>,
    /// RAM read.
    pub read: Option<Read>,
    /// RAM write.
    pub write: Option<Write>,
    /// Quantization point.
    pub quantize: Quantize,
    /// Whose NCO the ROM read uses (0 gyro A, 1 gyro B).
    pub rom_gyro: u8,
    /// Whose NCO advances.
    pub advance_gyro: u8,
    /// Whose register the quantization point loads.
    pub quantize_gyro: u8,
}

/// Two controls asked for the same unit in one clock (a schedule conflict).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Busy(pub &'static str);

/// The control word's fields, least significant first: name and width in bits (the
/// [module doc](self)'s table; 64 bits in all).
pub const FIELDS: [(&str, u32); 24] = [
    ("rom", 3),
    ("advance", 1),
    ("a", 4),
    ("limb", 3),
    ("top", 1),
    ("b", 3),
    ("tap", 4),
    ("x", 4),
    ("y", 4),
    ("read", 1),
    ("read_address", ADDRESS_BITS),
    ("gate", 3),
    ("seen", 4),
    ("write", 1),
    ("write_address", ADDRESS_BITS),
    ("data", 3),
    ("quantize", 4),
    ("rom_gyro", 1),
    ("advance_gyro", 1),
    ("issue_gyro", 1),
    ("accumulate_gyro", 1),
    ("read_gyro", 1),
    ("quantize_gyro", 1),
    ("decimating_write", 1),
];

impl Control {
    /// Each field's value, in [`FIELDS`] order.
    pub fn fields(&self) -> [u64; 24] {
        let issue = self.issue.unwrap_or(Issue {
            a: ASource::None,
            limb: 0,
            top: false,
            b: BSource::Reference,
            tap: 0,
            gyro: 0,
        });
        let acc = self.accumulate.unwrap_or_default();
        let read = self.read.map_or((0, 0, 0, 0, 0), |r| {
            (
                1,
                u64::from(r.address),
                r.gate.code(),
                u64::from(r.seen),
                u64::from(r.gyro),
            )
        });
        let write = self.write.map_or((0, 0, 0, 0), |w| {
            (
                1,
                u64::from(w.address),
                w.data.code(),
                u64::from(w.decimating),
            )
        });
        [
            self.rom.code(),
            u64::from(self.advance),
            issue.a.code(),
            u64::from(issue.limb),
            u64::from(issue.top),
            issue.b.code(),
            u64::from(issue.tap),
            acc.x.code(),
            acc.y.code(),
            read.0,
            read.1,
            read.2,
            read.3,
            write.0,
            write.1,
            write.2,
            self.quantize.code(),
            u64::from(self.rom_gyro),
            u64::from(self.advance_gyro),
            u64::from(issue.gyro),
            u64::from(acc.gyro),
            read.4,
            u64::from(self.quantize_gyro),
            write.3,
        ]
    }

    /// The control word's bits: [`Control::fields`] packed as [`FIELDS`] lays them out.
    pub fn encode(&self) -> u64 {
        let mut word = 0u64;
        let mut offset = 0;
        for (value, (_, width)) in self.fields().into_iter().zip(FIELDS) {
            debug_assert!(value < 1 << width, "a field wider than its {width} bits");
            word |= value << offset;
            offset += width;
        }
        word
    }

    /// This clock's units and `other`'s together, or the first unit both use.
    ///
    /// # Errors
    /// [`Busy`] naming the unit.
    pub fn merge(&self, other: &Control) -> Result<Control, Busy> {
        fn one<T: Copy>(a: Option<T>, b: Option<T>, unit: &'static str) -> Result<Option<T>, Busy> {
            match (a, b) {
                (Some(_), Some(_)) => Err(Busy(unit)),
                (a, b) => Ok(a.or(b)),
            }
        }
        let (rom, rom_gyro) = match (self.rom, other.rom) {
            (RomRead::None, r) => (r, other.rom_gyro),
            (r, RomRead::None) => (r, self.rom_gyro),
            _ => return Err(Busy("sine ROM")),
        };
        if self.advance && other.advance {
            return Err(Busy("NCO advance"));
        }
        let advance_gyro = if self.advance {
            self.advance_gyro
        } else {
            other.advance_gyro
        };
        let (quantize, quantize_gyro) = match (self.quantize, other.quantize) {
            (Quantize::None, q) => (q, other.quantize_gyro),
            (q, Quantize::None) => (q, self.quantize_gyro),
            _ => return Err(Busy("quantizer")),
        };
        // A block RAM's read of the word it writes in the same clock is undefined (the RTL
        // does not pay for the logic that would return the old word).
        let read = self.read.or(other.read);
        let write = self.write.or(other.write);
        if read.zip(write).is_some_and(|(r, w)| r.address == w.address) {
            return Err(Busy("RAM word (read and written)"));
        }
        Ok(Control {
            rom,
            advance: self.advance || other.advance,
            issue: one(self.issue, other.issue, "multiplier")?,
            accumulate: one(self.accumulate, other.accumulate, "accumulator")?,
            read: one(self.read, other.read, "RAM read port")?,
            write: one(self.write, other.write, "RAM write port")?,
            quantize,
            rom_gyro,
            advance_gyro,
            quantize_gyro,
        })
    }
}

impl std::fmt::Display for Control {
    /// One line: the units this clock uses (`rom DriveSin; issue AdcDrive[0]×Reference; …`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts: Vec<String> = Vec::new();
        if self.rom != RomRead::None {
            parts.push(format!("rom {:?}", self.rom));
        }
        if self.advance {
            parts.push("advance".into());
        }
        if let Some(i) = self.issue {
            let tap = if i.b == BSource::Tap {
                format!("{}", i.tap)
            } else {
                String::new()
            };
            parts.push(format!("{:?}[{}]×{:?}{tap}", i.a, i.limb, i.b));
        }
        if let Some(a) = self.accumulate {
            parts.push(format!("acc {:?}+{:?}", a.x, a.y));
        }
        if let Some(r) = self.read {
            parts.push(format!("read {} {:?}", r.address, r.gate));
        }
        if let Some(w) = self.write {
            let when = if w.decimating { " (decimating)" } else { "" };
            parts.push(format!("write {} {:?}{when}", w.address, w.data));
        }
        if self.quantize != Quantize::None {
            parts.push(format!("{:?}", self.quantize));
        }
        if parts.is_empty() {
            parts.push("idle".into());
        }
        let gyros = [
            self.rom_gyro,
            self.advance_gyro,
            self.issue.map_or(0, |i| i.gyro),
            self.accumulate.map_or(0, |a| a.gyro),
            self.read.map_or(0, |r| r.gyro),
            self.quantize_gyro,
        ];
        if gyros.iter().any(|&g| g != 0) {
            let names = ["rom", "advance", "issue", "acc", "read", "quantize"];
            let b: Vec<&str> = names
                .iter()
                .zip(gyros)
                .filter(|(_, g)| *g != 0)
                .map(|(n, _)| *n)
                .collect();
            parts.push(format!("gyro B: {}", b.join(",")));
        }
        write!(f, "{}", parts.join("; "))
    }
}
