//! Resonator throughput (goal: >= 20 M steps/s on one core without noise) and the cost of
//! recomputing the discretisation when the rate changes.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::resonator::{PhysicsSettings, Resonator, ResonatorParams};

fn resonator(c: &mut Criterion) {
    let params = ResonatorParams::paper_004();
    const N: usize = 1 << 16;
    let w = 2.0 * std::f64::consts::PI * params.drive_frequency_hz / 200e3;
    let force: Vec<f64> = (0..N).map(|k| 1.5e-5 * libm::sin(w * k as f64)).collect();

    let mut group = c.benchmark_group("resonator");
    group.throughput(Throughput::Elements(N as u64));
    for (name, settings) in [
        ("step_noiseless_64k", PhysicsSettings::example().noiseless()),
        ("step_all_noise_64k", PhysicsSettings::example()),
    ] {
        group.bench_function(name, |b| {
            let mut r = Resonator::new(&params, &settings, 1).unwrap();
            b.iter(|| {
                let mut acc = 0.0;
                for f in &force {
                    acc += r.step([*f, 0.0])[1];
                }
                black_box(acc)
            })
        });
    }
    group.throughput(Throughput::Elements(1));
    for (name, settings) in [
        ("set_rate_noiseless", PhysicsSettings::example().noiseless()),
        ("set_rate_with_noise", PhysicsSettings::example()),
    ] {
        group.bench_function(name, |b| {
            let mut r = Resonator::new(&params, &settings, 1).unwrap();
            let mut omega = 0.0;
            b.iter(|| {
                omega += 1e-3;
                r.set_rate(black_box(omega));
            })
        });
    }
    group.finish();
}

criterion_group!(benches, resonator);
criterion_main!(benches);
