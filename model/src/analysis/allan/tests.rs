//! Tests of the Allan family: NIST SP 1065 reference values, the AVX2 kernel and the blocked
//! pass against the plain ones, the τ grids, noise-type identification and interval coverage.

use super::*;

/// NIST SP 1065 §12.4 / Riley's 1000-point test set: n(i+1) = 16807 n(i) mod (2³¹ − 1),
/// n(0) = 1234567890, y(i) = n(i) / (2³¹ − 1).
fn nbs14_1000() -> Vec<f64> {
    let mut n = vec![1_234_567_890u64];
    for i in 0..999 {
        n.push(16807 * n[i] % 2_147_483_647);
    }
    assert_eq!(&n[1..4], &[395_529_916, 1_209_410_747, 633_705_974]);
    n.iter().map(|v| *v as f64 / 2_147_483_647.0).collect()
}

fn check(kind: Kind, data: &[f64], taus: &[usize], published: &[f64]) {
    let x = phase(data);
    for (m, want) in taus.iter().zip(published) {
        let (got, _) = deviation(kind, &x, *m, 1.0).unwrap();
        // The published values have 7 significant digits.
        assert!(
            (got / want - 1.0).abs() < 1e-6,
            "{kind:?} m = {m}: {got:.9e} vs {want:e}"
        );
    }
}

#[test]
fn reproduces_the_nist_1000_point_reference_values() {
    // NIST SP 1065, p. 108 (Riley, Table III): τ = 1, 10, 100.
    let y = nbs14_1000();
    check(
        Kind::NonOverlapping,
        &y,
        &[1, 10, 100],
        &[2.922319e-01, 9.965736e-02, 3.897804e-02],
    );
    check(
        Kind::Overlapping,
        &y,
        &[1, 10, 100],
        &[2.922319e-01, 9.159953e-02, 3.241343e-02],
    );
    check(
        Kind::Modified,
        &y,
        &[1, 10, 100],
        &[2.922319e-01, 6.172376e-02, 2.170921e-02],
    );
    check(
        Kind::Hadamard,
        &y,
        &[1, 10, 100],
        &[2.943883e-01, 9.581083e-02, 3.237638e-02],
    );
}

#[test]
fn reproduces_the_nist_10_point_reference_values() {
    // NBS14 frequency data (SP 1065 p. 107): τ = 1, 2.
    let y = [
        892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0,
    ];
    check(Kind::NonOverlapping, &y, &[1, 2], &[91.22945, 115.8082]);
    check(Kind::Overlapping, &y, &[1, 2], &[91.22945, 85.95287]);
    check(Kind::Modified, &y, &[1, 2], &[91.22945, 74.78849]);
    check(Kind::Hadamard, &y, &[1, 2], &[70.80607, 85.61487]);
}

#[test]
fn the_avx2_kernel_gives_the_same_bits() {
    use crate::stimulus::{Gaussian, Stream};
    let mut g = Gaussian::new(9, Stream::AngleRandomWalk(0));
    let x = phase(&(0..10_007).map(|_| g.sample()).collect::<Vec<_>>());
    for m in [1usize, 3, 64, 1000] {
        let terms = x.len() - 2 * m;
        let (a, b, c) = (&x[..terms], &x[m..m + terms], &x[2 * m..2 * m + terms]);
        let portable = second_differences_kernel(a, b, c);
        assert_eq!(
            sum_second_differences(a, b, c).to_bits(),
            portable.to_bits(),
            "m {m}"
        );
    }
}

#[test]
fn the_blocked_pass_agrees_with_one_deviation_at_a_time() {
    use crate::stimulus::{Gaussian, Stream};
    let mut g = Gaussian::new(10, Stream::AngleRandomWalk(0));
    let y: Vec<f64> = (0..100_003).map(|_| 0.2 + g.sample()).collect();
    let x = phase(&y);
    let ms = factors(Kind::Overlapping, Grid::Octave, x.len());
    for (m, blocked) in ms.iter().zip(deviations(Kind::Overlapping, &x, &ms, 50.0)) {
        let (a, ta) = blocked.unwrap();
        let (b, tb) = deviation(Kind::Overlapping, &x, *m, 50.0).unwrap();
        assert_eq!(ta, tb);
        // Blocks change the summation order only.
        assert!((a / b - 1.0).abs() < 1e-12, "m {m}: {a} vs {b}");
    }
}

