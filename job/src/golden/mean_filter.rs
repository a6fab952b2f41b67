//! The port-level golden model of the mean filter (`gyrofx_mean_filter`).

use super::{check_code, PortResult};
use gyrofx_model::mean_filter;
use gyrofx_model::mean_filter::FixedMeanFilter;

/// The mean filter with gross-error rejection (`gyrofx_mean_filter`): `x` in; on a block's last
/// sample `y_valid` with `(y, kept)`.
#[derive(Clone, Debug)]
pub struct MeanFilter {
    plan: mean_filter::Plan,
    model: FixedMeanFilter,
}

impl MeanFilter {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        Vec::new()
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::mean_filter(&self.plan)
    }

    /// From reset.
    pub fn new(plan: &mean_filter::Plan) -> MeanFilter {
        MeanFilter {
            plan: plan.clone(),
            model: FixedMeanFilter::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &mean_filter::Plan {
        &self.plan
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample: `Some((y, kept))` on a block's last sample.
    ///
    /// # Errors
    /// `x` outside the input format.
    pub fn step(&mut self, x: i64) -> PortResult<Option<(i64, i64)>> {
        check_code(x, self.plan.input, "x")?;
        Ok(self.step_checked(x))
    }

    /// [`MeanFilter::step`] on a checked input.
    pub fn step_checked(&mut self, x: i64) -> Option<(i64, i64)> {
        self.model.step(x).map(|m| (m.y, i64::from(m.kept)))
    }
}
