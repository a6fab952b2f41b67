//! The loop closed around paper 004's resonator.

use super::*;
use crate::gyro_loop::closed::{FixedHarness, FloatHarness};
use crate::gyro_loop::figures::{characterize, Procedure};

#[test]
fn print_characterization() {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    println!("{:#?}", plan.design);
    println!("{:#?}", plan.modes[0]);
    let c = characterize::<FixedHarness>(&plan, &spec.resonator, &spec.front_end, &Procedure::default()).unwrap();
    println!("{}", serde_json::to_string_pretty(&c).unwrap());
    let c = characterize::<FloatHarness>(&plan, &spec.resonator, &spec.front_end, &Procedure::default()).unwrap();
    println!("{}", serde_json::to_string_pretty(&c).unwrap());
}
