//! Proven value ranges of the gyro loop's quantization points ([`crate::gyro_loop`]), for
//! *any* ADC code sequence and any reference sequence the NCO's ROM can give, and the integer
//! bits a format needs to hold them.
//!
//! Units: the demodulator's nodes, `e_A` and the CIC's in ADC full-scale units; the PLL's in
//! cycles per sample; the AGC's and the DAC's in DAC LSB; the loop's output in °/s.
//!
//! Each node is bounded in exact codes (every rounding mode is monotone: the rounded endpoints
//! of an interval bound its rounded values), the recursions by what they can reach:
//!
//! - **Demodulator product** `p = Q(2·x·ref)`: the ADC's codes times the ROM's actual codes
//!   (their extremes `±max ROM[k]`, not the nominal amplitude), rounded.
//! - **Demodulator state** `y ← Q(y + (p − y)·2^−k)`: `y` and `p` are both codes of the state
//!   format (the plan requires it to hold the product's fraction and integer bits), and the
//!   update lies between them (`0 < 2^−k ≤ ½`), so no monotone rounding leaves `[y, p]`. From
//!   the reset's `0` the state stays in the hull of `0` and every product: the product's range.
//!   Rounding adds no drift here (unlike the KF's, whose two states share one error).
//! - **I, Q** `Q(y)`: the state's range rounded.
//! - **PI** `v = clamp(Q(v + ki·e))`, `u = Q(kp·e + v)`: the clamp keeps the integrator within
//!   its limits (and `0` from reset); the output takes `v` after the clamp, so it is
//!   `kp·e` over the error's range plus the limits, rounded. The PLL's `e` is `Q_D`, the AGC's
//!   `e_A = a_set − I_D` over both modes' setpoints.
//! - **DAC** `Q(u·cos)`: the AGC's output times the ROM's codes.
//! - **CIC comb** `w = Σ_j g_j x`: the impulse response `g` of `((1 − z^−RM)/(1 − z^−1))^N` is
//!   nonnegative and sums to `(R·M)^N`, so `w` spans the input's range times that (Hogenauer's
//!   register holds what the input port carries; the integrators wrap by design and the combs
//!   undo it). `c = Q(w·2^−shift)`.
//! - **Compensator** `y = Q(Σ_t h_t c_{m−t})`: the cascade from the CIC's input to `y` is
//!   linear up to `c`'s roundings, with impulse response `H_ℓ = 2^−shift Σ_t h_t g_{ℓ−tR}`;
//!   its worst-case peak gain is the l1 norm split into positive and negative taps (the sign
//!   pattern of `H` at full scale reaches it), plus `Σ|h|` times `c`'s rounding error. This is
//!   below the compensator's own l1 norm times `c`'s range: consecutive `c` share input
//!   samples and cannot alternate between extremes. When `c`'s format cannot hold its range
//!   the compensator sees saturated (or wrapped) values, which no longer follow the cascade:
//!   then only the taps' own split l1 norm over the values `c` can take bounds `y`.
//! - **Loop output** `Q(c_rate·y)`, `Q(c_quad·y)`: over all four `1/SF` coefficients.
//!
//! A node's range assumes the nodes before it hold theirs (as after `gyrofx formats --write`);
//! where one cannot, what the next one sees is [`delivered`]: with saturation its range still
//! (a saturated value lies between 0 and the unsaturated one), with wrapping anything its
//! format holds. One format stays narrow on purpose: the AGC's output saturates at the DAC's
//! full scale (the drive stays a sine of the largest amplitude; a DAC saturating instead would
//! clip it), so the DAC sees what that format outputs ([`output_of`]), not the AGC's range.
//!
//! The references are bounded per sample, not as a sinusoid: the demodulator block takes any
//! reference sequence (a frequency word of 0 holds one ROM code), which is what makes the
//! bounds tight for the block. Inside the closed loop the NCO turns at the drive frequency, and
//! an adversarial ADC sequence reaches `I_D ≈ (4/π)·max ROM` rather than `2·max ROM`.

use super::{find, Interval, NodeRange};
use crate::fx::{requantize, Format, Overflow, Rounding};
use crate::gyro_loop::{cic, demodulator, gyro, nco, pi, Point};

/// Which of the loop's PI controllers a [`pi`] analysis is for: it names the nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Controller {
    /// The PLL: `Q_D` in (ADC full-scale units), frequency word out (cycles per sample).
    Pll,
    /// The AGC: `e_A` in (ADC full-scale units), drive amplitude out (DAC LSB).
    Agc,
}

/// The codes of a format with `frac` fraction bits inside `range`.
fn codes(range: Interval, frac: i32) -> (i128, i128) {
    let scale = crate::fx::pow2(frac);
    (
        (range.lo * scale).ceil() as i128,
        (range.hi * scale).floor() as i128,
    )
}

