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

#[test]
fn print_switch_trace() {
    use crate::gyro_loop::closed::{FixedClosedLoop, LoopUnderTest};
    use crate::resonator::Mode;
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    let mut c = FixedClosedLoop::new(&plan, &spec.resonator, &spec.front_end.noiseless(), 0).unwrap();
    for _ in 0..80 { c.step_chain(0.0, Mode::Normal); }
    c.set(0.0, Mode::Reverse);
    for k in 0..60 {
        let w = c.advance(1000);
        let f = c.gyro.frequency_hz();
        println!("{:5.1} ms amp {:.6e} f {:.4} locked {} rate {:?} agc {}", (k+1) as f64*5.0, w.drive_amplitude_m, f, w.locked, w.chain.map(|c| c.rate_dps), c.gyro.gyro.agc_integrator());
    }
}
