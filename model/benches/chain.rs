//! The mode-reversal chain: the fixed chain on pre-generated gyro samples (goal ≥ 50 M
//! samples/s) and the whole chain including the two-gyro plant (goal ≥ 10 M samples/s).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

use gyrofx_model::chain::{FixedChain, Plan};
use gyrofx_model::examples;
use gyrofx_model::fx::Rounding;
use gyrofx_model::plant::{GyroErrors, Plant};
use gyrofx_model::sequencer::Sequencer;
use gyrofx_model::stimulus::adc;

const N: usize = 1 << 20;

fn plan() -> Plan {
    examples::chain_plan(150, 10, 0, 0, Rounding::Nearest)
}

fn plant() -> Plant {
    let gyro = |bias| GyroErrors {
        sf_ppm: 0.0,
        sf_mode_mismatch_ppm: 0.0,
        bias_dps: bias,
        bias_mode_mismatch_dps: 0.0,
        arw_deg_per_sqrt_h: 4.87,
        bias_instability_deg_per_h: 44.41,
        rrw_deg_per_h_per_sqrt_h: 1200.0,
        rate_ramp_deg_per_h2: 0.0,
        settle_tau_s: 0.005,
    };
    Plant {
        fs_hz: 200.0,
        gyros: [gyro(0.5), gyro(-0.3)],
        bi_tau_min_s: 0.5,
        bi_tau_max_s: 500.0,
    }
}

fn modes(plan: &Plan) -> Vec<[i8; 2]> {
    let mut seq = Sequencer::new(&plan.estimator.schedule);
    (0..N)
        .map(|_| {
            let s = seq.advance();
            [s.mode_a, s.mode_b]
        })
        .collect()
}

fn chain(c: &mut Criterion) {
    let plan = plan();
    let plant = plant();
    let rate = vec![10.0; N];
    let modes = modes(&plan);
    let record = plant.simulate(&rate, &modes, 1);
    let (ya, _) = adc(&record.y[0], plan.estimator.input);
    let (yb, _) = adc(&record.y[1], plan.estimator.input);

    let mut group = c.benchmark_group("chain");
    group.throughput(Throughput::Elements(N as u64));
    group.sample_size(10);
    let y: Vec<[i64; 2]> = ya.iter().zip(&yb).map(|(a, b)| [*a, *b]).collect();
    let mut rates = vec![None; N];
    group.bench_function("fixed_chain_process_1M", |b| {
        b.iter(|| {
            let mut chain = FixedChain::new(&plan);
            chain.process(black_box(&y), 0, &mut rates);
            black_box(&rates);
        })
    });
    group.bench_function("fixed_chain_step_1M", |b| {
        b.iter(|| {
            let mut chain = FixedChain::new(&plan);
            let mut acc = 0i64;
            for k in 0..N {
                if let Some(r) = chain.step([ya[k], yb[k]], 0).rate {
                    acc = acc.wrapping_add(r);
                }
            }
            black_box(acc)
        })
    });
    group.bench_function("plant_and_fixed_chain_1M", |b| {
        b.iter(|| {
            let record = plant.simulate(&rate, &modes, 2);
            let (ya, _) = adc(&record.y[0], plan.estimator.input);
            let (yb, _) = adc(&record.y[1], plan.estimator.input);
            let mut chain = FixedChain::new(&plan);
            let mut acc = 0i64;
            for k in 0..N {
                if let Some(r) = chain.step([ya[k], yb[k]], 0).rate {
                    acc = acc.wrapping_add(r);
                }
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, chain);
criterion_main!(benches);