/// The least and greatest of `values`.
fn extremes(values: impl IntoIterator<Item = i128>) -> (i128, i128) {
    values
        .into_iter()
        .fold((i128::MAX, i128::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

/// The exact codes `[lo, hi]` at `from_frac` rounded with `rounding` to `to_frac` fraction
/// bits, before any saturation, as reals.
fn rounded(lo: i128, hi: i128, from_frac: i32, to_frac: i32, rounding: Rounding) -> Interval {
    let unbounded = Format::intermediate(true, 128, to_frac).expect("128 bits is allowed");
    let round = |code| {
        unbounded.to_f64(requantize(code, from_frac, unbounded, rounding, Overflow::Saturate).code)
    };
    Interval::new(round(lo), round(hi))
}

/// The exact codes `[lo, hi]` rounded at `point` (before its overflow handling).
fn rounded_at(lo: i128, hi: i128, point: &Point) -> Interval {
    rounded(lo, hi, point.from.frac, point.to.frac, point.rounding)
}

/// What the nodes after `point` see when its value ranges over `range`: `range` when the
/// point's format holds it or saturates (a saturated value lies between 0 and the unsaturated
/// one, so with 0 it stays in the hull), else every value the format holds as well.
pub fn delivered(range: Interval, point: &Point) -> Interval {
    if range.fits(point.to) {
        range
    } else {
        match point.overflow {
            Overflow::Saturate => range.union(Interval::new(0.0, 0.0)),
            Overflow::Wrap => range.union(Interval::of_format(point.to)),
        }
    }
}

/// Every value `point` outputs when its exact value ranges over `range`: the range, its ends
/// saturated into the point's format, or anything the format holds when it wraps.
pub fn output_of(range: Interval, point: &Point) -> Interval {
    if range.fits(point.to) {
        return range;
    }
    let format = Interval::of_format(point.to);
    match point.overflow {
        Overflow::Saturate => Interval::new(
            range.lo.clamp(format.lo, format.hi),
            range.hi.clamp(format.lo, format.hi),
        ),
        Overflow::Wrap => format,
    }
}

/// Every value the NCO's sine and cosine take: `±ROM[k]` over the ROM's codes (output format,
/// full-scale units).
pub fn reference(plan: &nco::Plan) -> Interval {
    let (lo, hi) = extremes(plan.rom_codes().iter().flat_map(|&c| [c, -c]));
    Interval::new(plan.output.to_f64(lo), plan.output.to_f64(hi))
}

/// The demodulator's nodes for ADC codes in `input` and references in `reference` (full-scale
/// units): `loop.demod_product`, `loop.demod_state`, `loop.demod_output`, each over both
/// channels.
pub fn demodulator(
    plan: &demodulator::Plan,
    input: Interval,
    reference: Interval,
) -> Vec<NodeRange> {
    let (x_lo, x_hi) = codes(input, plan.input.frac);
    let (r_lo, r_hi) = codes(reference, plan.reference.frac);
    // x·ref at Fx + Fr fraction bits is 2·x·ref at the exact product's Fx + Fr − 1.
    let (lo, hi) = extremes([x_lo * r_lo, x_lo * r_hi, x_hi * r_lo, x_hi * r_hi]);
    let product = rounded_at(lo, hi, &plan.product);
    // The hull of the reset's 0 and every product the state has seen (see the module doc).
    let state = delivered(product, &plan.product).union(Interval::new(0.0, 0.0));
    let (y_lo, y_hi) = codes(state, plan.state.to.frac);
    let output = rounded_at(y_lo, y_hi, &plan.output);
    vec![
        NodeRange {
            name: "loop.demod_product",
            what: "demodulator product 2·x·ref (I and Q, drive and sense)",
            range: product,
            format: plan.product.to,
            exact: false,
        },
        NodeRange {
            name: "loop.demod_state",
            what: "demodulator low-pass state y (I and Q, drive and sense)",
            range: state,
            format: plan.state.to,
            exact: false,
        },
        NodeRange {
            name: "loop.demod_output",
            what: "demodulator outputs I, Q (drive and sense)",
            range: output,
            format: plan.output.to,
            exact: false,
        },
    ]
}

/// A PI controller's nodes for errors `e` in `input` (its input's units):
/// `loop.pll_integrator` and `loop.pll_output`, or the AGC's.
pub fn pi(plan: &pi::Plan, input: Interval, controller: Controller) -> Vec<NodeRange> {
    let (integrator_name, output_name, what_integrator, what_output) = match controller {
        Controller::Pll => (
            "loop.pll_integrator",
            "loop.pll_output",
            "PLL integrator, clamped to the pull range (cycles per sample)",
            "PLL output kp·Q_D + v, the NCO's frequency word (cycles per sample)",
        ),
        Controller::Agc => (
            "loop.agc_integrator",
            "loop.agc_output",
            "AGC integrator, clamped to [0, DAC full scale] (DAC LSB)",
            "AGC output kp·e_A + v, the drive amplitude (DAC LSB)",
        ),
    };
    let [v_lo, v_hi] = plan.limits;
    let integrator = Interval::new(
        plan.integrator.to_f64(v_lo).min(0.0),
        plan.integrator.to_f64(v_hi).max(0.0),
    );
    let (e_lo, e_hi) = codes(input, plan.input.frac);
    let sum = plan.output.from.frac;
    let kp_e_shift = sum - (plan.kp.format.frac + plan.input.frac);
    let v_shift = sum - plan.integrator.frac;
    let (kp_e_lo, kp_e_hi) = extremes([plan.kp.code * e_lo, plan.kp.code * e_hi]);
    // The output adds the integrator after this sample's clamp: always within the limits.
    let output = rounded_at(
        (kp_e_lo << kp_e_shift) + (v_lo << v_shift),
        (kp_e_hi << kp_e_shift) + (v_hi << v_shift),
        &plan.output,
    );
    vec![
        NodeRange {
            name: integrator_name,
            what: what_integrator,
            range: integrator,
            format: plan.integrator,
            exact: false,
        },
        NodeRange {
            name: output_name,
            what: what_output,
            range: output,
            format: plan.output.to,
            exact: false,
        },
    ]
}

/// The CIC's integer impulse response `g` of `((1 − z^−RM)/(1 − z^−1))^N` (nonnegative, sum
/// `(R·M)^N`), by running sums.
fn cic_impulse_response(plan: &cic::Plan) -> Vec<u128> {
    let length = (plan.decimation * plan.differential_delay) as usize;
    let mut g: Vec<u128> = vec![1];
    for _ in 0..plan.stages {
        let mut next = vec![0u128; g.len() + length - 1];
        let mut running = 0u128;
        for (i, slot) in next.iter_mut().enumerate() {
            running += g.get(i).copied().unwrap_or(0);
            if i >= length {
                running -= g[i - length];
            }
            *slot = running;
        }
        g = next;
    }
    g
}

/// The positive and negative sums `(P, N)` of the cascade's impulse response from the CIC's
/// input to the compensator's sum, `H_ℓ = 2^−shift Σ_t h_t g_{ℓ−tR}` (reals), and a bound on
/// their f64 rounding error relative to `P + N`.
fn cascade_tap_sums(plan: &cic::Plan) -> (f64, f64, f64) {
    let g: Vec<f64> = cic_impulse_response(plan)
        .into_iter()
        .map(|v| v as f64)
        .collect();
    let taps = plan.tap_values();
    let r = plan.decimation as usize;
    let scale = crate::fx::pow2(-(plan.shift as i32));
    let length = (taps.len() - 1) * r + g.len();
    let (mut positive, mut negative) = (0.0f64, 0.0f64);
    for l in 0..length {
        let tap: f64 = taps
            .iter()
            .enumerate()
            .filter_map(|(t, h)| l.checked_sub(t * r).and_then(|j| g.get(j)).map(|g| h * g))
            .sum();
        if tap >= 0.0 {
            positive += tap * scale;
        } else {
            negative -= tap * scale;
        }
    }
    // Each H_ℓ is a sum of at most T rounded products, each of P and N a sum of `length` of
    // them (and the g above 2^53 are rounded once): a relative error within (T + length + 2)
    // roundings of 2^−53, doubled for margin.
    let relative = 2.0 * (taps.len() + length + 2) as f64 * crate::fx::pow2(-53);
    (positive, negative, relative)
}

/// The CIC's nodes for inputs in `input` (full-scale units): `loop.cic_comb` (exact),
/// `loop.cic_internal` (`c`), `loop.cic_output` (the compensator's `y`).
pub fn cic(plan: &cic::Plan, input: Interval) -> Vec<NodeRange> {
    let (x_lo, x_hi) = codes(input, plan.input.frac);
    let gain = plan.cic_gain();
    // The register is sized for the port: it holds whatever the input format carries, even
    // where `input` (a range that can overflow the format before it) reaches beyond it.
    let port = Interval::of_format(plan.input);
    let comb = Interval::new(gain * input.lo.max(port.lo), gain * input.hi.min(port.hi));
    // w in codes at F_in, read at F_in + shift: exact in i128 whenever the register is.
    let exact_gain =
        i128::try_from(u128::from(plan.decimation * plan.differential_delay).pow(plan.stages)).ok();
    let scaled = match exact_gain.and_then(|g| Some((g.checked_mul(x_lo)?, g.checked_mul(x_hi)?))) {
        Some((w_lo, w_hi)) => rounded_at(w_lo, w_hi, &plan.cic),
        None => comb
            .scale(crate::fx::pow2(-(plan.shift as i32)))
            .quantized(plan.cic.to.frac, plan.cic.rounding),
    };
    let taps = plan.tap_values();
    let c_error = plan.cic.max_error();
    let sum = if scaled.fits(plan.cic.to) {
        let (positive, negative, relative) = cascade_tap_sums(plan);
        let tap_l1: f64 = taps.iter().map(|h| h.abs()).sum();
        let linear = Interval::new(
            positive * input.lo - negative * input.hi,
            positive * input.hi - negative * input.lo,
        );
        linear.widen(tap_l1 * c_error + relative * (positive + negative) * input.magnitude())
    } else {
        // c saturated or wrapped: any c the compensator can see, each tap on its own.
        let (c_lo, c_hi) = codes(delivered(scaled, &plan.cic), plan.cic.to.frac);
        let (lo, hi) = plan.taps.iter().fold((0i128, 0i128), |(lo, hi), h| {
            let (a, b) = extremes([h.code * c_lo, h.code * c_hi]);
            (lo + a, hi + b)
        });
        let sum = plan.fir_sum;
        Interval::new(sum.to_f64(lo), sum.to_f64(hi))
    };
    let output = sum.quantized(plan.output.to.frac, plan.output.rounding);
    vec![
        NodeRange {
            name: "loop.cic_comb",
            what: "CIC comb output w, before 2^-shift (the integrators wrap by design)",
            range: comb,
            format: plan.register,
            exact: true,
        },
        NodeRange {
            name: "loop.cic_internal",
            what: "CIC output c = Q(w·2^-shift), the compensator's input",
            range: scaled,
            format: plan.cic.to,
            exact: false,
        },
        NodeRange {
            name: "loop.cic_output",
            what: "compensator output Q(Σ h·c) (I and Q)",
            range: output,
            format: plan.output.to,
            exact: false,
        },
    ]
}

/// Every node of one gyro's loop for any ADC codes (the ADC format's full scale, both axes,
/// both modes), in data-flow order: the demodulators, `loop.agc_error`, the PLL and the AGC,
/// `loop.dac`, the CICs and `loop.output`.
pub fn gyro(plan: &gyro::Plan) -> Vec<NodeRange> {
    let reference = reference(&plan.nco);
    let mut nodes = demodulator(&plan.demodulator, Interval::of_format(plan.adc), reference);
    let range = |nodes: &[NodeRange], name: &str| find(nodes, name).expect("analysed").range;
    let iq = delivered(range(&nodes, "loop.demod_output"), &plan.demodulator.output);

    // e_A = a_set − I_D, exact (same fraction bits), over both modes' setpoints.
    let (i_lo, i_hi) = codes(iq, plan.agc_error.from.frac);
    let (set_lo, set_hi) = extremes(plan.modes.iter().map(|m| i128::from(m.setpoint_code)));
    let agc_error = rounded_at(set_lo - i_hi, set_hi - i_lo, &plan.agc_error);
    nodes.push(NodeRange {
        name: "loop.agc_error",
        what: "AGC error e_A = a_set − I_D (both modes)",
        range: agc_error,
        format: plan.agc_error.to,
        exact: false,
    });

    nodes.extend(pi(&plan.pll, iq, Controller::Pll));
    nodes.extend(pi(
        &plan.agc,
        delivered(agc_error, &plan.agc_error),
        Controller::Agc,
    ));

    // The AGC's output format limits the drive on purpose (see the module doc).
    let amplitude = output_of(range(&nodes, "loop.agc_output"), &plan.agc.output);
    let (u_lo, u_hi) = codes(amplitude, plan.agc.output.to.frac);
    let (r_lo, r_hi) = codes(reference, plan.nco.output.frac);
    let (lo, hi) = extremes([u_lo * r_lo, u_lo * r_hi, u_hi * r_lo, u_hi * r_hi]);
    nodes.push(NodeRange {
        name: "loop.dac",
        what: "drive DAC code u·cos (DAC LSB)",
        range: rounded_at(lo, hi, &plan.dac),
        format: plan.dac.to,
        exact: false,
    });

    nodes.extend(cic(&plan.cic, iq));
    let decimated = delivered(range(&nodes, "loop.cic_output"), &plan.cic.output);
    let (y_lo, y_hi) = codes(decimated, plan.cic.output.to.frac);
    let (lo, hi) = extremes(plan.modes.iter().flat_map(|m| {
        [m.rate_coefficient.code, m.quadrature_coefficient.code]
            .into_iter()
            .flat_map(|c| [c * y_lo, c * y_hi])
    }));
    nodes.push(NodeRange {
        name: "loop.output",
        what: "rate and quadrature c·y (°/s, both modes)",
        range: rounded_at(lo, hi, &plan.output),
        format: plan.output.to,
        exact: false,
    });
    nodes
}

#[cfg(test)]
mod tests;
