//! [`Spec`] → [`Plan`]: the blocks' plans, the per-mode presets, offsets and `1/SF`
//! coefficients, and the PI gains, all designed from the nominal physics (equations in the
//! [module doc](super)).

use std::f64::consts::PI;

use super::design::{dac_offset, trimmed_sense_offset, Design, LockPlan, ModePlan, PhaseInputs};
use super::mode_index;
use super::settings::{format, LoopSettings};
use crate::fx::{from_f64, CoefficientFormat, Format, Overflow, Rounding};
use crate::gyro_loop::{
    cic, demodulator, field_error, nco, pi, quantize_coefficients, Coefficient, PlanError, Point,
};
use crate::resonator::{Mode, ModeFigures, PhysicsSettings, ResonatorParams};

/// Largest `adc_to_dac_latency_samples`.
pub const MAX_LATENCY: u32 = 8;

/// What one gyro's loop is asked to be: its settings and the nominal physics it is designed
/// from (the resonator and its front end: pick-off gains, ADC, DAC).
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The `[loop]` settings.
    pub settings: LoopSettings,
    /// The nominal resonator.
    pub resonator: ResonatorParams,
    /// The nominal front end (its noise and drift settings do not matter here).
    pub front_end: PhysicsSettings,
}

impl Spec {
    /// Paper 004 with [`LoopSettings::default`] and [`PhysicsSettings::example`].
    pub fn paper_004() -> Self {
        Spec {
            settings: LoopSettings::default(),
            resonator: ResonatorParams::paper_004(),
            front_end: PhysicsSettings::example(),
        }
    }
}

/// The resolved loop.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The settings it was resolved from.
    pub settings: LoopSettings,
    /// `fs`, Hz.
    pub adc_rate_hz: f64,
    /// `L`.
    pub latency: u32,
    /// ADC codes.
    pub adc: Format,
    /// The three NCOs.
    pub nco: nco::Plan,
    /// Both demodulators.
    pub demodulator: demodulator::Plan,
    /// PLL: `Q_D` in, frequency word `s P.P` out.
    pub pll: pi::Plan,
    /// AGC: `e_A` in, `u` out.
    pub agc: pi::Plan,
    /// `a_set − I_D` → demodulator output format.
    pub agc_error: Point,
    /// `u · cos` → DAC format.
    pub dac: Point,
    /// Both CICs (`I_S`, `Q_S`).
    pub cic: cic::Plan,
    /// `c · y_CIC` → output format.
    pub output: Point,
    /// Lock detector.
    pub lock: LockPlan,
    /// Normal, reverse.
    pub modes: [ModePlan; 2],
    /// The unquantized design values.
    pub design: Design,
    /// DAC force per LSB, N (the twin's DAC).
    pub dac_newton_per_lsb: f64,
    /// ADC full scale, V (the twin's ADC).
    pub adc_full_scale_v: f64,
}

/// Largest share of the AGC output's or the DAC's full scale the nominal drive may take.
const AMPLITUDE_HEADROOM: f64 = 0.8;

