//! Fixed-point KF throughput (goal: >= 100 M samples/s on one core) and, for scale, the float
//! golden model.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::fx::{Overflow, Rounding};
use gyrofx_model::kf::design::{design_for_bandwidth, Convergence, Method, Noise};
use gyrofx_model::kf::{CoefficientFormat, FixedKf, FloatKf, Plan, Spec};
use gyrofx_model::stimulus::{adc, Scenario, SingleGyro};

fn default_plan() -> Plan {
    let noise = Noise::from_gyro_units(4.87, 1200.0, 0.0);
    let gains = [10.0, 20.0, 30.0]
        .iter()
        .map(|bw| {
            design_for_bandwidth(*bw, noise, 200.0, Method::Direct, Convergence::default())
                .unwrap()
                .g
        })
        .collect();
    Plan::new(&Spec {
        input: "s24.14".parse().unwrap(),
        state: "s36.26".parse().unwrap(),
        output: "s24.14".parse().unwrap(),
        coefficients: [CoefficientFormat::Auto { width: 18 }; 2],
        rounding: Rounding::Nearest,
        overflow: Overflow::Saturate,
        gains,
        labels: vec!["10 Hz".into(), "20 Hz".into(), "30 Hz".into()],
    })
    .unwrap()
}

fn kf(c: &mut Criterion) {
    let plan = default_plan();
    const N: usize = 1 << 20;
    let gyro = SingleGyro {
        fs_hz: 200.0,
        scenario: Scenario::Sine {
            amplitude_dps: 20.0,
            frequency_hz: 0.5,
        },
        initial_bias_dps: 0.5,
        arw_deg_per_sqrt_h: 4.87,
        rrw_deg_per_h_per_sqrt_h: 1200.0,
    };
    let (z, _) = adc(&gyro.simulate(N, 1).analog, plan.input);
    let z_real: Vec<f64> = z
        .iter()
        .map(|c| plan.input.to_f64(i128::from(*c)))
        .collect();
    let mut out = vec![0i64; N];

    let mut group = c.benchmark_group("kf");
    group.throughput(Throughput::Elements(N as u64));
    group.bench_function("fixed_process_1M", |b| {
        let mut model = FixedKf::new(&plan);
        b.iter(|| {
            model.process(black_box(&z), 0, &mut out);
            black_box(&out);
        })
    });
    group.bench_function("float_1M", |b| {
        let mut model = FloatKf::new(plan.quantized_gains());
        b.iter(|| {
            let mut acc = 0.0;
            for v in &z_real {
                acc += model.step(*v, 0);
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, kf);
criterion_main!(benches);
