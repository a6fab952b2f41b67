//! The folded loop's schedule, derived from the plan: each piece of the loop's arithmetic is a
//! template (its units' work at clocks relative to its start); the templates are placed one by
//! one at the earliest clock where their units are free, their registers hold nobody else's
//! value and the values they read are ready.

use std::collections::BTreeMap;
use std::fmt;

use super::control::{
    ASource, AccX, AccY, Accumulate, BSource, Control, Issue, Quantize, Read, ReadGate, RomRead,
    Write, WriteData, ADDRESS_BITS, PRODUCT_LATENCY,
};
use super::limbs;
use crate::gyro_loop::cic::{MAX_STAGES, MAX_TAPS};
use crate::gyro_loop::gyro::Plan;

/// The RAM's words: where each state lives.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Words {
    /// The drive demodulator's `I` and `Q` low-pass states.
    pub drive: [u8; 2],
    /// The sense demodulator's.
    pub sense: [u8; 2],
    /// The PLL's integrator.
    pub pll: u8,
    /// The AGC's integrator.
    pub agc: u8,
    /// The lock filters' `z_Q`, `z_A`.
    pub lock: [u8; 2],
    /// Per CIC (`I`, `Q`): the integrators `v_1..v_N`.
    pub integrators: [Vec<u8>; 2],
    /// Per CIC: each comb's value of the last decimation.
    pub combs: [Vec<u8>; 2],
    /// Per CIC: the compensator's delay line `c[m−1] .. c[m−T+1]`.
    pub line: [Vec<u8>; 2],
    /// In the folded pair, per CIC: the last integrator as of the decimating sample, then the
    /// combs' `c`, for the compensator of a later sample.
    pub fresh: Option<[u8; 2]>,
    /// In the folded pair, per CIC: the compensator's partial sum between two samples.
    pub partial: Option<[u8; 2]>,
    count: usize,
}

impl Words {
    /// A gyro's words from `first` on; `fresh` for a pair's deferred compensators.
    fn new(stages: usize, taps: usize, first: usize, fresh: bool) -> Words {
        let mut next = first;
        let mut take = || {
            next += 1;
            (next - 1) as u8
        };
        let drive = [take(), take()];
        let sense = [take(), take()];
        let pll = take();
        let agc = take();
        let lock = [take(), take()];
        let mut cic = || {
            let integrators: Vec<u8> = (0..stages).map(|_| take()).collect();
            let combs: Vec<u8> = (0..stages).map(|_| take()).collect();
            let line: Vec<u8> = (1..taps).map(|_| take()).collect();
            (integrators, combs, line)
        };
        let (i0, c0, l0) = cic();
        let (i1, c1, l1) = cic();
        let (fresh, partial) = if fresh {
            (Some([take(), take()]), Some([take(), take()]))
        } else {
            (None, None)
        };
        Words {
            drive,
            sense,
            pll,
            agc,
            lock,
            integrators: [i0, i1],
            combs: [c0, c1],
            line: [l0, l1],
            fresh,
            partial,
            count: next - first,
        }
    }

    /// Words used.
    pub fn count(&self) -> usize {
        self.count
    }
}

// The most states a plan has (eight words of the demodulators, PIs and lock filters, then per
// CIC its integrators, combs and delay line) fit a control word's address.
const _: () = assert!(
    8 + 2 * (2 * MAX_STAGES + MAX_TAPS - 1) <= 1 << ADDRESS_BITS,
    "a plan's states outgrow the control word's RAM address"
);

/// Why a plan has no folded schedule.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ScheduleError {
    /// The loop's CICs have a differential delay of 1; the schedule has no other.
    #[error("the folded loop's CICs need a differential delay of 1, not {0}")]
    DifferentialDelay(u32),
    /// A template found no free start (a bug in the templates).
    #[error("the folded loop's {0} found no free clock")]
    Unplaced(&'static str),
    /// The pair's deferred work outlasts the samples between two decimations.
    #[error("the folded pair's deferred work takes {segments} samples after a decimating one; the CIC decimates every {decimation}, so it needs a decimation of at least {need}", need = segments + 1)]
    Decimation {
        /// Samples the deferred work takes.
        segments: usize,
        /// The CIC's decimation.
        decimation: u32,
    },
    /// The pair's states outgrow the control word's RAM address.
    #[error("the folded pair's states take {0} RAM words; a control word addresses {max}", max = 1 << ADDRESS_BITS)]
    Words(usize),
}

/// Where a template landed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The template: `drive I`, `PLL`, `CIC I`, ….
    pub name: &'static str,
    /// Whose (0 gyro A, 1 gyro B).
    pub gyro: u8,
    /// Its first clock.
    pub first: usize,
    /// Its last clock.
    pub last: usize,
}

/// The folded loop's schedule: a control word per clock after a sample's `ce`.
///
/// One gyro ([`Schedule::new`]): every sample runs the regular part, a decimating one all of
/// `controls` (the combs, compensators and `1/SF` after it). The folded pair
/// ([`Schedule::pair`]): both gyros' regular parts, the combs in the decimating sample, and
/// the compensators and `1/SF` products deferred into the following samples' spare clocks
/// (`deferred`), so that no sample is longer than [`PAIR_SAMPLE_WORDS`] words.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Clock `t`'s control word in a decimating sample (`t` = 0: the clock after `ce`).
    pub controls: Vec<Control>,
    /// Clocks every sample runs; a decimating sample runs all of `controls`.
    pub regular: usize,
    /// The RAM's words (gyro A's in a pair).
    pub words: Words,
    /// Gyro B's RAM words, in a pair (after A's).
    pub words_b: Option<Words>,
    /// The pair's deferred work: segment `k` runs at clocks `regular..` of the `k + 1`-th
    /// sample after a decimating one (its words from `regular` on); the last one's sample
    /// publishes both gyros' rates. Empty for one gyro.
    pub deferred: Vec<Vec<Control>>,
    /// Each template's clocks, in the order they were placed (a deferred template's from the
    /// start of its sample).
    pub placements: Vec<Placement>,
}

