//! The engine's instruction set: what one instruction does, and its program-ROM word.
//!
//! Every value lives in the data RAM as *limbs* of [`LIMB_BITS`] bits, least significant
//! first, each held in a 16-bit word: the low limbs zero-extended (0..2^15), the top limb
//! sign-extended (a signed 15-bit value). The value is `Σ limb_i · 2^(15 i)`, so a 16×16
//! signed multiplier takes any limb and any coefficient limb as they are.

/// Bits of a value per limb (one 16-bit RAM word).
pub const LIMB_BITS: u32 = 15;

/// Mask of a limb's bits.
pub const LIMB_MASK: i128 = (1 << LIMB_BITS) - 1;

/// Clocks the engine spends on one instruction: fetch, read the operands, multiply, execute.
pub const CLOCKS_PER_INSTRUCTION: u32 = 4;

/// What an instruction does (the `op` field, 4 bits). `acc` is the column accumulator;
/// `A` the data RAM word at the instruction's address, `B` the coefficient ROM word at its
/// coefficient address.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Op {
    /// `acc = 0`; clears the rounding flags (`half`, `sticky`) and sets both `high` flags.
    Zero = 0,
    /// `acc += A · B`.
    Mac = 1,
    /// `acc += I · B`, `I` the input limb at the address (`y_a`'s limbs, then `y_b`'s).
    MacInput = 2,
    /// `A ← acc[14:0]` (zero-extended), then `acc >>>= 15`: a low limb.
    Emit = 3,
    /// `A ← acc[14:0]` sign-extended from bit 14, then `acc >>>= 15`: a top limb.
    EmitTop = 4,
    /// A dropped remainder limb below the half bit: `sticky |= acc[14:0] != 0`, `acc >>>= 15`.
    Drop = 5,
    /// The remainder's top limb: `half = acc[14]`, `sticky |= acc[13:0] != 0`, `acc >>>= 15`.
    DropHalf = 6,
    /// `negative = A[15]`: the sign of the value about to be rounded (its top limb).
    Sign = 7,
    /// `acc += increment(ROUNDING, half, sticky, negative, acc[0])`.
    Round = 8,
    /// A limb above the target width: `high_zero &= acc[14:0] == 0`,
    /// `high_ones &= acc[14:0] == 0x7fff`, `acc >>>= 15`.
    High = 9,
    /// `fits = (acc == 0 && high_zero) || (acc == −1 && high_ones)`.
    Fits = 10,
    /// A low limb, saturated: `A ← fits ? acc[14:0] : (negative ? 0 : 0x7fff)`, `acc >>>= 15`.
    StoreLow = 11,
    /// A top limb, saturated: `A ← fits ? sext(acc[14:0]) : (negative ? ~B : B)`, `acc >>>= 15`
    /// (`B` the format's largest top limb).
    StoreTop = 12,
    /// Shifts `A[14:0]` into the output register `B` (0 rate, 1 bias_a, 2 bias_b) from the
    /// top: a value's limbs go least significant first.
    Out = 13,
    /// `estimated ← 1` (read by the conditions from the next instruction on).
    SetEstimated = 14,
    /// The program's end: the output registers show the new values (`out_valid` pulses when
    /// the rate was updated); the sample is no longer the first since reset.
    End = 15,
}

/// When an instruction acts (the `cond` field, 4 bits): on a false condition it does nothing.
/// The flags are the sample's, captured at `ce`; `estimated` is the engine's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Cond {
    /// Always.
    Always = 0,
    /// A's sample is not blanked.
    ValidA = 1,
    /// B's sample is not blanked.
    ValidB = 2,
    /// A's interval ends with this sample.
    DoneA = 3,
    /// B's interval ends with this sample.
    DoneB = 4,
    /// The window ends with this sample.
    Window = 5,
    /// A is in mode +1.
    ModeA = 6,
    /// A is in mode −1.
    NotModeA = 7,
    /// B is in mode +1.
    ModeB = 8,
    /// B is in mode −1.
    NotModeB = 9,
    /// Both samples are valid.
    BothValid = 10,
    /// Only A's sample is valid.
    OnlyA = 11,
    /// Only B's sample is valid.
    OnlyB = 12,
    /// At least one sample is valid (the KF steps).
    AnyValid = 13,
    /// The window ends and an earlier window produced estimates (smoothing applies).
    WindowEstimated = 14,
    /// The first sample since reset: the program clears the state before it uses it.
    Fresh = 15,
}