/// The `[loop]` key behind each field a block's plan names, per block: a refused sub-plan is
/// reported as the config key the user wrote (`loop.nco_phase_bits`, not the block's own
/// `nco.phase_bits`).
type Keys = &'static [(&'static str, &'static str)];
const NCO_KEYS: Keys = &[
    ("phase_bits", "nco_phase_bits"),
    ("address_bits", "nco_address_bits"),
    ("sine_width", "nco_sine_width"),
    ("error_feedback", "nco_error_feedback"),
];
const DEMODULATOR_KEYS: Keys = &[
    ("input_format", "adc_format"),
    ("reference_format", "nco_sine_width"),
    ("product_format", "demod_product_format"),
    ("state_format", "demod_state_format"),
    ("output_format", "demod_output_format"),
    ("lowpass_shift", "demod_lowpass_shift"),
];
const CIC_KEYS: Keys = &[
    ("input_format", "demod_output_format"),
    ("stages", "cic_stages"),
    ("decimation", "decimation"),
    ("taps", "cic_taps"),
    ("coefficient taps", "cic_tap_width"),
    ("passband", "cic_passband"),
    ("cic_output_format", "cic_internal_format"),
    ("output_format", "cic_output_format"),
];
const PLL_KEYS: Keys = &[
    ("input_format", "demod_output_format"),
    ("coefficient kp", "pll_gain_width"),
    ("coefficient ki", "pll_gain_width"),
    ("integrator_format", "pll_integrator_format"),
    ("integrator_limits", "pll_pull_range_hz"),
    ("preset", "pll_integrator_format"),
    ("output_format", "nco_phase_bits"),
];
const AGC_KEYS: Keys = &[
    ("input_format", "demod_output_format"),
    ("coefficient kp", "agc_gain_width"),
    ("coefficient ki", "agc_gain_width"),
    ("integrator_format", "agc_integrator_format"),
    ("integrator_limits", "dac_format"),
    ("output_format", "agc_output_format"),
];

/// Renames a block's refusal to the `[loop]` key of `keys` (a coefficient's entry is
/// `"coefficient NAME"`): a field error keeps its value and what is allowed; a coefficient that
/// does not fit or rounds to zero names the width key that sizes it.
fn config_key(keys: Keys) -> impl Fn(PlanError) -> PlanError {
    move |error| {
        let key = |name: &str| keys.iter().find(|(field, _)| *field == name).map(|k| k.1);
        match &error {
            PlanError::Field {
                field,
                value,
                allowed,
                ..
            } => match key(field) {
                Some(key) => field_error("loop", key, value, allowed.clone()),
                None => error,
            },
            PlanError::CoefficientOverflow { name, format, .. }
            | PlanError::CoefficientZero { name, format, .. } => {
                let Some(key) = key(&format!("coefficient {name}")) else {
                    return error.clone();
                };
                let block = key.split('_').next().unwrap_or("loop");
                let allowed = match &error {
                    PlanError::CoefficientOverflow {
                        value, bits_needed, ..
                    } => format!(
                        "a width that holds the designed {block} {name} = {value:e}: it needs {bits_needed} bits in {format}"
                    ),
                    PlanError::CoefficientZero { value, .. } => format!(
                        "a width at which the designed {block} {name} = {value:e} does not round to zero (it does in {format})"
                    ),
                    _ => unreachable!("the arm matched a coefficient error"),
                };
                field_error("loop", key, format.width, allowed)
            }
            PlanError::Intermediate { .. } => error,
        }
    }
}

fn positive(field: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(field_error("loop", field, value, "a finite value above 0"))
    }
}

fn word(nco: &nco::Plan, cycles: f64) -> Result<u64, PlanError> {
    nco.offset_word(cycles * 360.0)
}