/// Words a folded pair's sample may take: a 200 kHz ADC at 24 MHz is 120 clocks, two of
/// them the fetch and decode before the first word acts.
pub const PAIR_SAMPLE_WORDS: usize = 118;

/// A register whose value lives between clocks: a template holds it from its first load to
/// its last read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Register {
    Accumulator,
    ReadData,
    Reference,
    DemodProduct,
    DemodState,
    Integrator,
    Cic,
    CicOutput,
}

/// A piece of the loop's arithmetic: control fragments at clocks relative to its start.
#[derive(Clone, Debug)]
struct Template {
    name: &'static str,
    gyro: u8,
    ops: BTreeMap<u32, Control>,
}

impl Template {
    fn new(name: &'static str) -> Template {
        Template {
            name,
            gyro: 0,
            ops: BTreeMap::new(),
        }
    }

    /// The template as `gyro`'s: every unit it uses works on that gyro's registers.
    fn for_gyro(mut self, gyro: u8) -> Template {
        self.gyro = gyro;
        for c in self.ops.values_mut() {
            if c.rom != RomRead::None {
                c.rom_gyro = gyro;
            }
            if c.advance {
                c.advance_gyro = gyro;
            }
            if c.quantize != Quantize::None {
                c.quantize_gyro = gyro;
            }
            if let Some(issue) = c.issue.as_mut() {
                issue.gyro = gyro;
            }
            if let Some(op) = c.accumulate.as_mut() {
                op.gyro = gyro;
            }
            if let Some(read) = c.read.as_mut() {
                read.gyro = gyro;
            }
        }
        self
    }

    fn at(&mut self, t: u32, fragment: Control) {
        let merged = self
            .ops
            .get(&t)
            .map_or(Ok(fragment), |c| c.merge(&fragment))
            .unwrap_or_else(|busy| panic!("{}: {} twice at {t}", self.name, busy.0));
        self.ops.insert(t, merged);
    }

    fn rom(&mut self, t: u32, rom: RomRead) {
        self.at(
            t,
            Control {
                rom,
                ..Control::default()
            },
        );
    }

    fn accumulate(&mut self, t: u32, x: AccX, y: AccY) {
        let accumulate = Some(Accumulate { x, y, gyro: 0 });
        self.at(
            t,
            Control {
                accumulate,
                ..Control::default()
            },
        );
    }

    fn read(&mut self, t: u32, address: u8, gate: ReadGate, seen: u8) {
        let read = Some(Read {
            address,
            gate,
            seen,
            gyro: 0,
        });
        self.at(
            t,
            Control {
                read,
                ..Control::default()
            },
        );
    }

    fn write(&mut self, t: u32, address: u8, data: WriteData) {
        let write = Some(Write {
            address,
            data,
            decimating: false,
        });
        self.at(
            t,
            Control {
                write,
                ..Control::default()
            },
        );
    }

    fn quantize(&mut self, t: u32, quantize: Quantize) {
        self.at(
            t,
            Control {
                quantize,
                ..Control::default()
            },
        );
    }

    /// `a · b` issued from `start`, one limb a clock, accumulated from
    /// `start + PRODUCT_LATENCY` onto `first` (the first limb's base); returns the clock at
    /// which the accumulator holds the sum.
    fn product(
        &mut self,
        start: u32,
        a: ASource,
        a_width: u32,
        b: BSource,
        tap: u8,
        first: AccX,
    ) -> u32 {
        let l = limbs(a_width);
        for k in 0..l {
            let issue = Some(Issue {
                a,
                limb: k as u8,
                top: k + 1 == l,
                b,
                tap,
                gyro: 0,
            });
            self.at(
                start + k,
                Control {
                    issue,
                    ..Control::default()
                },
            );
            let x = if k == 0 { first } else { AccX::Keep };
            self.accumulate(start + PRODUCT_LATENCY + k, x, AccY::Product);
        }
        start + PRODUCT_LATENCY + l
    }

    /// The first clock of an op matching `predicate`.
    fn first(&self, predicate: impl Fn(&Control) -> bool) -> Option<u32> {
        self.ops.iter().find(|(_, c)| predicate(c)).map(|(t, _)| *t)
    }

    fn last(&self) -> u32 {
        self.ops.keys().next_back().copied().unwrap_or(0)
    }

    /// Each register's window: from its first load to the clock before its last read, the
    /// clocks in which no other template may load it.
    fn windows(&self) -> Vec<(Register, u32, u32)> {
        let mut loads: BTreeMap<Register, u32> = BTreeMap::new();
        let mut reads: BTreeMap<Register, u32> = BTreeMap::new();
        for (&t, c) in &self.ops {
            for r in loaded(c) {
                loads.entry(r).or_insert(t);
            }
            for (r, when) in used(c, t) {
                let last = reads.entry(r).or_insert(when);
                *last = (*last).max(when);
            }
        }
        loads
            .into_iter()
            .filter_map(|(r, load)| {
                let read = *reads.get(&r)?;
                (read > load).then_some((r, load, read - 1))
            })
            .collect()
    }
}

