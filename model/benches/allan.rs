//! Allan analysis: overlapping ADEV over the octave grid on 10^7 samples (goal ≤ 0.12 s on one
//! core), over every tau on 10^5 samples (goal ≤ 0.3 s), and DAVAR of 60 000 samples with a
//! 3001-sample window (goal ≤ 0.1 s).

use criterion::{black_box, criterion_group, criterion_main, Criterion};

use gyrofx_model::analysis::allan::{deviations as all_deviations, factors, phase, Grid, Kind};
use gyrofx_model::analysis::davar::{davar, Window};
use gyrofx_model::stimulus::{Gaussian, Stream};

fn record(n: usize) -> Vec<f64> {
    let mut g = Gaussian::new(1, Stream::AngleRandomWalk(0));
    (0..n).map(|_| g.sample()).collect()
}

fn deviations(rate: &[f64], grid: Grid) -> f64 {
    let x = phase(rate);
    let factors = factors(Kind::Overlapping, grid, x.len());
    all_deviations(Kind::Overlapping, &x, &factors, 100.0)
        .into_iter()
        .flatten()
        .map(|(d, _)| d)
        .sum()
}

fn allan(c: &mut Criterion) {
    let mut group = c.benchmark_group("allan");
    group.sample_size(10);
    let big = record(10_000_000);
    group.bench_function("oadev_octave_1e7", |b| {
        b.iter(|| deviations(black_box(&big), Grid::Octave))
    });
    let small = record(100_000);
    group.bench_function("oadev_all_taus_1e5", |b| {
        b.iter(|| deviations(black_box(&small), Grid::All))
    });
    // Paper 002's case: 60 000 samples, a 3001-sample window moved one sample at a time.
    let paper = record(60_000);
    group.bench_function("davar_60000_window_3001_step_1", |b| {
        b.iter(|| davar(black_box(&paper), 100.0, Window::Fixed(3001), 1))
    });
    group.finish();
}

criterion_group!(benches, allan);
criterion_main!(benches);
