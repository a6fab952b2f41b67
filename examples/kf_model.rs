//! The bit-accurate KF from Rust, on the default config: what a C++ or Rust testbench gets from
//! gyrofx's crates. `cargo run --example kf_model` prints a step response in codes and °/s, and
//! the fixed-versus-float difference in output LSB; the test suite runs it (`test = true`).

use gyrofx_job::config::Config;
use gyrofx_job::golden;
use gyrofx_job::job::Job;
use gyrofx_model::kf::FloatKf;

fn main() {
    // The embedded default config, resolved as `gyrofx generate` resolves it.
    let job = Job::new(Config::embedded()).expect("the default config is valid");
    let plan = &job.chain.kf;
    // The port-level model: codes in, codes out, every input checked against its port.
    let mut kf = golden::Kf::new(plan);
    // Its float twin on the same quantized gains.
    let mut twin = FloatKf::new(plan.quantized_gains());
    let step = 10.0; // °/s
    let z = (step / plan.input.lsb()).round() as i64;
    let mut worst_lsb: f64 = 0.0;
    for k in 0..200 {
        let rate_out = kf.step(z, 1).expect("z is a code of the input format");
        let real = twin.step(plan.input.to_f64(i128::from(z)), 1);
        let fixed = plan.output.to_f64(i128::from(rate_out));
        worst_lsb = worst_lsb.max((fixed - real).abs() / plan.output.lsb());
        if k % 40 == 0 {
            println!("sample {k:3}: rate_out = {rate_out:8} ({fixed:.5} °/s), float {real:.5} °/s");
        }
    }
    println!(
        "fixed vs float over 200 samples: {worst_lsb:.3} LSB of {}",
        plan.output
    );
    assert!(
        worst_lsb < 1.0,
        "the fixed KF stays within an LSB of its twin here"
    );
}

#[test]
fn runs() {
    main();
}