/// The registers `c` loads.
fn loaded(c: &Control) -> Vec<Register> {
    let mut out = Vec::new();
    if c.rom != RomRead::None {
        out.push(Register::Reference);
    }
    if c.read.is_some() {
        out.push(Register::ReadData);
    }
    if c.accumulate.is_some() {
        out.push(Register::Accumulator);
    }
    match c.quantize {
        Quantize::DemodProduct => out.push(Register::DemodProduct),
        Quantize::DemodState => out.push(Register::DemodState),
        Quantize::PllIntegrator | Quantize::AgcIntegrator => out.push(Register::Integrator),
        Quantize::Cic => out.push(Register::Cic),
        Quantize::CicOutput => out.push(Register::CicOutput),
        _ => {}
    }
    out
}

/// The registers `c` (at clock `t`) reads, and the clock whose value it reads.
fn used(c: &Control, t: u32) -> Vec<(Register, u32)> {
    let mut out = Vec::new();
    if let Some(issue) = c.issue {
        match issue.a {
            ASource::Read => out.push((Register::ReadData, t)),
            ASource::Cic => out.push((Register::Cic, t)),
            ASource::CicOutput => out.push((Register::CicOutput, t)),
            _ => {}
        }
        if issue.b == BSource::Reference {
            out.push((Register::Reference, t));
        }
    }
    if let Some(op) = c.accumulate {
        match op.x {
            AccX::Keep => out.push((Register::Accumulator, t)),
            AccX::Read | AccX::ReadLowpass | AccX::PllIntegrator | AccX::AgcIntegrator => {
                out.push((Register::ReadData, t));
            }
            AccX::PllSum | AccX::AgcSum => out.push((Register::Integrator, t)),
            AccX::Zero | AccX::Setpoint => {}
        }
        match op.y {
            AccY::NegRead | AccY::NegReadShifted => out.push((Register::ReadData, t)),
            AccY::PreviousRead => out.push((Register::ReadData, t - 1)),
            AccY::DemodProduct => out.push((Register::DemodProduct, t)),
            // Q_O's register holds the state of the clock before.
            AccY::NegDemodOutput | AccY::DemodOutput => out.push((Register::DemodState, t - 1)),
            _ => {}
        }
    }
    if let Some(write) = c.write {
        match write.data {
            WriteData::Read => out.push((Register::ReadData, t)),
            WriteData::Cic => out.push((Register::Cic, t)),
            WriteData::DemodState => out.push((Register::DemodState, t)),
            WriteData::Integrator => out.push((Register::Integrator, t)),
            _ => out.push((Register::Accumulator, t)),
        }
    }
    match c.quantize {
        Quantize::None => {}
        Quantize::DriveQ => out.push((Register::DemodState, t - 1)),
        _ => out.push((Register::Accumulator, t)),
    }
    out
}

/// The schedule under construction.
#[derive(Default)]
struct Timeline {
    controls: Vec<Control>,
    windows: Vec<(Register, u32, u32)>,
    placements: Vec<Placement>,
}

impl Timeline {
    fn fits(&self, template: &Template, start: u32) -> bool {
        let ops_fit = template.ops.iter().all(|(&t, c)| {
            let clock = (start + t) as usize;
            self.controls
                .get(clock)
                .is_none_or(|other| other.merge(c).is_ok())
        });
        ops_fit
            && template.windows().iter().all(|&(r, a, b)| {
                let (a, b) = (a + start, b + start);
                self.windows
                    .iter()
                    .all(|&(r2, a2, b2)| r2 != r || b < a2 || b2 < a)
            })
    }

    /// Places `template` at its earliest free start from `earliest` at which it ends before
    /// `limit`; returns the start, or `None` where there is none.
    fn place_before(
        &mut self,
        template: &Template,
        earliest: u32,
        limit: u32,
    ) -> Result<Option<u32>, ScheduleError> {
        let length = template.last() + 1;
        match (earliest..limit.saturating_sub(length) + 1).find(|&s| self.fits(template, s)) {
            Some(start) => self.place(template, start).map(Some),
            None => Ok(None),
        }
    }

    /// Places `template` at its earliest free start from `earliest`; returns the start.
    fn place(&mut self, template: &Template, earliest: u32) -> Result<u32, ScheduleError> {
        let start = (earliest..earliest + 4096)
            .find(|&s| self.fits(template, s))
            .ok_or(ScheduleError::Unplaced(template.name))?;
        for (&t, c) in &template.ops {
            let clock = (start + t) as usize;
            if self.controls.len() <= clock {
                self.controls.resize(clock + 1, Control::default());
            }
            self.controls[clock] = self.controls[clock]
                .merge(c)
                .expect("a fitting template merges");
        }
        self.windows.extend(
            template
                .windows()
                .into_iter()
                .map(|(r, a, b)| (r, a + start, b + start)),
        );
        self.placements.push(Placement {
            name: template.name,
            gyro: template.gyro,
            first: start as usize,
            last: (start + template.last()) as usize,
        });
        Ok(start)
    }
}

/// The operand widths the templates need.
struct Widths {
    adc: u32,
    demod_output: u32,
    agc_error: u32,
    amplitude: u32,
    cic: u32,
    cic_output: u32,
}

/// What the demodulator's state feeds.
#[derive(Clone, Copy)]
enum Consumer {
    /// `e_A = Q(setpoint − I)`.
    AmplitudeError,
    /// The PLL's error register.
    DriveQ,
    /// CIC `channel`'s integrators.
    Cic(usize),
}