/// The sample's flags the conditions read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Flags {
    /// A's, B's sample not blanked.
    pub valid: [bool; 2],
    /// A's, B's interval ends.
    pub done: [bool; 2],
    /// The window ends.
    pub window: bool,
    /// A's, B's mode is +1.
    pub mode_positive: [bool; 2],
    /// A window produced estimates before this instruction.
    pub estimated: bool,
    /// No sample since reset.
    pub fresh: bool,
}

impl Cond {
    /// Whether the condition holds.
    pub fn holds(self, f: &Flags) -> bool {
        match self {
            Cond::Always => true,
            Cond::ValidA => f.valid[0],
            Cond::ValidB => f.valid[1],
            Cond::DoneA => f.done[0],
            Cond::DoneB => f.done[1],
            Cond::Window => f.window,
            Cond::ModeA => f.mode_positive[0],
            Cond::NotModeA => !f.mode_positive[0],
            Cond::ModeB => f.mode_positive[1],
            Cond::NotModeB => !f.mode_positive[1],
            Cond::BothValid => f.valid[0] && f.valid[1],
            Cond::OnlyA => f.valid[0] && !f.valid[1],
            Cond::OnlyB => !f.valid[0] && f.valid[1],
            Cond::AnyValid => f.valid[0] || f.valid[1],
            Cond::WindowEstimated => f.window && f.estimated,
            Cond::Fresh => f.fresh,
        }
    }
}

/// Which run-time index is added to the RAM address (the `ram_index` field, 2 bits), shifted
/// left by the program's `ram_index_shift`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum RamIndex {
    /// None.
    None = 0,
    /// A's interval index.
    IntervalA = 1,
    /// B's interval index.
    IntervalB = 2,
}

/// One instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Instruction {
    /// What it does.
    pub op: Op,
    /// When.
    pub cond: Cond,
    /// Run-time index of the RAM address.
    pub ram_index: RamIndex,
    /// `bw_sel`, shifted left by the program's `coefficient_index_shift`, is added to the
    /// coefficient address (the KF's gains).
    pub coefficient_by_bw_sel: bool,
    /// Data RAM address (or input limb, for [`Op::MacInput`]).
    pub address: u16,
    /// Coefficient ROM address (or output register, for [`Op::Out`]).
    pub coefficient: u16,
}

/// Field widths of a program-ROM word: from the most significant, `op` (4), `cond` (4),
/// `ram_index` (2), `coefficient_by_bw_sel` (1), `address` (`address_bits`), `coefficient`
/// (`coefficient_bits`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Data RAM address bits.
    pub address_bits: u32,
    /// Coefficient ROM address bits.
    pub coefficient_bits: u32,
}

impl Layout {
    /// Bits of a program word.
    pub fn word_bits(&self) -> u32 {
        4 + 4 + 2 + 1 + self.address_bits + self.coefficient_bits
    }
}

impl Instruction {
    /// The program-ROM word.
    pub fn encode(&self, layout: &Layout) -> u64 {
        let mut word = u64::from(self.op as u8);
        word = (word << 4) | u64::from(self.cond as u8);
        word = (word << 2) | u64::from(self.ram_index as u8);
        word = (word << 1) | u64::from(self.coefficient_by_bw_sel);
        word = (word << layout.address_bits) | u64::from(self.address);
        (word << layout.coefficient_bits) | u64::from(self.coefficient)
    }
}