#[test]
fn grids() {
    assert_eq!(
        factors(Kind::Overlapping, Grid::Octave, 101),
        vec![1, 2, 4, 8, 16, 32]
    );
    assert_eq!(
        factors(Kind::Overlapping, Grid::Decade, 1001),
        vec![1, 2, 5, 10, 20, 50, 100, 200]
    );
    assert_eq!(factors(Kind::Hadamard, Grid::All, 11).len(), 3);
    // Ten per decade, log-spaced (round(10^(k/10))), each once.
    assert_eq!(
        factors(Kind::Overlapping, Grid::Many, 2002),
        vec![
            1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25, 32, 40, 50, 63, 79, 100, 126, 158, 200, 251,
            316, 398, 501, 631, 794, 1000
        ]
    );
    assert!(deviation(Kind::Overlapping, &phase(&[1.0; 10]), 5, 1.0).is_none());
}

#[test]
fn noise_types_are_identified() {
    use crate::stimulus::{Gaussian, Stream};
    let mut g = Gaussian::new(2, Stream::AngleRandomWalk(0));
    let white: Vec<f64> = (0..100_000).map(|_| g.sample()).collect();
    let mut walk = 0.0;
    let random_walk: Vec<f64> = white
        .iter()
        .map(|w| {
            walk += w;
            walk
        })
        .collect();
    let white_pm: Vec<f64> = white.windows(2).map(|w| w[1] - w[0]).collect();
    for m in [1, 10, 100] {
        assert_eq!(noise_type(&white, m), Some(0), "white FM at m = {m}");
        assert_eq!(noise_type(&random_walk, m), Some(-2), "RW FM at m = {m}");
    }
    assert_eq!(noise_type(&white_pm, 1), Some(2));
}

/// The lag-1 method as written out plainly: averages collected, each difference stored, every
/// sum its own pass.
fn plain_lag_one(rate: &[f64], m: usize, d: usize) -> (Vec<f64>, f64) {
    let mut z: Vec<f64> = rate
        .chunks_exact(m)
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect();
    let averages = z.clone();
    for _ in 0..d {
        z = z.windows(2).map(|w| w[1] - w[0]).collect();
    }
    let mean = z.iter().sum::<f64>() / z.len() as f64;
    let denominator: f64 = z.iter().map(|v| (v - mean) * (v - mean)).sum();
    let numerator: f64 = z.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    let r1 = if denominator > 0.0 {
        numerator / denominator
    } else {
        0.0
    };
    (averages, r1)
}

#[test]
fn the_fast_lag_one_method_agrees_with_the_plain_one() {
    use proptest::prelude::*;
    let values = prop_oneof![
        4 => -1e3f64..1e3,
        1 => Just(0.0f64),
        1 => any::<i16>().prop_map(f64::from),
    ];
    proptest!(ProptestConfig::with_cases(300), |(
        white in proptest::collection::vec(values, 32..3000),
        m in 1usize..40,
        integrate in 0usize..3,
    )| {
        // White, random-walk or twice-integrated records: each difference order is taken.
        let mut rate = white;
        for _ in 0..integrate {
            let mut sum = 0.0;
            rate = rate.iter().map(|v| { sum += v; sum }).collect();
        }
        prop_assume!(rate.len() / m >= 3);
        for d in 0..=2usize {
            let (averages, want) = plain_lag_one(&rate, m, d);
            let mut z = averages;
            for _ in 0..d {
                z = z.windows(2).map(|w| w[1] - w[0]).collect();
            }
            let got = lag_one_autocorrelation(&z);
            prop_assert!((got - want).abs() <= 1e-9 * (1.0 + want.abs()), "m {} d {}: {} vs {}", m, d, got, want);
        }
    });
}

#[test]
fn the_octave_pyramid_types_each_octave_as_its_plain_averages_do() {
    use crate::stimulus::{Gaussian, Stream};
    let mut g = Gaussian::new(9, Stream::AngleRandomWalk(0));
    let white: Vec<f64> = (0..50_000).map(|_| g.sample()).collect();
    let mut sum = 0.0;
    let walk: Vec<f64> = white
        .iter()
        .map(|v| {
            sum += v;
            sum
        })
        .collect();
    let white_pm: Vec<f64> = white.windows(2).map(|w| w[1] - w[0]).collect();
    // A mix whose type changes across the octaves (white at short τ, walk at long).
    let mix: Vec<f64> = white
        .iter()
        .zip(&walk)
        .map(|(w, r)| 30.0 * w + 0.05 * r)
        .collect();
    let octaves: Vec<usize> = (0..12).map(|k| 1 << k).collect();
    let mut seen = std::collections::BTreeSet::new();
    for rate in [&white, &walk, &white_pm, &mix] {
        for (octave, alpha) in noise_types(rate, &octaves) {
            assert_eq!(
                alpha,
                noise_type(rate, octave).unwrap_or(0),
                "octave {octave}"
            );
            seen.insert(alpha);
        }
    }
    assert!(seen.len() >= 3, "the records cover several types: {seen:?}");
}