fn demodulator(
    name: &'static str,
    rom: RomRead,
    a: ASource,
    word: u8,
    consumer: Consumer,
    widths: &Widths,
    words: &Words,
) -> Template {
    let mut t = Template::new(name);
    t.rom(0, rom);
    let done = t.product(1, a, widths.adc, BSource::Reference, 0, AccX::Zero);
    t.read(done - 1, word, ReadGate::Switch, 0);
    t.quantize(done, Quantize::DemodProduct);
    t.accumulate(done, AccX::ReadLowpass, AccY::NegRead);
    t.accumulate(done + 1, AccX::Keep, AccY::DemodProduct);
    t.quantize(done + 2, Quantize::DemodState);
    // The state register loads at done + 2 and is written back from it.
    t.write(done + 3, word, WriteData::DemodState);
    // The state register loads at done + 2; Q_O's register has its output from done + 4.
    let output = done + 4;
    match consumer {
        Consumer::AmplitudeError => {
            t.accumulate(output, AccX::Setpoint, AccY::NegDemodOutput);
            t.quantize(output + 1, Quantize::AmplitudeError);
        }
        Consumer::DriveQ => t.quantize(output, Quantize::DriveQ),
        Consumer::Cic(channel) => {
            // v_1 += x, v_j += v_(j−1) (the old values): stage j's sum at o_j, its word read
            // the clock before and written the clock after.
            for (j, &v) in words.integrators[channel].iter().enumerate() {
                let o = output + j as u32;
                t.read(o - 1, v, ReadGate::First, 0);
                let y = if j == 0 {
                    AccY::DemodOutput
                } else {
                    AccY::PreviousRead
                };
                t.accumulate(o, AccX::Read, y);
                t.write(o + 1, v, WriteData::AccCic);
            }
        }
    }
    t
}

/// A PI: `v ← clamp(Q(v + ki·e))`, `u = Q(kp·e + v)`.
struct Pi {
    name: &'static str,
    error: ASource,
    error_width: u32,
    gains: [BSource; 2],
    word: u8,
    gate: ReadGate,
    x: [AccX; 2],
    points: [Quantize; 2],
}

fn pi(p: &Pi) -> Template {
    let mut t = Template::new(p.name);
    // The integrator's word is in the read register when the first limb's product arrives.
    t.read(PRODUCT_LATENCY - 1, p.word, p.gate, 0);
    let update = t.product(0, p.error, p.error_width, p.gains[0], 0, p.x[0]);
    t.quantize(update, p.points[0]);
    t.write(update + 1, p.word, WriteData::Integrator);
    // kp·e's first product arrives the clock after the integrator register loads.
    let sum = t.product(
        update + 1 - PRODUCT_LATENCY,
        p.error,
        p.error_width,
        p.gains[1],
        0,
        p.x[1],
    );
    t.quantize(sum, p.points[1]);
    t
}

fn dac(widths: &Widths) -> Template {
    let mut t = Template::new("DAC");
    t.rom(0, RomRead::TransmitCos);
    let done = t.product(
        1,
        ASource::Amplitude,
        widths.amplitude,
        BSource::Reference,
        0,
        AccX::Zero,
    );
    t.quantize(done, Quantize::Dac);
    t
}

fn lock(words: &Words) -> Template {
    let mut t = Template::new("lock");
    let [zq, za] = words.lock;
    t.read(0, zq, ReadGate::Switch, 0);
    t.accumulate(1, AccX::Read, AccY::NegReadShifted);
    t.read(1, za, ReadGate::Switch, 0);
    t.accumulate(2, AccX::Keep, AccY::DriveQ);
    t.quantize(3, Quantize::LockQ);
    t.write(3, zq, WriteData::AccLock);
    t.accumulate(3, AccX::Read, AccY::NegReadShifted);
    t.accumulate(4, AccX::Keep, AccY::AmplitudeError);
    t.quantize(5, Quantize::LockA);
    t.write(5, za, WriteData::AccLock);
    t
}

/// The combs on the accumulator's value from clock 1 on: `w_j = w_(j−1) − (w_(j−1) one
/// decimation ago)`, each comb reading its word, subtracting it on the next clock and writing
/// the new value there. Returns the clock of the last comb's sum (1 with no comb).
fn comb_chain(t: &mut Template, combs: &[u8]) -> u32 {
    let mut op = 1;
    for (j, &word) in combs.iter().enumerate() {
        let read_clock = 1 + j as u32;
        t.read(read_clock, word, ReadGate::Seen, 1);
        op = read_clock + 1;
        t.accumulate(op, AccX::Keep, AccY::NegRead);
        t.write(op, word, WriteData::AccCic);
    }
    op
}

/// CIC `channel`'s decimation: the combs, the compensator, the `1/SF` product.
fn cic(channel: usize, widths: &Widths, words: &Words, taps: usize) -> Template {
    let name = ["CIC I", "CIC Q"][channel];
    let mut t = Template::new(name);
    let integrators = &words.integrators[channel];
    t.read(
        0,
        *integrators.last().expect("a CIC has a stage"),
        ReadGate::None,
        0,
    );
    t.accumulate(1, AccX::Read, AccY::Zero);
    let op = comb_chain(&mut t, &words.combs[channel]);
    let read_clock = op;
    let cic_ready = op + 1;
    t.quantize(cic_ready, Quantize::Cic);
    // The compensator: taps T−1 .. 1 from the delay line (read in that order, so that each
    // word moves one place on after it is read), then tap 0 on this decimation's c.
    let l = limbs(widths.cic);
    let line = &words.line[channel];
    // The first tap's product may arrive at the clock that quantizes c (which reads the
    // accumulator before it loads).
    let mut issue = (read_clock + 1).max(cic_ready.saturating_sub(PRODUCT_LATENCY));
    let mut first = AccX::Zero;
    for g in (1..taps).rev() {
        t.read(issue - 1, line[g - 1], ReadGate::Seen, g as u8);
        if g < taps - 1 {
            t.write(issue, line[g], WriteData::Read);
        }
        t.product(
            issue,
            ASource::Read,
            widths.cic,
            BSource::Tap,
            g as u8,
            first,
        );
        first = AccX::Keep;
        issue += l;
    }
    issue = issue.max(cic_ready + 1);
    if taps > 1 {
        t.write(issue, line[0], WriteData::Cic);
    }
    let fir = t.product(issue, ASource::Cic, widths.cic, BSource::Tap, 0, first);
    t.quantize(fir, Quantize::CicOutput);
    scale(&mut t, channel, fir + 1, widths);
    t
}

