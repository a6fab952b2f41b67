//! `generate` of 10^6 chain samples with every block's files, written to disk (goal: < 1 s),
//! on the rate-level plant: this measures the chain and the writers, not the resonators.

use criterion::{criterion_group, criterion_main, Criterion};

use gyrofx_codegen::generate::{generate, provenance, Contents, Options, Output};
use gyrofx_codegen::output_folder::Replace;
use gyrofx_codegen::progress::Progress;
use gyrofx_job::config::Config;
use gyrofx_job::job::Job;

fn generate_million(c: &mut Criterion) {
    let mut config =
        Config::from_toml("[plant]\nmodel = \"rate\"\n", "bench.toml").expect("a valid overlay");
    config.samples = 1_000_000;
    let job = Job::new(config).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pkg");
    let provenance = provenance(&job, Output::Package, None, None);
    let mut group = c.benchmark_group("generate");
    group.sample_size(10);
    group.bench_function("default_1M_samples_all_files", |b| {
        b.iter(|| {
            generate(
                &job,
                &out,
                Options {
                    replace: Replace::IfOwned,
                    strict: false,
                    contents: Contents::default(),
                },
                &provenance,
                &Progress::default(),
            )
            .unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, generate_million);
criterion_main!(benches);
