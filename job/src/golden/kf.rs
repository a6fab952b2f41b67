//! The port-level golden model of the steady-state KF (`gyrofx_kf`).

use super::{check_bw_sel, check_code, PortResult};
use gyrofx_model::kf;
use gyrofx_model::kf::FixedKf;

/// The steady-state KF (`gyrofx_kf`): `z`, `bw_sel` in, `rate_out` out (`out_valid` with it).
#[derive(Clone, Debug)]
pub struct Kf {
    plan: kf::Plan,
    model: FixedKf,
}

impl Kf {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        super::overflows::kf(&self.model)
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::kf(&self.plan)
    }

    /// From reset.
    pub fn new(plan: &kf::Plan) -> Kf {
        Kf {
            plan: plan.clone(),
            model: FixedKf::new(plan),
        }
    }

    /// The plan.
    pub fn plan(&self) -> &kf::Plan {
        &self.plan
    }

    /// The model itself (for block-wise processing).
    pub fn model(&mut self) -> &mut FixedKf {
        &mut self.model
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// One sample: `rate_out`.
    ///
    /// # Errors
    /// `z` outside the input format or `bw_sel` beyond the ROM.
    pub fn step(&mut self, z: i64, bw_sel: i64) -> PortResult<i64> {
        check_code(z, self.plan.input, "z")?;
        let bw_sel = check_bw_sel(bw_sel, self.plan.rom.len(), "bw_sel")?;
        Ok(self.model.step(z, bw_sel))
    }
}