/// CIC `channel`'s snapshot in a pair: its last integrator, copied to the channel's `fresh`
/// word by a write that acts only in a decimating sample (placed after the integrator's update,
/// in the regular part's free read and write slots).
fn snapshot(channel: usize, words: &Words) -> Template {
    let mut t = Template::new(["snapshot I", "snapshot Q"][channel]);
    let last = *words.integrators[channel]
        .last()
        .expect("a CIC has a stage");
    t.read(0, last, ReadGate::None, 0);
    let fresh = words.fresh.expect("a pair's words have fresh words")[channel];
    t.at(
        1,
        Control {
            write: Some(Write {
                address: fresh,
                data: WriteData::Read,
                decimating: true,
            }),
            ..Control::default()
        },
    );
    t
}

/// CIC `channel`'s combs in a pair, a sample or more after its decimation: on the snapshot in
/// `fresh`, whose word then holds this decimation's `c`.
fn combs(channel: usize, words: &Words) -> Template {
    let mut t = Template::new(["combs I", "combs Q"][channel]);
    let fresh = words.fresh.expect("a pair's words have fresh words")[channel];
    t.read(0, fresh, ReadGate::None, 0);
    t.accumulate(1, AccX::Read, AccY::Zero);
    let op = comb_chain(&mut t, &words.combs[channel]);
    t.quantize(op + 1, Quantize::Cic);
    t.write(op + 2, fresh, WriteData::Cic);
    t
}

/// How a piece of a pair's compensator ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FirEnd {
    /// Its partial sum goes to the channel's `partial` word.
    Save,
    /// The sum is complete: the compensator's output point.
    Output,
}

/// A piece of CIC `channel`'s compensator in a pair: `taps` (descending) on the delay line and,
/// for tap 0, on `fresh` (which moves into the line); from the partial sum of the piece before
/// when `restore`.
fn fir_piece(
    channel: usize,
    widths: &Widths,
    words: &Words,
    taps: &[usize],
    all_taps: usize,
    restore: bool,
    end: FirEnd,
) -> Template {
    let mut t = Template::new(["compensator I", "compensator Q"][channel]);
    let l = limbs(widths.cic);
    let line = &words.line[channel];
    let fresh = words.fresh.expect("a pair's words have fresh words")[channel];
    let partial = words.partial.expect("a pair's words have partial words")[channel];
    let mut issue = 1;
    let mut first = AccX::Zero;
    if restore {
        t.read(0, partial, ReadGate::None, 0);
        t.accumulate(1, AccX::Read, AccY::Zero);
        issue = 2;
        first = AccX::Keep;
    }
    let mut sum = 0;
    for &g in taps {
        let (word, gate, seen) = if g == 0 {
            (fresh, ReadGate::None, 0)
        } else {
            (line[g - 1], ReadGate::Seen, g as u8)
        };
        t.read(issue - 1, word, gate, seen);
        if g < all_taps - 1 {
            t.write(issue, line[g], WriteData::Read);
        }
        sum = t.product(
            issue,
            ASource::Read,
            widths.cic,
            BSource::Tap,
            g as u8,
            first,
        );
        first = AccX::Keep;
        issue += l;
    }
    match end {
        FirEnd::Save => t.write(sum, partial, WriteData::AccFir),
        FirEnd::Output => t.quantize(sum, Quantize::CicOutput),
    }
    t
}

/// CIC `channel`'s `1/SF` product in a pair, on the compensator's output register.
fn scale_piece(channel: usize, widths: &Widths) -> Template {
    let mut t = Template::new(["1/SF I", "1/SF Q"][channel]);
    scale(&mut t, channel, 0, widths);
    t
}

/// The pieces of a pair's deferred work for one gyro's CIC `channel`, in order, each at most
/// `segment` clocks long where it can be: the combs, the compensator's taps in groups (partial
/// sums in RAM between them), the `1/SF` product.
fn deferred_pieces(
    channel: usize,
    widths: &Widths,
    words: &Words,
    taps: usize,
    segment: u32,
) -> Vec<Template> {
    let l = limbs(widths.cic);
    let mut pieces = vec![combs(channel, words)];
    let order: Vec<usize> = (0..taps).rev().collect();
    let mut done = 0;
    while done < taps {
        let restore = done > 0;
        // A group of k taps takes (restore) + 1 + k·l + PRODUCT_LATENCY + 1 clocks.
        let overhead = u32::from(restore) + 1 + PRODUCT_LATENCY + 1;
        let k = (segment.saturating_sub(overhead) / l).max(1) as usize;
        let k = k.min(taps - done);
        let end = if done + k == taps {
            FirEnd::Output
        } else {
            FirEnd::Save
        };
        pieces.push(fir_piece(
            channel,
            widths,
            words,
            &order[done..done + k],
            taps,
            restore,
            end,
        ));
        done += k;
    }
    pieces.push(scale_piece(channel, widths));
    pieces
}

/// The `1/SF` product of CIC `channel`'s compensator output, issued at `issue`.
fn scale(t: &mut Template, channel: usize, issue: u32, widths: &Widths) {
    let (coefficient, point) = if channel == 0 {
        (BSource::RateCoefficient, Quantize::Rate)
    } else {
        (BSource::QuadratureCoefficient, Quantize::Quadrature)
    };
    let out = t.product(
        issue,
        ASource::CicOutput,
        widths.cic_output,
        coefficient,
        0,
        AccX::Zero,
    );
    t.quantize(out, point);
}

