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
    count: usize,
}

impl Words {
    fn new(stages: usize, taps: usize) -> Words {
        let mut next = 0usize;
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
        Words {
            drive,
            sense,
            pll,
            agc,
            lock,
            integrators: [i0, i1],
            combs: [c0, c1],
            line: [l0, l1],
            count: next,
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
}

/// Where a template landed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The template: `drive I`, `PLL`, `CIC I`, ….
    pub name: &'static str,
    /// Its first clock.
    pub first: usize,
    /// Its last clock.
    pub last: usize,
}

/// The folded loop's schedule: a control word per clock after a sample's `ce`.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Clock `t`'s control word (`t` = 0: the clock after `ce`).
    pub controls: Vec<Control>,
    /// Clocks every sample runs; a decimating sample runs all of `controls`.
    pub regular: usize,
    /// The RAM's words.
    pub words: Words,
    /// Each template's clocks, in the order they were placed.
    pub placements: Vec<Placement>,
}

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
    ops: BTreeMap<u32, Control>,
}

impl Template {
    fn new(name: &'static str) -> Template {
        Template {
            name,
            ops: BTreeMap::new(),
        }
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
        let accumulate = Some(Accumulate { x, y });
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
        let write = Some(Write { address, data });
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
    // w_j = w_(j−1) − (w_(j−1) one decimation ago): each comb reads its word, subtracts it
    // on the next clock and writes the new value there.
    let mut read_clock = 1;
    let mut op = 1;
    for &word in &words.combs[channel] {
        t.read(read_clock, word, ReadGate::Seen, 1);
        op = read_clock + 1;
        t.accumulate(op, AccX::Keep, AccY::NegRead);
        t.write(op, word, WriteData::AccCic);
        read_clock += 1;
    }
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
    let (coefficient, point) = if channel == 0 {
        (BSource::RateCoefficient, Quantize::Rate)
    } else {
        (BSource::QuadratureCoefficient, Quantize::Quadrature)
    };
    let out = t.product(
        fir + 1,
        ASource::CicOutput,
        widths.cic_output,
        coefficient,
        0,
        AccX::Zero,
    );
    t.quantize(out, point);
    t
}

impl Schedule {
    /// The schedule of `plan`'s folded loop.
    ///
    /// # Errors
    /// [`ScheduleError`] for a CIC whose differential delay is not 1.
    pub fn new(plan: &Plan) -> Result<Schedule, ScheduleError> {
        let cic_plan = &plan.cic;
        let taps = cic_plan.taps.len();
        if cic_plan.differential_delay != 1 {
            return Err(ScheduleError::DifferentialDelay(
                cic_plan.differential_delay,
            ));
        }
        let words = Words::new(cic_plan.stages as usize, taps);
        let widths = Widths {
            adc: plan.demodulator.input.width,
            demod_output: plan.demodulator.output.to.width,
            agc_error: plan.agc_error.to.width,
            amplitude: plan.agc.output.to.width,
            cic: cic_plan.cic.to.width,
            cic_output: cic_plan.output.to.width,
        };
        let mut line = Timeline {
            controls: Vec::new(),
            windows: Vec::new(),
            placements: Vec::new(),
        };
        let at = |template: &Template, start: u32, predicate: &dyn Fn(&Control) -> bool| {
            start + template.first(predicate).expect("the template has the op")
        };
        let is = |q: Quantize| move |c: &Control| c.quantize == q;
        let has_rom = |c: &Control| c.rom != RomRead::None;

        let drive_i = demodulator(
            "drive I",
            RomRead::DriveSin,
            ASource::AdcDrive,
            words.drive[0],
            Consumer::AmplitudeError,
            &widths,
            &words,
        );
        let s = line.place(&drive_i, 0)?;
        let sin_d = at(&drive_i, s, &has_rom);
        let error_ready = at(&drive_i, s, &is(Quantize::AmplitudeError)) + 1;

        let drive_q = demodulator(
            "drive Q",
            RomRead::DriveCos,
            ASource::AdcDrive,
            words.drive[1],
            Consumer::DriveQ,
            &widths,
            &words,
        );
        let s = line.place(&drive_q, sin_d + 1)?;
        let q_ready = at(&drive_q, s, &is(Quantize::DriveQ)) + 1;
        let mut last_rom = at(&drive_q, s, &has_rom);

        let agc = pi(&Pi {
            name: "AGC",
            error: ASource::AmplitudeError,
            error_width: widths.agc_error,
            gains: [BSource::AgcKi, BSource::AgcKp],
            word: words.agc,
            gate: ReadGate::Switch,
            x: [AccX::AgcIntegrator, AccX::AgcSum],
            points: [Quantize::AgcIntegrator, Quantize::AgcOutput],
        });
        let s = line.place(&agc, error_ready)?;
        let amplitude_ready = at(&agc, s, &is(Quantize::AgcOutput)) + 1;

        let dac = dac(&widths);
        let s = line.place(&dac, amplitude_ready - 1)?;
        last_rom = last_rom.max(at(&dac, s, &has_rom));

        let sense_i = demodulator(
            "sense I",
            RomRead::SenseSin,
            ASource::AdcSense,
            words.sense[0],
            Consumer::Cic(0),
            &widths,
            &words,
        );
        let s = line.place(&sense_i, 0)?;
        let sin_s = at(&sense_i, s, &has_rom);
        last_rom = last_rom.max(sin_s);
        let sense_q = demodulator(
            "sense Q",
            RomRead::SenseCos,
            ASource::AdcSense,
            words.sense[1],
            Consumer::Cic(1),
            &widths,
            &words,
        );
        let s = line.place(&sense_q, sin_s + 1)?;
        last_rom = last_rom.max(at(&sense_q, s, &has_rom));

        let mut advance = Template::new("NCO advance");
        advance.at(
            0,
            Control {
                advance: true,
                ..Control::default()
            },
        );
        let advanced = line.place(&advance, last_rom)?;

        let pll = pi(&Pi {
            name: "PLL",
            error: ASource::DriveQ,
            error_width: widths.demod_output,
            gains: [BSource::PllKi, BSource::PllKp],
            word: words.pll,
            gate: ReadGate::Preset,
            x: [AccX::PllIntegrator, AccX::PllSum],
            points: [Quantize::PllIntegrator, Quantize::PllOutput],
        });
        let output_at = pll
            .first(|c| c.quantize == Quantize::PllOutput)
            .unwrap_or(0);
        line.place(&pll, q_ready.max(advanced.saturating_sub(output_at)))?;

        let lock = lock(&words);
        line.place(
            &lock,
            q_ready.saturating_sub(2).max(error_ready.saturating_sub(4)),
        )?;

        let regular = line.controls.len();
        for channel in 0..2 {
            line.place(&cic(channel, &widths, &words, taps), regular as u32)?;
        }
        Ok(Schedule {
            controls: line.controls,
            regular,
            words,
            placements: line.placements,
        })
    }

    /// Clocks of a decimating sample (the longest).
    pub fn len(&self) -> usize {
        self.controls.len()
    }

    /// Whether the schedule is empty (never: every loop has work).
    pub fn is_empty(&self) -> bool {
        self.controls.is_empty()
    }

    /// The schedule ROM's words.
    pub fn encoded(&self) -> Vec<u64> {
        self.controls.iter().map(Control::encode).collect()
    }
}

impl fmt::Display for Schedule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} clocks every sample, {} in a decimating one; {} RAM words",
            self.regular,
            self.len(),
            self.words.count()
        )?;
        for p in &self.placements {
            writeln!(f, "  {:<12} clocks {:>3} to {:>3}", p.name, p.first, p.last)?;
        }
        Ok(())
    }
}