#[test]
fn confidence_intervals_cover_the_truth_about_68_percent_of_the_time() {
    use crate::stimulus::{Gaussian, Stream};
    // White FM of σ = 1 per sample: ADEV(m) = 1/√m exactly in expectation.
    let mut covered = 0;
    let trials = 200;
    for seed in 0..trials {
        let mut g = Gaussian::new(seed, Stream::RateRandomWalk(1));
        let y: Vec<f64> = (0..2000).map(|_| g.sample()).collect();
        let p = curve(Kind::Overlapping, &y, 1.0, Grid::Octave);
        let point = p.iter().find(|p| p.m == 16).unwrap();
        let truth = 1.0 / 4.0;
        covered += usize::from(point.lo <= truth && truth <= point.hi);
    }
    let rate = covered as f64 / trials as f64;
    assert!((0.58..=0.78).contains(&rate), "coverage {rate}");
}

/// Each kind gets its own degrees of freedom: the non-overlapping deviation averages about m
/// times fewer terms than the overlapping one at the same τ, the modified fewer than the
/// overlapping; and every point of every kind rests on at least two terms.
#[test]
fn each_kind_has_its_own_degrees_of_freedom_and_at_least_two_terms() {
    let data: Vec<f64> = nbs14_1000().iter().cycle().take(20_000).copied().collect();
    let at = |kind: Kind, grid: Grid| curve(kind, &data, 1.0, grid);
    let overlapping = at(Kind::Overlapping, Grid::Octave);
    let non_overlapping = at(Kind::NonOverlapping, Grid::Octave);
    let modified = at(Kind::Modified, Grid::Octave);
    for m in [8usize, 32, 128] {
        let edf = |c: &[Point]| c.iter().find(|p| p.m == m).unwrap().edf;
        assert!(edf(&non_overlapping) < edf(&overlapping) / 2.0, "m {m}");
        assert!(edf(&modified) < edf(&overlapping), "m {m}");
    }
    for kind in [
        Kind::Overlapping,
        Kind::NonOverlapping,
        Kind::Modified,
        Kind::Hadamard,
    ] {
        let points = curve(kind, &data[..301], 1.0, Grid::All);
        assert!(points.iter().all(|p| p.terms >= 2), "{kind:?}");
        assert_eq!(
            points.last().unwrap().m,
            max_factor(kind, 302),
            "{kind:?}: the grid goes to the last factor with two terms"
        );
    }
}

/// Computing a long grid in chunks, each reported, gives the points of one pass.
#[test]
fn the_reported_curve_is_the_curve() {
    let data: Vec<f64> = nbs14_1000().iter().cycle().take(3000).copied().collect();
    let mut reports = Vec::new();
    let chunked = curve_reporting(
        Kind::Overlapping,
        &data,
        1.0,
        Grid::All,
        &mut |done, total| {
            reports.push((done, total));
        },
    );
    assert_eq!(chunked, curve(Kind::Overlapping, &data, 1.0, Grid::All));
    let total = max_factor(Kind::Overlapping, 3001);
    assert_eq!(reports.len(), total.div_ceil(FACTORS_PER_CHUNK));
    assert_eq!(reports.last(), Some(&(total, total)));
}

/// Every point carries the noise type of its octave, typed on the cores in any order: on a
/// record whose type changes with τ (white plus a random walk), against one octave at a time.
#[test]
fn each_point_has_its_octaves_noise_type() {
    let mut white = crate::stimulus::Gaussian::new(5, crate::stimulus::Stream::AngleRandomWalk(0));
    let mut walk = crate::stimulus::Gaussian::new(5, crate::stimulus::Stream::RateRandomWalk(0));
    let mut level = 0.0;
    let rate: Vec<f64> = (0..200_000)
        .map(|_| {
            level += 0.003 * walk.sample();
            white.sample() + level
        })
        .collect();
    for grid in [Grid::Octave, Grid::Many] {
        let points = curve(Kind::Overlapping, &rate, 100.0, grid);
        let alphas: std::collections::BTreeSet<i32> = points.iter().map(|p| p.alpha).collect();
        assert!(alphas.len() >= 2, "{alphas:?}");
        for p in &points {
            let octave = 1usize << (usize::BITS - 1 - p.m.leading_zeros());
            assert_eq!(p.alpha, noise_type(&rate, octave).unwrap_or(0), "m {}", p.m);
        }
    }
}
