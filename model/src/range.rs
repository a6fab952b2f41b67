//! Proven value ranges of the chain's quantization points, for *any* input sequence inside the
//! declared input range, and the integer bits a format needs to hold them.
//!
//! Each linear block's node is bounded by the worst-case peak gain from the input to that
//! node: the l1 norm of its impulse response, split into positive and negative taps so the
//! bound is an interval `[lo, hi]` (an asymmetric two's-complement input range gives an
//! asymmetric node range). The rounding errors are added with their own worst case. The
//! bounds are tight: the input that takes every tap's sign at full scale reaches them (up to
//! the tail of a recursion after a finite record), which the tests show.
//!
//! - **KF** (`x += g (z − x1 − x2)`, one gain set per `bw_sel`): `y = x1 + x2` obeys
//!   `y ← (1 − S) y + S z`, impulse response `S pᵏ` with `p = 1 − S`; from reset `x1 = (g1/S) y`
//!   and `x2 = (g2/S) y` exactly, and `e = z − y`. A `bw_sel` switch re-splits the state along
//!   the eigenvalue-1 direction `[1, −1]` (see [`crate::kf::bound`]): each switch can move
//!   `x1` and `x2` by `Y · max|g1/S − g1'/S'|` (`Y` the bound of `|y|`), so their range grows
//!   with the number of switches, and the rounding error with the number of samples
//!   ([`crate::kf::bound::state_error_bounds`]); both are bounds *for a record length*.
//! - **Estimator** (interval means, least-squares biases) and **calibration**: finite sums, so
//!   interval arithmetic is exact: the accumulator holds `n ≤ L − M` samples, the mean is
//!   `Q(acc · recip)`, the bias `Q(Σ G_j m_j)` (with smoothing a convex update whose rounding
//!   stays within `2ˢ` LSB), and the calibrated sample `Q(y ∓ b)` takes either sign of the bias.
//! - **Mean filter** (gross-error rejection): the kept subset depends on the data, so its output
//!   `Q(kept_sum · ROM[n])` is bounded over every count `n` of kept samples, in exact codes. A
//!   kept subset of `n > L/2` samples can all sit at full scale (the rejected ones far enough
//!   below the mean); one of `n ≤ L/2` cannot (the rejected ones would have to lie beyond the
//!   mean on the far side of full scale), so at least one kept sample is an LSB inside it; no
//!   sample kept (`n = 0`) outputs the plain mean. With `1/n` rounded up in the ROM, a count
//!   other than `L` can give the largest output.

use crate::estimator;
use crate::fx::{pow2, requantize, Format, Overflow, Rounding};
use crate::kf;
use crate::mean_filter;

pub mod gyro_loop;

/// A closed interval of real values (°/s for the chain's nodes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Least value.
    pub lo: f64,
    /// Greatest value.
    pub hi: f64,
}

impl Interval {
    /// `[lo, hi]`.
    pub fn new(lo: f64, hi: f64) -> Interval {
        debug_assert!(lo <= hi, "[{lo}, {hi}]");
        Interval { lo, hi }
    }

    /// Every value a format holds.
    pub fn of_format(format: Format) -> Interval {
        Interval::new(format.min_value(), format.max_value())
    }

    /// `c · self`.
    pub fn scale(self, c: f64) -> Interval {
        if c >= 0.0 {
            Interval::new(c * self.lo, c * self.hi)
        } else {
            Interval::new(c * self.hi, c * self.lo)
        }
    }

    /// The smallest interval holding both.
    pub fn union(self, other: Interval) -> Interval {
        Interval::new(self.lo.min(other.lo), self.hi.max(other.hi))
    }

    /// `[lo − margin, hi + margin]`.
    pub fn widen(self, margin: f64) -> Interval {
        Interval::new(self.lo - margin, self.hi + margin)
    }

    /// Every value `rounding` to `frac` fraction bits makes of one of these: the endpoints
    /// rounded (every rounding mode is monotone), before any saturation.
    pub fn quantized(self, frac: i32, rounding: Rounding) -> Interval {
        let round = |value: f64| {
            // Scaling by a power of two is exact.
            let scaled = value * pow2(frac);
            let code = match rounding {
                Rounding::Floor => scaled.floor(),
                Rounding::Ceil => scaled.ceil(),
                Rounding::Zero => scaled.trunc(),
                Rounding::Nearest => (scaled + 0.5).floor(),
                Rounding::Round => scaled.round(),
                Rounding::Convergent => scaled.round_ties_even(),
            };
            code * pow2(-frac)
        };
        Interval::new(round(self.lo), round(self.hi))
    }