impl Plan {
    /// Validates `spec`, designs the gains, presets, offsets and coefficients, and resolves
    /// every block.
    ///
    /// # Errors
    /// [`PlanError::Field`] for a setting out of range, a format that does not parse, a
    /// front end that does not match (`adc_rate_hz`, `adc_format`) or invalid physics;
    /// [`PlanError::CoefficientOverflow`] for a gain, preset or `1/SF` that does not fit.
    pub fn new(spec: &Spec) -> Result<Plan, PlanError> {
        let s = &spec.settings;
        let (params, front) = (&spec.resonator, &spec.front_end);
        let checked = Checked::new(spec)?;
        let blocks = LeafBlocks::new(s, &checked)?;
        let figures = [Mode::Normal, Mode::Reverse].map(|m| ModeFigures::new(params, m));
        let (a_nco, cic_gain) = (blocks.nco.amplitude(), blocks.cic.flatness().dc_gain);
        let physics =
            figures.map(|f| ModePhysics::new(&f, params, front, a_nco, cic_gain, checked.fs));
        let (pll, pll_gains, pll_limits) = pll_plan(s, &checked, &blocks, &physics)?;
        let drive = Drive::new(s, &checked, &blocks, &physics[0])?;
        let (coefficients, output) = output_stage(s, &checked, &blocks, &physics)?;
        let lock = lock_plan(s, &checked, blocks.demod_output)?;
        let mut modes = Vec::with_capacity(2);
        for (i, f) in figures.iter().enumerate() {
            modes.push(mode_plan(
                spec,
                &checked,
                &blocks,
                &pll,
                &drive,
                (f, &physics[i]),
                [coefficients[i], coefficients[2 + i]],
            )?);
        }
        let modes: [ModePlan; 2] = [modes[0], modes[1]];
        debug_assert_eq!(mode_index(modes[1].mode), 1);
        Ok(Plan {
            settings: s.clone(),
            adc_rate_hz: checked.fs,
            latency: s.adc_to_dac_latency_samples,
            adc: checked.adc,
            nco: blocks.nco,
            demodulator: blocks.demodulator,
            pll,
            agc: drive.agc,
            agc_error: drive.agc_error,
            dac: drive.dac_point,
            cic: blocks.cic,
            output,
            lock,
            modes,
            design: Design {
                pll_gains,
                agc_gains: drive.gains,
                pll_limits,
                agc_limits: drive.limits,
            },
            dac_newton_per_lsb: front.dac_newton_per_lsb,
            adc_full_scale_v: front.adc_full_scale_v,
        })
    }

    /// The plan of `mode`.
    pub fn mode(&self, mode: Mode) -> &ModePlan {
        &self.modes[mode_index(mode)]
    }

    /// The chain's rate `fs / R`, Hz.
    pub fn chain_rate_hz(&self) -> f64 {
        self.adc_rate_hz / f64::from(self.cic.decimation)
    }
}

/// The settings checked one by one, in the order a refusal names the first bad one: the
/// physics, the modes, the ADC, the latency, then the positive design values.
struct Checked {
    rounding: Rounding,
    overflow: Overflow,
    /// `fs`, Hz.
    fs: f64,
    adc: Format,
    /// Hz.
    pll_bandwidth: f64,
    /// Hz.
    agc_bandwidth: f64,
    /// Hz either side of the two modes' frequencies.
    pull: f64,
    /// Degrees.
    lock_phase: f64,
    /// Share of the setpoint.
    lock_tolerance: f64,
    /// Milliseconds.
    hold_ms: f64,
}

impl Checked {
    fn new(spec: &Spec) -> Result<Checked, PlanError> {
        let s = &spec.settings;
        let (params, front) = (&spec.resonator, &spec.front_end);
        params
            .validate()
            .and_then(|_| front.validate(params))
            .map_err(|e| match e {
                crate::resonator::ParamError::Range {
                    field,
                    value,
                    allowed,
                } => field_error("resonator", field, value, allowed),
            })?;
        let rounding = s.rounding_mode()?;
        let overflow = s.overflow_mode()?;
        let fs = positive("adc_rate_hz", s.adc_rate_hz)?;
        if fs != front.sample_rate_hz {
            return Err(field_error(
                "loop",
                "adc_rate_hz",
                fs,
                format!("the resonator's sample rate, {} Hz", front.sample_rate_hz),
            ));
        }
        let adc = format("adc_format", &s.adc_format)?;
        let w = front.adc_width;
        if !adc.signed || adc.width != w || adc.frac != w as i32 - 1 {
            return Err(field_error(
                "loop",
                "adc_format",
                adc,
                format!("s{w}.{} (the resonator's ADC in full-scale units)", w - 1),
            ));
        }
        if s.adc_to_dac_latency_samples > MAX_LATENCY {
            return Err(field_error(
                "loop",
                "adc_to_dac_latency_samples",
                s.adc_to_dac_latency_samples,
                format!("0..={MAX_LATENCY}"),
            ));
        }
        Ok(Checked {
            rounding,
            overflow,
            fs,
            adc,
            pll_bandwidth: positive("pll_bandwidth_hz", s.pll_bandwidth_hz)?,
            agc_bandwidth: positive("agc_bandwidth_hz", s.agc_bandwidth_hz)?,
            pull: positive("pll_pull_range_hz", s.pll_pull_range_hz)?,
            lock_phase: positive("lock_phase_deg", s.lock_phase_deg)?,
            lock_tolerance: positive("lock_amplitude_tolerance", s.lock_amplitude_tolerance)?,
            hold_ms: positive("lock_hold_ms", s.lock_hold_ms)?,
        })
    }
}