impl Schedule {
    /// The schedule of `plan`'s folded loop.
    ///
    /// # Errors
    /// [`ScheduleError`] for a CIC whose differential delay is not 1.
    pub fn new(plan: &Plan) -> Result<Schedule, ScheduleError> {
        let taps = check(plan)?;
        let widths = Widths::of(plan);
        let words = Words::new(plan.cic.stages as usize, taps, 0, false);
        let mut line = Timeline::default();
        let order: Vec<(usize, Job)> = Job::ALL.iter().map(|&j| (0, j)).collect();
        place_regular(&mut line, &widths, &[&words], &order)?;
        let regular = line.controls.len();
        for channel in 0..2 {
            line.place(&cic(channel, &widths, &words, taps), regular as u32)?;
        }
        Ok(Schedule {
            controls: line.controls,
            regular,
            words,
            words_b: None,
            deferred: Vec::new(),
            placements: line.placements,
        })
    }

    /// The schedule of the folded pair: gyros A and B, whose plans have `plan`'s formats, on
    /// one datapath. Each sample runs both regular parts; the decimating one also the four
    /// CICs' combs, each writing its `c` to a RAM word; the compensators and `1/SF` products
    /// follow in the spare clocks of the next samples (`deferred`), packed so that no sample
    /// is longer than [`PAIR_SAMPLE_WORDS`] words if they can be.
    ///
    /// # Errors
    /// [`ScheduleError`] for a CIC whose differential delay is not 1, or states beyond the
    /// control word's RAM address.
    pub fn pair(plan: &Plan) -> Result<Schedule, ScheduleError> {
        let taps = check(plan)?;
        let widths = Widths::of(plan);
        let stages = plan.cic.stages as usize;
        let words = Words::new(stages, taps, 0, true);
        let words_b = Words::new(stages, taps, words.count(), true);
        let total = words.count() + words_b.count();
        if total > 1 << ADDRESS_BITS {
            return Err(ScheduleError::Words(total));
        }
        let banks = [&words, &words_b];
        let mut best: Option<Timeline> = None;
        for order in pair_orders(PAIR_ORDERS) {
            let mut candidate = Timeline::default();
            place_regular(&mut candidate, &widths, &banks, &order)?;
            if best
                .as_ref()
                .is_none_or(|b| candidate.controls.len() < b.controls.len())
            {
                best = Some(candidate);
            }
        }
        let mut line = best.expect("at least one order");
        let regular = line.controls.len();
        // The snapshots go in the regular part's free read and write slots, after the
        // integrators' last write.
        for (g, bank) in banks.iter().enumerate() {
            for channel in 0..2 {
                let last = *bank.integrators[channel].last().expect("a CIC has a stage");
                let written = line
                    .controls
                    .iter()
                    .rposition(|c| c.write.is_some_and(|w| w.address == last))
                    .expect("the integrator is written") as u32;
                line.place(&snapshot(channel, bank).for_gyro(g as u8), written + 1)?;
            }
        }
        let regular = regular.max(line.controls.len());
        line.controls.resize(regular, Control::default());
        let segment = (PAIR_SAMPLE_WORDS.saturating_sub(regular) as u32).max(MIN_SEGMENT);
        // Each piece with its CIC (gyro, channel): one CIC's pieces follow one another.
        let pieces: Vec<((usize, usize), Template)> = banks
            .iter()
            .enumerate()
            .flat_map(|(g, bank)| {
                let widths = &widths;
                (0..2).flat_map(move |channel| {
                    deferred_pieces(channel, widths, bank, taps, segment)
                        .into_iter()
                        .map(move |t| ((g, channel), t.for_gyro(g as u8)))
                })
            })
            .collect();
        let (deferred, placements) = pack(&pieces, regular as u32, segment)?;
        if deferred.len() >= plan.cic.decimation as usize {
            return Err(ScheduleError::Decimation {
                segments: deferred.len(),
                decimation: plan.cic.decimation,
            });
        }
        line.placements.extend(placements);
        Ok(Schedule {
            controls: line.controls,
            regular,
            words,
            words_b: Some(words_b),
            deferred,
            placements: line.placements,
        })
    }
}

/// Random job orders a pair's schedule tries beside the plain one.
const PAIR_ORDERS: usize = 64;

/// The shortest segment a pair gives its deferred work, clocks (a compensator piece of one
/// tap on a 40-bit CIC output and its overheads).
const MIN_SEGMENT: u32 = 12;

/// Packs `pieces`, in order, into segments of at most `segment` clocks after `regular`: each
/// piece at its earliest fit in the current segment no earlier than the piece before it (or
/// after its end, when it reads what that piece made: the same channel's), else in a new one.
/// Returns each segment's words (from `regular`) and the pieces' placements.
fn pack(
    pieces: &[((usize, usize), Template)],
    regular: u32,
    segment: u32,
) -> Result<(Vec<Vec<Control>>, Vec<Placement>), ScheduleError> {
    let limit = regular + segment;
    let mut segments: Vec<Timeline> = vec![Timeline::default()];
    let mut previous: Option<(u32, u32)> = None;
    for (i, (cic, piece)) in pieces.iter().enumerate() {
        // Pieces of one channel follow one another (they share its RAM words and registers);
        // the first piece of a channel reads nothing of the one before.
        let same_channel = i > 0 && pieces[i - 1].0 == *cic;
        let earliest = match previous {
            Some((start, end)) => {
                if same_channel {
                    end + 1
                } else {
                    start
                }
            }
            None => regular,
        };
        let current = segments.last_mut().expect("a segment");
        let start = match current.place_before(piece, earliest, limit)? {
            Some(s) => s,
            None => {
                let mut fresh = Timeline::default();
                let s = fresh
                    .place_before(piece, regular, limit.max(regular + piece.last() + 1))?
                    .ok_or(ScheduleError::Unplaced(piece.name))?;
                segments.push(fresh);
                s
            }
        };
        previous = Some((start, start + piece.last()));
    }
    let mut words = Vec::new();
    let mut placements = Vec::new();
    for s in segments {
        placements.extend(s.placements);
        words.push(s.controls[regular as usize..].to_vec());
    }
    Ok((words, placements))
}