    /// The largest magnitude.
    pub fn magnitude(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// Whether `format` holds every value (its codes' range; values between codes round into
    /// it).
    pub fn fits(self, format: Format) -> bool {
        format.min_value() <= self.lo && self.hi <= format.max_value()
    }

    /// Integer bits, sign included, that a signed format with `frac` fraction bits needs to
    /// hold every value: the least `I` with `−2^(I−1) ≤ lo` and `hi ≤ 2^(I−1) − 2^−frac`.
    /// Exact (powers of two compared, no logarithm).
    pub fn signed_integer_bits(self, frac: i32) -> i32 {
        let lsb = pow2(-frac);
        let mut bits = 1 - frac;
        while -pow2(bits - 1) > self.lo || self.hi > pow2(bits - 1) - lsb {
            bits += 1;
        }
        bits
    }
}

/// Every sum of one value of each.
impl std::ops::Add for Interval {
    type Output = Interval;
    fn add(self, other: Interval) -> Interval {
        Interval::new(self.lo + other.lo, self.hi + other.hi)
    }
}

/// Every difference of one value of each.
impl std::ops::Sub for Interval {
    type Output = Interval;
    fn sub(self, other: Interval) -> Interval {
        Interval::new(self.lo - other.hi, self.hi - other.lo)
    }
}

/// What the analysis proved about one node.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeRange {
    /// `block.signal`, as [`crate::fx`] formats are named in the Python package and manifest.
    pub name: &'static str,
    /// What the node is.
    pub what: &'static str,
    /// Every value it can take (°/s), rounding included.
    pub range: Interval,
    /// Its format in the plan.
    pub format: Format,
    /// Whether the plan derives the format by bit growth (exact arithmetic, not configured).
    pub exact: bool,
}

impl NodeRange {
    /// Integer bits (sign included) the node needs at its fraction bits.
    pub fn needed_integer_bits(&self) -> i32 {
        self.range.signed_integer_bits(self.format.frac)
    }

    /// Integer bits the plan's format has (sign included).
    pub fn integer_bits(&self) -> i32 {
        self.format.width as i32 - self.format.frac
    }

    /// Whether the plan's format holds every value.
    pub fn fits(&self) -> bool {
        self.range.fits(self.format)
    }
}

/// The node named `name` (`"kf.state"`) of `nodes`.
pub fn find<'a>(nodes: &'a [NodeRange], name: &str) -> Option<&'a NodeRange> {
    nodes.iter().find(|node| node.name == name)
}

/// The KF's proven ranges.
#[derive(Clone, Debug, PartialEq)]
pub struct KfRanges {
    /// `y = x1 + x2`, the filter's estimate of `z` (not a register).
    pub estimate: Interval,
    /// Each node.
    pub nodes: Vec<NodeRange>,
    /// How far one `bw_sel` switch can move `x1` and `x2` (°/s).
    pub per_switch: f64,
    /// The rounding error of `[x1, x2]` after the record (°/s).
    pub rounding: [f64; 2],
}

/// The positive and negative sums `(P, N)` of the impulse response `S pᵏ`, `k ≥ 0`.
fn tap_sums(s: f64, p: f64) -> (f64, f64) {
    if p >= 0.0 {
        (s / (1.0 - p), 0.0)
    } else {
        let denominator = 1.0 - p * p;
        (s / denominator, s * p.abs() / denominator)
    }
}