/// The blocks whose plans follow from the settings alone: the NCOs, the demodulators and the
/// CICs.
struct LeafBlocks {
    nco: nco::Plan,
    demodulator: demodulator::Plan,
    /// The demodulators' output format, which the PIs, the lock detector and the CICs take.
    demod_output: Format,
    cic: cic::Plan,
}

impl LeafBlocks {
    fn new(s: &LoopSettings, checked: &Checked) -> Result<LeafBlocks, PlanError> {
        let (rounding, overflow) = (checked.rounding, checked.overflow);
        let nco = nco::Plan::new(&nco::Spec {
            phase_bits: s.nco_phase_bits,
            address_bits: s.nco_address_bits,
            sine_width: s.nco_sine_width,
            error_feedback: s.nco_error_feedback,
        })
        .map_err(config_key(NCO_KEYS))?;
        let demod_output = format("demod_output_format", &s.demod_output_format)?;
        let demodulator = demodulator::Plan::new(&demodulator::Spec {
            input: checked.adc,
            reference: nco.output,
            product: format("demod_product_format", &s.demod_product_format)?,
            state: format("demod_state_format", &s.demod_state_format)?,
            output: demod_output,
            lowpass_shift: s.demod_lowpass_shift,
            rounding,
            overflow,
        })
        .map_err(config_key(DEMODULATOR_KEYS))?;
        let cic = cic::Plan::new(&cic::Spec {
            input: demod_output,
            stages: s.cic_stages,
            decimation: s.decimation,
            differential_delay: 1,
            shift: None,
            cic_output: format("cic_internal_format", &s.cic_internal_format)?,
            taps: s.cic_taps,
            passband: s.cic_passband,
            coefficients: CoefficientFormat::Auto {
                width: s.cic_tap_width,
            },
            output: format("cic_output_format", &s.cic_output_format)?,
            rounding,
            overflow,
        })
        .map_err(config_key(CIC_KEYS))?;
        Ok(LeafBlocks {
            nco,
            demodulator,
            demod_output,
            cic,
        })
    }
}

/// One mode's nominal physics as the loop sees it, in ADC full-scale units.
struct ModePhysics {
    /// The drive frequency, Hz.
    frequency_hz: f64,
    /// The drive mode's ring-down time constant, s.
    tau: f64,
    /// The drive amplitude the AGC holds, `I_D` (full scale).
    setpoint: f64,
    /// `I_D` per DAC LSB of drive, at steady state.
    plant_gain: f64,
    /// The sense channel's output per °/s, after the CIC.
    sense: f64,
}

impl ModePhysics {
    fn new(
        f: &ModeFigures,
        params: &ResonatorParams,
        front: &PhysicsSettings,
        a_nco: f64,
        cic_gain: f64,
        fs: f64,
    ) -> ModePhysics {
        let per_fs = |axis: usize| front.pickoff_gain_v_per_m[axis] / front.adc_full_scale_v;
        let [driven, sensed] = f.mode.axes();
        let f_nom = f.drive_frequency_hz();
        let x = PI * f_nom / fs;
        let hold_gain = libm::sin(x) / x;
        let tau = f.ring_down_time_constant;
        let setpoint = per_fs(driven) * params.drive_amplitude_m * a_nco;
        let plant_gain =
            per_fs(driven) * a_nco * a_nco * front.dac_newton_per_lsb * hold_gain * tau
                / (2.0 * params.mass_kg * f.drive_angular_frequency);
        let sense = per_fs(sensed) * a_nco * f.scale_factor_m_per_dps() * cic_gain;
        ModePhysics {
            frequency_hz: f_nom,
            tau,
            setpoint,
            plant_gain,
            sense,
        }
    }
}

