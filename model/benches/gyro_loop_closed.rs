//! One gyro closed: the resonator physics and the fixed-point loop, per ADC sample (goal: at
//! least 10 M gyro-samples/s on one core), noiseless and with the front end's noise and
//! drift; both gyros on two threads (as `generate` runs them); and the fixed loop alone on
//! recorded ADC codes.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::gyro_loop::closed::FixedClosedLoop;
use gyrofx_model::gyro_loop::gyro::{FixedGyroLoop, Plan, Spec};
use gyrofx_model::resonator::Mode;

fn closed_loop(c: &mut Criterion) {
    let spec = Spec::paper_004();
    let plan = Plan::new(&spec).unwrap();
    const N: u32 = 1 << 16;
    let mut group = c.benchmark_group("gyro_loop_closed");
    group.throughput(Throughput::Elements(u64::from(N)));
    let mut closed =
        FixedClosedLoop::new(&plan, &spec.resonator, &spec.front_end.noiseless(), 1).unwrap();
    closed.set(10.0, Mode::Normal);
    closed.advance(200_000);
    group.bench_function("physics_and_fixed_loop_64k", |b| {
        b.iter(|| black_box(closed.advance(N)))
    });

    let mut noisy = FixedClosedLoop::new(&plan, &spec.resonator, &spec.front_end, 1).unwrap();
    noisy.set(10.0, Mode::Normal);
    noisy.advance(200_000);
    group.bench_function("physics_with_noise_and_fixed_loop_64k", |b| {
        b.iter(|| black_box(noisy.advance(N)))
    });

    // Two gyros, one thread each: twice the samples per iteration.
    let mut pair = [noisy.clone(), noisy.clone()];
    group.throughput(Throughput::Elements(2 * u64::from(N)));
    group.bench_function("two_gyros_with_noise_on_two_threads_2x64k", |b| {
        b.iter(|| {
            let [a, b] = &mut pair;
            std::thread::scope(|scope| {
                let other = scope.spawn(|| black_box(b.advance(N)));
                black_box(a.advance(N));
                other.join().expect("no panic");
            })
        })
    });
    group.throughput(Throughput::Elements(u64::from(N)));

    // The loop alone, on ADC codes recorded from the locked closed loop.
    let mut recorder = closed.clone();
    let mut gyro = FixedGyroLoop::new(&plan);
    let mut codes = Vec::with_capacity(N as usize);
    let mut adc = [0i64; 2];
    for _ in 0..N {
        let out = recorder.gyro.gyro.step(adc, Mode::Normal);
        adc = recorder.resonator.step_codes(out.dac);
        codes.push(adc);
    }
    group.bench_function("fixed_loop_only_64k", |b| {
        b.iter(|| {
            let mut acc = 0i64;
            for x in &codes {
                acc = acc.wrapping_add(gyro.step(*x, Mode::Normal).dac[0]);
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, closed_loop);
criterion_main!(benches);