/// The KF's nodes for inputs `z` in `input`, every ROM entry, a record of `samples` samples
/// with at most `switches` changes of `bw_sel`. The plan's gains keep `|1 − S| < 1` (the plan
/// refuses others).
pub fn kf(plan: &kf::Plan, input: Interval, samples: u64, switches: u64) -> KfRanges {
    let gains = plan.quantized_gains();
    let mut estimate: Option<Interval> = None;
    let mut states: [Option<Interval>; 2] = [None, None];
    let mut error: Option<Interval> = None;
    let mut products: [Option<Interval>; 2] = [None, None];
    let union = |slot: &mut Option<Interval>, value: Interval| {
        *slot = Some(slot.map_or(value, |old| old.union(value)));
    };
    let ratios: Vec<f64> = gains.iter().map(|g| g[0] / (g[0] + g[1])).collect();
    for g in &gains {
        let s = g[0] + g[1];
        let (positive, negative) = tap_sums(s, 1.0 - s);
        // From reset y starts at 0, inside every such interval.
        let y = Interval::new(
            positive * input.lo - negative * input.hi,
            positive * input.hi - negative * input.lo,
        );
        union(&mut estimate, y);
        for i in 0..2 {
            union(&mut states[i], y.scale(g[i] / s));
        }
        let e = input - y;
        union(&mut error, e);
        for i in 0..2 {
            union(&mut products[i], e.scale(g[i]));
        }
    }
    let estimate = estimate.expect("a plan has at least one ROM entry");
    let jump = ratios
        .iter()
        .flat_map(|a| ratios.iter().map(move |b| (a - b).abs()))
        .fold(0.0f64, f64::max);
    let per_switch = estimate.magnitude() * jump;
    let rounding = kf::bound::state_error_bounds(plan, samples, switches);
    let state = |i: usize| {
        states[i]
            .expect("one per entry")
            .widen(switches as f64 * per_switch + rounding[i])
    };
    let [x1, x2] = [state(0), state(1)];
    let nodes = vec![
        NodeRange {
            name: "kf.error",
            what: "innovation e = z − x1 − x2",
            // The states' rounding errors enter e too.
            range: error
                .expect("one per entry")
                .widen(rounding[0] + rounding[1] + 2.0 * switches as f64 * per_switch),
            format: plan.error,
            exact: true,
        },
        NodeRange {
            name: "kf.product_g1",
            what: "g1 · e",
            range: products[0]
                .expect("one per entry")
                .widen(max_gain(&gains, 0) * (rounding[0] + rounding[1])),
            format: plan.product[0],
            exact: true,
        },
        NodeRange {
            name: "kf.product_g2",
            what: "g2 · e",
            range: products[1]
                .expect("one per entry")
                .widen(max_gain(&gains, 1) * (rounding[0] + rounding[1])),
            format: plan.product[1],
            exact: true,
        },
        NodeRange {
            name: "kf.sum_x1",
            what: "x1 + g1 · e, before rounding",
            range: x1,
            format: plan.sum[0],
            exact: true,
        },
        NodeRange {
            name: "kf.sum_x2",
            what: "x2 + g2 · e, before rounding",
            range: x2,
            format: plan.sum[1],
            exact: true,
        },
        NodeRange {
            name: "kf.state",
            what: "x1 and x2 (rate and bias)",
            // x_fixed = x_exact + ε, ε the accumulated rounding (already in x1, x2).
            range: x1.union(x2),
            format: plan.state,
            exact: false,
        },
        NodeRange {
            name: "kf.output",
            what: "rate_hat = Q(x1)",
            range: x1.quantized(plan.output.frac, plan.rounding),
            format: plan.output,
            exact: false,
        },
    ];
    KfRanges {
        estimate,
        nodes,
        per_switch,
        rounding,
    }
}

fn max_gain(gains: &[[f64; 2]], i: usize) -> f64 {
    gains.iter().fold(0.0f64, |m, g| m.max(g[i].abs()))
}