/// The PLL, designed on the normal mode: its plan, its gains `[kp, ki]` and its integrator's
/// limits (cycles per sample) around both modes' frequencies.
fn pll_plan(
    s: &LoopSettings,
    checked: &Checked,
    blocks: &LeafBlocks,
    physics: &[ModePhysics; 2],
) -> Result<(pi::Plan, [f64; 2], [f64; 2]), PlanError> {
    let (fs, pull) = (checked.fs, checked.pull);
    let (tau, setpoint) = (physics[0].tau, physics[0].setpoint);
    let kp = checked.pll_bandwidth / (fs * setpoint);
    let ki = kp / (tau * fs);
    let frequencies = [physics[0].frequency_hz, physics[1].frequency_hz];
    let lowest = frequencies[0].min(frequencies[1]) - pull;
    let highest = frequencies[0].max(frequencies[1]) + pull;
    if lowest <= 0.0 || highest >= fs / 2.0 {
        return Err(field_error(
            "loop",
            "pll_pull_range_hz",
            pull,
            format!("a range within (0, fs/2) around {lowest} .. {highest} Hz"),
        ));
    }
    let p = blocks.nco.phase.width;
    let pll_limits = [lowest / fs, highest / fs];
    let pll = pi::Plan::new(&pi::Spec {
        input: blocks.demod_output,
        kp,
        ki,
        kp_format: CoefficientFormat::Auto {
            width: s.pll_gain_width,
        },
        ki_format: CoefficientFormat::Auto {
            width: s.pll_gain_width,
        },
        integrator: format("pll_integrator_format", &s.pll_integrator_format)?,
        integrator_limits: pll_limits,
        output: Format::signed(p, p as i32).expect("the NCO checked P"),
        rounding: checked.rounding,
        overflow: checked.overflow,
    })
    .map_err(config_key(PLL_KEYS))?;
    if pll.integrator.frac < p as i32 {
        return Err(field_error(
            "loop",
            "pll_integrator_format",
            pll.integrator,
            format!(
                "at least nco_phase_bits = {p} fraction bits (the integrator must resolve the \
                 NCO's frequency step, 2^-{p} cycles per sample)"
            ),
        ));
    }
    Ok((pll, [kp, ki], pll_limits))
}

/// The drive: the AGC designed on the normal mode, its error point and the DAC's.
struct Drive {
    agc: pi::Plan,
    /// `a_set − I_D` → the demodulator output format.
    agc_error: Point,
    dac: Format,
    /// `u · cos` → the DAC format.
    dac_point: Point,
    /// `[kp, ki]`.
    gains: [f64; 2],
    limits: [f64; 2],
}

