//! The population study's speed on one core: one member (both gyros characterized, then 2 s
//! of chain run with noise) end to end. Gyro-samples per second = the member's gyro-samples
//! (reported by the study) over the time criterion measures.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_job::config::Config;
use gyrofx_job::population::{Population, RunSettings};

fn member(c: &mut Criterion) {
    let config = Config::from_toml(
        "[population.resonator]\nq_drive = { distribution = \"normal\", std = 0.05, relative = true }\n",
        "bench",
    )
    .unwrap();
    let population = Population::new(&config).unwrap();
    let settings = RunSettings {
        seconds: 2.0,
        noise: true,
    };
    let samples = population.study(0, &settings).figures.unwrap().gyro_samples;
    let mut group = c.benchmark_group("population");
    group.sample_size(10);
    group.throughput(Throughput::Elements(samples));
    group.bench_function("member_2s_noise", |b| {
        b.iter(|| population.study(0, &settings))
    });
    group.finish();
}

criterion_group!(benches, member);
criterion_main!(benches);
