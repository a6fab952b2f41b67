//! A closed loop's trace across a mode switch: drive amplitude, NCO frequency, lock and the
//! rate output against time, for plotting (`gyrofx loop --plot`).

use super::closed::{FixedClosedLoop, Window};
use super::gyro::Plan;
use crate::resonator::{Mode, ParamError, PhysicsSettings, ResonatorParams};

/// One point of a trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracePoint {
    /// Time from the switch, s (negative before it).
    pub time_s: f64,
    /// The driven axis's amplitude, m.
    pub drive_amplitude_m: f64,
    /// Mean NCO frequency over the window, Hz.
    pub frequency_hz: f64,
    /// The lock flag at the window's end.
    pub locked: bool,
    /// The last rate output within the window, °/s.
    pub rate_dps: Option<f64>,
}

/// How a trace is taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceSpec {
    /// Input rate, °/s.
    pub rate_dps: f64,
    /// Normal mode from rest before the switch, s.
    pub before_s: f64,
    /// The part of it that is traced, s.
    pub shown_before_s: f64,
    /// Reverse mode after the switch, s.
    pub after_s: f64,
    /// ADC samples per point.
    pub window_samples: u32,
    /// Noise and drift as the front end says (off: deterministic).
    pub noise: bool,
    /// Seed of the resonator's random streams.
    pub seed: u64,
}

impl Default for TraceSpec {
    /// 100 °/s; 0.4 s of normal mode from rest, the last 0.1 s traced; 0.3 s of reverse mode;
    /// a point per 100 ADC samples; noise off.
    fn default() -> Self {
        TraceSpec {
            rate_dps: 100.0,
            before_s: 0.4,
            shown_before_s: 0.1,
            after_s: 0.3,
            window_samples: 100,
            noise: false,
            seed: 0,
        }
    }
}

/// The fixed loop of `plan` closed around the physics: from rest in normal mode, switched to
/// reverse at `time_s = 0`.
///
/// # Errors
/// [`ParamError`] for invalid physics.
pub fn switch_trace(
    plan: &Plan,
    params: &ResonatorParams,
    physics: &PhysicsSettings,
    spec: &TraceSpec,
) -> Result<Vec<TracePoint>, ParamError> {
    let physics = if spec.noise {
        *physics
    } else {
        physics.noiseless()
    };
    let mut closed = FixedClosedLoop::new(plan, params, &physics, spec.seed)?;
    let window = spec.window_samples.max(1);
    let dt = f64::from(window) / plan.adc_rate_hz;
    let windows = |seconds: f64| (seconds / dt).round().max(0.0) as usize;
    let (before, shown, after) = (
        windows(spec.before_s),
        windows(spec.shown_before_s.min(spec.before_s)),
        windows(spec.after_s),
    );
    let point = |k: isize, w: Window| TracePoint {
        time_s: k as f64 * dt,
        drive_amplitude_m: w.drive_amplitude_m,
        frequency_hz: w.mean_frequency_hz,
        locked: w.locked,
        rate_dps: w.chain.map(|c| c.rate_dps),
    };
    let mut out = Vec::with_capacity(shown + after);
    closed.set(spec.rate_dps, Mode::Normal);
    for k in 0..before {
        let w = closed.advance(window);
        if k + shown >= before {
            out.push(point(k as isize - before as isize + 1, w));
        }
    }
    closed.set(spec.rate_dps, Mode::Reverse);
    for k in 0..after {
        out.push(point(k as isize + 1, closed.advance(window)));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gyro_loop::gyro::Spec;

    /// Across a switch the drive frequency moves from the normal to the reverse resonance, the
    /// amplitude collapses and rebuilds to q0, and the lock drops and returns.
    #[test]
    fn the_trace_shows_the_switch_and_the_relock() {
        let spec = Spec::paper_004();
        let (params, physics) = (spec.resonator, spec.front_end);
        let plan = Plan::new(&spec).unwrap();
        let trace = switch_trace(&plan, &params, &physics, &TraceSpec::default()).unwrap();
        let before: Vec<&TracePoint> = trace.iter().filter(|p| p.time_s <= 0.0).collect();
        let after: Vec<&TracePoint> = trace.iter().filter(|p| p.time_s > 0.0).collect();
        let last_before = before.last().unwrap();
        let last_after = after.last().unwrap();
        assert!(last_before.locked && last_after.locked);
        assert!(
            (last_before.frequency_hz - 8195.0).abs() < 0.5,
            "{last_before:?}"
        );
        assert!(
            (last_after.frequency_hz - 8142.0).abs() < 0.5,
            "{last_after:?}"
        );
        for p in [last_before, last_after] {
            assert!((p.drive_amplitude_m - 2e-6).abs() < 2e-9, "{p:?}");
        }
        assert!(
            after.iter().any(|p| !p.locked),
            "the lock drops at the switch"
        );
        assert!(
            after
                .iter()
                .map(|p| p.drive_amplitude_m)
                .fold(f64::MAX, f64::min)
                < 1e-6,
            "the amplitude rebuilds from near zero"
        );
        assert!(after.iter().filter_map(|p| p.rate_dps).count() >= 50);
    }
}