impl Drive {
    fn new(
        s: &LoopSettings,
        checked: &Checked,
        blocks: &LeafBlocks,
        normal: &ModePhysics,
    ) -> Result<Drive, PlanError> {
        let (rounding, overflow) = (checked.rounding, checked.overflow);
        let (fs, demod_output) = (checked.fs, blocks.demod_output);
        let dac = format("dac_format", &s.dac_format)?;
        let agc_kp = 2.0 * PI * checked.agc_bandwidth * normal.tau / normal.plant_gain;
        let agc_ki = agc_kp / (normal.tau * fs);
        let limits = [0.0, dac.max_value()];
        let agc = pi::Plan::new(&pi::Spec {
            input: demod_output,
            kp: agc_kp,
            ki: agc_ki,
            kp_format: CoefficientFormat::Auto {
                width: s.agc_gain_width,
            },
            ki_format: CoefficientFormat::Auto {
                width: s.agc_gain_width,
            },
            integrator: format("agc_integrator_format", &s.agc_integrator_format)?,
            integrator_limits: limits,
            output: format("agc_output_format", &s.agc_output_format)?,
            rounding,
            overflow,
        })
        .map_err(config_key(AGC_KEYS))?;
        let error_exact = Format::sum(demod_output, demod_output, true)
            .map_err(crate::gyro_loop::intermediate("loop", "a_set - I"))?;
        let agc_error = Point::new(
            "loop",
            "demod_output_format",
            error_exact,
            demod_output,
            rounding,
            overflow,
        )?;
        let drive_exact = Format::product(agc.output.to, blocks.nco.output)
            .map_err(crate::gyro_loop::intermediate("loop", "u * cos"))?;
        let dac_point = Point::new("loop", "dac_format", drive_exact, dac, rounding, overflow)?;
        Ok(Drive {
            agc,
            agc_error,
            dac,
            dac_point,
            gains: [agc_kp, agc_ki],
            limits,
        })
    }
}

/// The `1/SF` coefficients in one format (rate normal, rate reverse, quadrature normal,
/// quadrature reverse) and the output point `c · y_CIC`.
fn output_stage(
    s: &LoopSettings,
    checked: &Checked,
    blocks: &LeafBlocks,
    physics: &[ModePhysics; 2],
) -> Result<(Vec<Coefficient>, Point), PlanError> {
    let sigma = [1.0, -1.0];
    let coefficient_values = [
        sigma[0] / physics[0].sense,
        sigma[1] / physics[1].sense,
        -1.0 / physics[0].sense,
        -1.0 / physics[1].sense,
    ];
    let coefficients = quantize_coefficients(
        "loop",
        "scale_coefficients",
        &coefficient_values,
        match &s.scale_coefficient_format {
            Some(text) => CoefficientFormat::Fixed(format("scale_coefficient_format", text)?),
            None => CoefficientFormat::Auto {
                width: s.scale_coefficient_width,
            },
        },
    )?;
    let output_format = format("output_format", &s.output_format)?;
    let output_exact = Format::product(blocks.cic.output.to, coefficients[0].format)
        .map_err(crate::gyro_loop::intermediate("loop", "c * y"))?;
    let output = Point::new(
        "loop",
        "output_format",
        output_exact,
        output_format,
        checked.rounding,
        checked.overflow,
    )?;
    Ok((coefficients, output))
}

/// The lock detector: its filter shift and hold time in samples.
fn lock_plan(
    s: &LoopSettings,
    checked: &Checked,
    demod_output: Format,
) -> Result<LockPlan, PlanError> {
    let shift = s.lock_filter_shift;
    if shift == 0 || demod_output.width + shift + 1 > 64 {
        return Err(field_error(
            "loop",
            "lock_filter_shift",
            shift,
            format!(
                "1..={} (the filter state has demod_output width + s + 1 bits, at most 64)",
                63 - demod_output.width
            ),
        ));
    }
    let hold = libm::round(checked.hold_ms * 1e-3 * checked.fs);
    if hold > f64::from(u32::MAX) {
        return Err(field_error(
            "loop",
            "lock_hold_ms",
            checked.hold_ms,
            "below 2^32 samples",
        ));
    }
    Ok(LockPlan {
        shift,
        hold_samples: hold as u32,
    })
}

/// `value` as a code of `to`, refused (naming `field`) where it does not fit.
fn code(value: f64, to: Format, field: &'static str) -> Result<i64, PlanError> {
    let q = from_f64(value, to, Rounding::Convergent, Overflow::Saturate)
        .map_err(|_| field_error("loop", field, value, "a finite number"))?;
    if q.overflowed {
        return Err(field_error(
            "loop",
            field,
            value,
            format!("a value that fits {to}"),
        ));
    }
    Ok(q.code as i64)
}

