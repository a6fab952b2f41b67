//! Fixed-point KF throughput (goal: >= 100 M samples/s on one core) and, for scale, the float
//! golden model.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::examples;
use gyrofx_model::kf::{FixedKf, FloatKf, Plan};
use gyrofx_model::stimulus::adc;

fn kf(c: &mut Criterion) {
    let plan = Plan::new(&examples::kf_spec()).unwrap();
    const N: usize = 1 << 20;
    let (z, _) = adc(&examples::gyro().simulate(N, 1).analog, plan.input);
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
