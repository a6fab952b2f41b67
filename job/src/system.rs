//! The system vectors' chain (`gyrofx_system`, SPEC §1.6): a window of the configured
//! schedule is 4 × 150 chain samples of 1000 ADC samples each, far too long for a testbench, so
//! the system's chain runs a short schedule ([`schedule`]) with its own estimator plan and the
//! configured KF. The job plans it ([`crate::job::Job::system_chain`]) so that the port-level
//! models and the package agree on it.

use gyrofx_model::chain;
use gyrofx_model::estimator;
use gyrofx_model::fx::CoefficientFormat;
use gyrofx_model::sequencer::Schedule;

use crate::error::{Error, Result};

/// Chain samples per interval of the system vectors' schedule.
pub const INTERVAL_LENGTH: usize = 3;
/// Blanked chain samples at the start of each interval there.
pub const BLANK: usize = 1;
/// The system vectors' schedule: the configured one with L = [`INTERVAL_LENGTH`] and
/// M = [`BLANK`]; B runs [`BLANK`] samples behind A when the configured schedule staggers.
pub fn schedule(configured: &Schedule) -> Schedule {
    Schedule {
        interval_length: INTERVAL_LENGTH,
        blank: BLANK,
        stagger: if configured.stagger > 0 { BLANK } else { 0 },
        ..configured.clone()
    }
}

/// The system's chain: the configured estimator settings on [`schedule`] (the reciprocal's
/// fraction bits re-derived for `1/(L − M)`, its width kept) and the configured KF.
///
/// # Errors
/// [`Error::Estimator`] when the estimator cannot be planned on the short schedule.
pub fn chain_plan(
    configured: &estimator::Spec,
    kf: &gyrofx_model::kf::Plan,
) -> Result<chain::Plan> {
    let mut spec = configured.clone();
    spec.schedule = schedule(&configured.schedule);
    let width = match spec.reciprocal {
        CoefficientFormat::Auto { width } => width,
        CoefficientFormat::Fixed(format) => format.width,
    };
    spec.reciprocal = CoefficientFormat::Auto { width };
    let plan = estimator::Plan::new(&spec).map_err(Error::Estimator)?;
    chain::Plan::new(plan, kf.clone()).map_err(|e| Error::Config {
        field: "estimator / kf formats (system vectors)".into(),
        value: String::new(),
        allowed: e.to_string(),
    })
}