/// The compensator taps of `plan`, or why it has no folded schedule.
fn check(plan: &Plan) -> Result<usize, ScheduleError> {
    if plan.cic.differential_delay != 1 {
        return Err(ScheduleError::DifferentialDelay(
            plan.cic.differential_delay,
        ));
    }
    Ok(plan.cic.taps.len())
}

impl Widths {
    fn of(plan: &Plan) -> Widths {
        let cic = &plan.cic;
        Widths {
            adc: plan.demodulator.input.width,
            demod_output: plan.demodulator.output.to.width,
            agc_error: plan.agc_error.to.width,
            amplitude: plan.agc.output.to.width,
            cic: cic.cic.to.width,
            cic_output: cic.output.to.width,
        }
    }
}

/// A piece of a gyro's regular part, placed as a whole: its templates and what they need ready.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Job {
    /// The drive demodulator's `I` and the AGC error.
    DriveI,
    /// The drive demodulator's `Q` (after `DriveI`'s sine read: the cosine read stores the
    /// reference's truncation error).
    DriveQ,
    /// The AGC and the DAC (after `DriveI`'s error).
    AgcDac,
    /// The sense demodulator's `I` and its CIC's integrators.
    SenseI,
    /// The sense demodulator's `Q` and its CIC's integrators (after `SenseI`'s sine read).
    SenseQ,
    /// The NCO's advance (after every ROM read), the PLL and the lock filters (after `DriveQ`).
    Finish,
}

impl Job {
    const ALL: [Job; 6] = [
        Job::DriveI,
        Job::DriveQ,
        Job::AgcDac,
        Job::SenseI,
        Job::SenseQ,
        Job::Finish,
    ];

    /// The jobs that must be placed before this one.
    fn after(self) -> &'static [Job] {
        match self {
            Job::DriveI | Job::SenseI => &[],
            Job::DriveQ | Job::AgcDac => &[Job::DriveI],
            Job::SenseQ => &[Job::SenseI],
            Job::Finish => &[Job::DriveQ, Job::AgcDac, Job::SenseQ],
        }
    }
}

/// When a gyro's values are ready, as its jobs are placed.
#[derive(Clone, Copy, Debug, Default)]
struct Ready {
    /// The drive reference's sine read.
    sin_d: u32,
    /// The sense reference's sine read.
    sin_s: u32,
    /// The AGC error's first reader may issue.
    error: u32,
    /// The PLL's error's first reader may issue.
    q: u32,
    /// The last ROM read (the NCO advances after it).
    last_rom: u32,
}

/// Places gyro `g`'s `job` (RAM words `words`) at its earliest free clock once what it reads
/// is ready, and records what it makes ready.
fn place_job(
    line: &mut Timeline,
    widths: &Widths,
    words: &Words,
    g: u8,
    job: Job,
    ready: &mut Ready,
) -> Result<(), ScheduleError> {
    let at = |template: &Template, start: u32, predicate: &dyn Fn(&Control) -> bool| {
        start + template.first(predicate).expect("the template has the op")
    };
    let is = |q: Quantize| move |c: &Control| c.quantize == q;
    let has_rom = |c: &Control| c.rom != RomRead::None;
    let demod = |name, rom, a, word, consumer| {
        demodulator(name, rom, a, word, consumer, widths, words).for_gyro(g)
    };
    match job {
        Job::DriveI => {
            let t = demod(
                "drive I",
                RomRead::DriveSin,
                ASource::AdcDrive,
                words.drive[0],
                Consumer::AmplitudeError,
            );
            let s = line.place(&t, 0)?;
            ready.sin_d = at(&t, s, &has_rom);
            ready.error = at(&t, s, &is(Quantize::AmplitudeError)) + 1;
        }
        Job::DriveQ => {
            let t = demod(
                "drive Q",
                RomRead::DriveCos,
                ASource::AdcDrive,
                words.drive[1],
                Consumer::DriveQ,
            );
            let s = line.place(&t, ready.sin_d + 1)?;
            ready.q = at(&t, s, &is(Quantize::DriveQ)) + 1;
            ready.last_rom = ready.last_rom.max(at(&t, s, &has_rom));
        }
        Job::AgcDac => {
            let agc = pi(&Pi {
                name: "AGC",
                error: ASource::AmplitudeError,
                error_width: widths.agc_error,
                gains: [BSource::AgcKi, BSource::AgcKp],
                word: words.agc,
                gate: ReadGate::Switch,
                x: [AccX::AgcIntegrator, AccX::AgcSum],
                points: [Quantize::AgcIntegrator, Quantize::AgcOutput],
            })
            .for_gyro(g);
            let s = line.place(&agc, ready.error)?;
            let amplitude_ready = at(&agc, s, &is(Quantize::AgcOutput)) + 1;
            let dac = dac(widths).for_gyro(g);
            let s = line.place(&dac, amplitude_ready - 1)?;
            ready.last_rom = ready.last_rom.max(at(&dac, s, &has_rom));
        }
        Job::SenseI => {
            let t = demod(
                "sense I",
                RomRead::SenseSin,
                ASource::AdcSense,
                words.sense[0],
                Consumer::Cic(0),
            );
            let s = line.place(&t, 0)?;
            ready.sin_s = at(&t, s, &has_rom);
            ready.last_rom = ready.last_rom.max(ready.sin_s);
        }
        Job::SenseQ => {
            let t = demod(
                "sense Q",
                RomRead::SenseCos,
                ASource::AdcSense,
                words.sense[1],
                Consumer::Cic(1),
            );
            let s = line.place(&t, ready.sin_s + 1)?;
            ready.last_rom = ready.last_rom.max(at(&t, s, &has_rom));
        }
        Job::Finish => {
            let mut advance = Template::new("NCO advance");
            advance.at(
                0,
                Control {
                    advance: true,
                    ..Control::default()
                },
            );
            let advanced = line.place(&advance.for_gyro(g), ready.last_rom)?;
            let pll = pi(&Pi {
                name: "PLL",
                error: ASource::DriveQ,
                error_width: widths.demod_output,
                gains: [BSource::PllKi, BSource::PllKp],
                word: words.pll,
                gate: ReadGate::Preset,
                x: [AccX::PllIntegrator, AccX::PllSum],
                points: [Quantize::PllIntegrator, Quantize::PllOutput],
            })
            .for_gyro(g);
            let output_at = pll
                .first(|c| c.quantize == Quantize::PllOutput)
                .unwrap_or(0);
            line.place(&pll, ready.q.max(advanced.saturating_sub(output_at)))?;
            let lock = lock(words).for_gyro(g);
            line.place(
                &lock,
                ready.q.saturating_sub(2).max(ready.error.saturating_sub(4)),
            )?;
        }
    }
    Ok(())
}

