//! Throughput of the gyro-loop blocks (goal: the whole loop, physics included, at >= 10 M
//! gyro-samples/s on one core), each on its own and the open-loop set one gyro needs per ADC
//! sample: two NCO reads (drive and sense references), two demodulators, two PI controllers
//! (PLL and AGC) and the CIC.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::gyro_loop::{cic, demodulator, nco, pi};

fn gyro_loop(c: &mut Criterion) {
    const N: usize = 1 << 16;
    let nco_plan = nco::Plan::new(&nco::Spec::default()).unwrap();
    let demodulator_plan = demodulator::Plan::new(&demodulator::Spec::default()).unwrap();
    let pi_plan = pi::Plan::new(&pi::Spec::default()).unwrap();
    let cic_plan = cic::Plan::new(&cic::Spec::default()).unwrap();
    let freq = nco_plan.frequency_word(8195.0, 200_000.0).unwrap();
    let adc: Vec<i64> = (0..N as i64)
        .map(|k| ((k * 2_654_435_761) % (1 << 23)) - (1 << 22))
        .collect();

    let mut group = c.benchmark_group("gyro_loop");
    group.throughput(Throughput::Elements(N as u64));
    // The default NCO carries its truncation error; `nco_plain` is the plain truncation, for
    // what the error feedback costs per sample.
    let plain_plan = nco::Plan::new(&nco::Spec {
        error_feedback: false,
        ..nco::Spec::default()
    })
    .unwrap();
    for (name, plan) in [("nco", &nco_plan), ("nco_plain", &plain_plan)] {
        group.bench_function(name, |b| {
            let mut m = nco::FixedNco::new(plan);
            b.iter(|| {
                let mut acc = 0i64;
                for _ in 0..N {
                    acc = acc.wrapping_add(m.step(black_box(freq), 0).sin);
                }
                black_box(acc)
            })
        });
    }
    group.bench_function("demodulator", |b| {
        let mut m = demodulator::FixedDemodulator::new(&demodulator_plan);
        let reference = nco::Reference {
            sin: 70_000,
            cos: -90_000,
        };
        b.iter(|| {
            let mut acc = 0i64;
            for x in &adc {
                acc = acc.wrapping_add(m.step(*x, black_box(reference)).i);
            }
            black_box(acc)
        })
    });
    group.bench_function("pi", |b| {
        let mut m = pi::FixedPi::new(&pi_plan);
        b.iter(|| {
            let mut acc = 0i64;
            for x in &adc {
                acc = acc.wrapping_add(m.step(*x));
            }
            black_box(acc)
        })
    });
    group.bench_function("cic", |b| {
        let mut m = cic::FixedCic::new(&cic_plan);
        b.iter(|| {
            let mut acc = 0i64;
            for x in &adc {
                acc = acc.wrapping_add(m.step(*x).unwrap_or(0));
            }
            black_box(acc)
        })
    });
    group.bench_function("open_loop_set_per_gyro_sample", |b| {
        let mut drive_nco = nco::FixedNco::new(&nco_plan);
        let mut sense_nco = nco::FixedNco::new(&nco_plan);
        let mut drive = demodulator::FixedDemodulator::new(&demodulator_plan);
        let mut sense = demodulator::FixedDemodulator::new(&demodulator_plan);
        let mut pll = pi::FixedPi::new(&pi_plan);
        let mut agc = pi::FixedPi::new(&pi_plan);
        let mut decimator = cic::FixedCic::new(&cic_plan);
        let mut word = freq as i64;
        b.iter(|| {
            let mut acc = 0i64;
            for x in &adc {
                let f = word as u64 & 0xffff_ffff;
                let d = drive.step(*x, drive_nco.step(f, 0));
                let s = sense.step(*x, sense_nco.step(f, 1 << 29));
                word = pll.step(d.q);
                acc = acc.wrapping_add(agc.step(d.i));
                acc = acc.wrapping_add(decimator.step(s.i).unwrap_or(0));
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, gyro_loop);
criterion_main!(benches);