/// The estimator's and the calibration's nodes for both gyros' samples in `input`.
pub fn estimator(plan: &estimator::Plan, input: Interval) -> Vec<NodeRange> {
    let schedule = &plan.schedule;
    let count = (schedule.interval_length - schedule.blank) as f64;
    let u = plan.rounding.max_error_lsb();
    // The accumulator holds at most L − M valid samples (0 from reset or a blanked start).
    let accumulator = input.scale(count).union(Interval::new(0.0, 0.0));
    let reciprocal = plan.reciprocal.to_f64(plan.reciprocal_code);
    let mean = accumulator
        .scale(reciprocal)
        .quantized(plan.mean.frac, plan.rounding)
        .union(Interval::new(0.0, 0.0));
    // Each row is a dot product over the 2W means; the two rows' ranges are united.
    let rows = [&plan.rom[0], &plan.rom[1]];
    let mut dot: Option<Interval> = None;
    for row in rows {
        let sum = row.iter().fold(Interval::new(0.0, 0.0), |sum, code| {
            sum + mean.scale(plan.gain.to_f64(*code))
        });
        dot = Some(dot.map_or(sum, |d| d.union(sum)));
    }
    let dot = dot.expect("two rows");
    // Smoothing b += (b_new − b)/2^s is a convex update whose roundings stay within 2^s LSB.
    let new = dot.quantized(plan.bias.frac, plan.rounding);
    let bias = if plan.smoothing_shift == 0 {
        new
    } else {
        new.widen(pow2(plan.smoothing_shift as i32) * u * plan.bias.lsb())
    }
    .union(Interval::new(0.0, 0.0));
    let calibrated_exact = (input - bias).union(input + bias);
    let calibrated = calibrated_exact.quantized(plan.calibrated.frac, plan.rounding);
    vec![
        NodeRange {
            name: "estimator.accumulator",
            what: "sum of an interval's valid samples",
            range: accumulator,
            format: plan.accumulator,
            exact: true,
        },
        NodeRange {
            name: "estimator.mean",
            what: "interval mean Q(acc · 1/(L − M))",
            range: mean,
            format: plan.mean,
            exact: false,
        },
        NodeRange {
            name: "estimator.dot",
            what: "Σ G_j m_j, before rounding",
            range: dot,
            format: plan.dot,
            exact: true,
        },
        NodeRange {
            name: "estimator.bias",
            what: "bias estimate",
            range: bias,
            format: plan.bias,
            exact: false,
        },
        NodeRange {
            name: "estimator.calibrated",
            what: "calibrated and combined sample Q(y ∓ b), the KF's input",
            range: calibrated,
            format: plan.calibrated,
            exact: false,
        },
    ]
}

/// The mean filter's nodes for samples in its input format.
pub fn mean_filter(plan: &mean_filter::Plan) -> Vec<NodeRange> {
    let window = i128::from(plan.window);
    let (min, max) = (plan.input.min_code(), plan.input.max_code());
    // The output before saturation: a format wide enough for any product here.
    let unsaturated = Format {
        signed: true,
        width: 64,
        frac: plan.output.frac,
    };
    let output_code = |total: i128, n: usize| {
        requantize(
            total * plan.rom[n],
            plan.product.frac,
            unsaturated,
            plan.rounding,
            Overflow::Saturate,
        )
        .code
    };
    let mut product = Interval::new(0.0, 0.0);
    let mut output = (i128::MAX, i128::MIN);
    for n in 0..=plan.window as usize {
        let count = n as i128;
        // The extremes of the total that feeds ROM[n].
        let (low, high) = match n {
            0 => (window * min, window * max),
            n if 2 * n > plan.window as usize => (count * min, count * max),
            _ => (count * min + 1, count * max - 1),
        };
        for total in [low, high] {
            let value = plan.product.to_f64(total * plan.rom[n]);
            product = product.union(Interval::new(value, value));
            let code = output_code(total, n);
            output = (output.0.min(code), output.1.max(code));
        }
    }
    let to_interval = |(lo, hi): (i128, i128), format: Format| {
        Interval::new(format.to_f64(lo), format.to_f64(hi))
    };
    let deviation = (window - 1) as f64 * (plan.input.max_value() - plan.input.min_value());
    vec![
        NodeRange {
            name: "mean_filter.sum",
            what: "sum of a block's samples",
            range: to_interval((window * min, window * max), plan.input),
            format: plan.sum,
            exact: true,
        },
        NodeRange {
            name: "mean_filter.deviation",
            what: "L · s_i − sum, compared with L · r",
            range: Interval::new(-deviation, deviation),
            format: plan.deviation,
            exact: true,
        },
        NodeRange {
            name: "mean_filter.product",
            what: "(kept) sum · ROM[n]",
            range: product,
            format: plan.product,
            exact: true,
        },
        NodeRange {
            name: "mean_filter.output",
            what: "block mean of the kept samples",
            range: to_interval(output, plan.output),
            format: plan.output,
            exact: false,
        },
    ]
}

#[cfg(test)]
mod tests;