/// Places the regular part (every sample's work) of each gyro of `banks` (gyro `g`'s RAM words
/// `banks[g]`) on `line`, job by job in `order` (gyro, job).
fn place_regular(
    line: &mut Timeline,
    widths: &Widths,
    banks: &[&Words],
    order: &[(usize, Job)],
) -> Result<(), ScheduleError> {
    let mut ready = vec![Ready::default(); banks.len()];
    for &(g, job) in order {
        place_job(line, widths, banks[g], g as u8, job, &mut ready[g])?;
    }
    Ok(())
}

/// Orders of the pair's jobs tried: each gyro's jobs in `Job::ALL`'s order, interleaved, and
/// then random orders that keep every job after those it reads (from a fixed seed, so the
/// schedule is a function of the plan alone).
fn pair_orders(trials: usize) -> Vec<Vec<(usize, Job)>> {
    let mut orders = vec![(0..2)
        .flat_map(|g| Job::ALL.iter().map(move |&j| (g, j)))
        .collect::<Vec<_>>()];
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = move |n: usize| {
        // xorshift64*: portable, no platform dependence.
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 33) as usize % n
    };
    for _ in 0..trials {
        let mut placed: Vec<(usize, Job)> = Vec::new();
        while placed.len() < 2 * Job::ALL.len() {
            let candidates: Vec<(usize, Job)> = (0..2)
                .flat_map(|g| Job::ALL.iter().map(move |&j| (g, j)))
                .filter(|c| !placed.contains(c))
                .filter(|&(g, j)| j.after().iter().all(|&a| placed.contains(&(g, a))))
                .collect();
            placed.push(candidates[next(candidates.len())]);
        }
        orders.push(placed);
    }
    orders
}

impl Schedule {
    /// Clocks of the longest sample: a decimating one, or one that runs a deferred segment.
    pub fn len(&self) -> usize {
        self.deferred
            .iter()
            .map(|d| self.regular + d.len())
            .fold(self.controls.len(), usize::max)
    }

    /// Whether the schedule is empty (never: every loop has work).
    pub fn is_empty(&self) -> bool {
        self.controls.is_empty()
    }

    /// The segments after the regular part, in the order samples run them: the decimating
    /// sample's (one gyro's; the pair's decimating sample runs only the regular part), then
    /// the deferred ones.
    pub fn segments(&self) -> impl Iterator<Item = &[Control]> {
        let decimating = &self.controls[self.regular..];
        (!decimating.is_empty())
            .then_some(decimating)
            .into_iter()
            .chain(self.deferred.iter().map(|d| &d[..]))
    }

    /// The schedule ROM's words: the regular part, then each segment ([`Schedule::segments`])
    /// padded with idle words to `len() − regular`, so that segment `k`'s clock `t` is word
    /// `regular + k·(len() − regular) + (t − regular)`. One gyro's is `controls`.
    pub fn rom_words(&self) -> Vec<Control> {
        let segment = self.len() - self.regular;
        let mut words = self.controls[..self.regular].to_vec();
        for s in self.segments() {
            words.extend_from_slice(s);
            words.resize(words.len() + segment - s.len(), Control::default());
        }
        words
    }

    /// The schedule ROM's words, encoded.
    pub fn encoded(&self) -> Vec<u64> {
        self.rom_words().iter().map(Control::encode).collect()
    }

    /// RAM words of every gyro.
    pub fn ram_words(&self) -> usize {
        self.words.count() + self.words_b.as_ref().map_or(0, Words::count)
    }
}

impl fmt::Display for Schedule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} clocks every sample, {} in a decimating one; {} RAM words",
            self.regular,
            self.controls.len(),
            self.ram_words()
        )?;
        if !self.deferred.is_empty() {
            writeln!(
                f,
                "{} deferred segments of at most {} clocks after a decimating sample: {} clocks in the longest sample",
                self.deferred.len(),
                self.len() - self.regular,
                self.len()
            )?;
        }
        let pair = self.words_b.is_some();
        for p in &self.placements {
            let name = if pair {
                format!("{} {}", ["A", "B"][usize::from(p.gyro)], p.name)
            } else {
                p.name.to_string()
            };
            let width = if pair { 16 } else { 12 };
            writeln!(f, "  {name:<width$} clocks {:>3} to {:>3}", p.first, p.last)?;
        }
        Ok(())
    }
}