/// One mode's presets, offsets, coefficients and lock limits. `coefficients` is its rate and
/// quadrature `1/SF`.
fn mode_plan(
    spec: &Spec,
    checked: &Checked,
    blocks: &LeafBlocks,
    pll: &pi::Plan,
    drive: &Drive,
    (f, physics): (&ModeFigures, &ModePhysics),
    coefficients: [Coefficient; 2],
) -> Result<ModePlan, PlanError> {
    let s = &spec.settings;
    let (fs, demod_output, nco) = (checked.fs, blocks.demod_output, &blocks.nco);
    let (agc, dac) = (&drive.agc, drive.dac);
    let f_nom = physics.frequency_hz;
    let (setpoint, plant_gain) = (physics.setpoint, physics.plant_gain);
    let nominal_amplitude = setpoint / plant_gain;
    // The AGC must reach the amplitude that holds q0 with room for its transients.
    let (limit_key, limit) = if agc.output.to.max_value() < dac.max_value() {
        ("agc_output_format", agc.output.to)
    } else {
        ("dac_format", dac)
    };
    if nominal_amplitude > AMPLITUDE_HEADROOM * limit.max_value() {
        return Err(field_error(
            "loop",
            limit_key,
            limit,
            format!(
                "a format whose largest value is at least {:.0} LSB: the {} mode's \
                 nominal drive u_nom = {nominal_amplitude:.1} DAC LSB (drive q0 = {:e} m \
                 through front_end.dac_newton_per_lsb) over {AMPLITUDE_HEADROOM}",
                libm::ceil(nominal_amplitude / AMPLITUDE_HEADROOM),
                f.mode.name(),
                spec.resonator.drive_amplitude_m
            ),
        ));
    }
    let dac_offset = dac_offset(
        (f64::from(s.adc_to_dac_latency_samples) + 0.5) * f_nom / fs,
        f_nom / fs,
        s.demod_lowpass_shift,
        agc.kp.quantized() * setpoint / (2.0 * nominal_amplitude),
    );
    let designed = -0.25 - f.sense_phase / (2.0 * PI);
    let sense_offset = if s.phase_trim {
        let inputs = PhaseInputs {
            nominal_frequency_hz: f_nom,
            sense_offset: designed,
            pll_kp: pll.kp.quantized(),
            setpoint,
            demod_lowpass_shift: s.demod_lowpass_shift,
            adc_rate_hz: fs,
        };
        trimmed_sense_offset(&spec.resonator, f.mode, &inputs)
    } else {
        designed
    };
    let scale = crate::fx::pow2(s.lock_filter_shift as i32);
    let lock_q = setpoint * libm::sin(checked.lock_phase.to_radians()) * scale;
    let lock_a = checked.lock_tolerance * setpoint * scale;
    let lock_format = Format::intermediate(true, 64, demod_output.frac).expect("64");
    Ok(ModePlan {
        mode: f.mode,
        figures: *f,
        setpoint,
        setpoint_code: code(setpoint, demod_output, "setpoint")?,
        nominal_frequency_hz: f_nom,
        frequency: f_nom / fs,
        pll_preset: pll
            .integrator_code(f_nom / fs)
            .map_err(|_| field_error("loop", "nominal_frequency", f_nom, "finite"))?,
        frequency_word: nco.frequency_word(f_nom, fs)?,
        plant_gain,
        nominal_amplitude,
        dac_offset,
        dac_offset_word: word(nco, dac_offset)?,
        sense_offset,
        sense_offset_word: word(nco, sense_offset)?,
        sense_offset_trim: sense_offset - designed,
        sense_gain_per_dps: physics.sense,
        rate_coefficient: coefficients[0],
        quadrature_coefficient: coefficients[1],
        lock_limits: [
            code(lock_q, lock_format, "lock_phase_deg")?,
            code(lock_a, lock_format, "lock_amplitude_tolerance")?,
        ],
    })
}
