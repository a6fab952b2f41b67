//! Allan-family deviations of rate records, their confidence intervals, and noise types.
//!
//! Input is a rate record (°/s, or any "frequency" data) at `rate_hz`; the phase (angle) is its
//! prefix sum `x[k] = τ0 Σ_{i<k} y[i]`. The mean is removed before summing: the deviations are
//! differences of the phase and do not depend on a constant rate offset, and without it the
//! phase of a biased gyro grows linearly and the differences cancel its leading digits. With
//! the mean removed the phase is a zero-mean walk of size `~√N σ`, so each running-sum step
//! rounds by at most `ulp(√N σ)` and the error of a difference over `m` steps stays below
//! `~√m · √N σ · 2⁻⁵³`: for N = 10⁷ and m = 1 a relative error of ~3e-13 of σ — far below
//! any confidence interval. Each deviation at an averaging factor `m` (τ = m τ0) is one O(N)
//! pass:
//!
//! - overlapping ADEV: `σ² = Σ_{i=0}^{N−2m−1} (x[i+2m] − 2x[i+m] + x[i])² / (2 τ² (N − 2m))`
//! - non-overlapping ADEV: the same over `i = 0, m, 2m, …`
//! - modified ADEV: `σ² = Σ_j (Σ_{i=j}^{j+m−1} (x[i+2m] − 2x[i+m] + x[i]))² / (2 m² τ² (N − 3m + 1))`,
//!   the inner sum kept as a sliding window
//! - overlapping Hadamard: `σ² = Σ (x[i+3m] − 3x[i+2m] + 3x[i+m] − x[i])² / (6 τ² (N − 3m))`
//!
//! with `N` the number of phase points (samples + 1), as in NIST SP 1065 (§5.2), whose
//! reference values the tests reproduce.
//!
//! Confidence intervals: the equivalent degrees of freedom of the kind's estimator
//! (Greenhall & Riley 2003, [`edf`]; [`edf_overlapping`] keeps SP 1065 Table 5's simple
//! approximations for the overlapping ADEV) for the noise type identified at that τ, and the χ²
//! interval `σ² · edf / χ²(p)` (SP 1065 eq. 45), by default
//! the 68.3 % (1σ) interval. The noise type at each τ comes from the lag-1 autocorrelation of
//! the τ-averaged rate (Riley & Greenhall 2004): `ρ = r1/(1 + r1)`, differencing while `ρ >= ¼`
//! (at most twice), `α = −2(ρ + d)` rounded — α = 2 white PM (quantization), 0 white FM
//! (ARW), −1 flicker FM (bias instability), −2 random-walk FM (RRW).

use super::chi2::chi2_quantile;
use super::edf;

mod stream;
pub use stream::OverlappingStream;

/// Which deviation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Overlapping Allan deviation.
    Overlapping,
    /// Non-overlapping (classic) Allan deviation.
    NonOverlapping,
    /// Modified Allan deviation.
    Modified,
    /// Overlapping Hadamard deviation.
    Hadamard,
}

/// Which averaging factors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Grid {
    /// 1, 2, 4, 8, …
    Octave,
    /// 1, 2, 5, 10, 20, 50, …
    Decade,
    /// Every m.
    All,
    /// Ten log-spaced factors per decade (1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25, …).
    Many,
}

impl std::str::FromStr for Grid {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "octave" => Ok(Grid::Octave),
            "decade" => Ok(Grid::Decade),
            "all" => Ok(Grid::All),
            "many" => Ok(Grid::Many),
            other => Err(format!(
                "'{other}' is not a tau grid: expected octave, decade, many or all"
            )),
        }
    }
}

/// The phase of a rate record (in units of rate × samples; multiply by τ0 for angle), mean
/// removed (see the module doc for the precision): `N + 1` points for `N` samples.
pub fn phase(rate: &[f64]) -> Vec<f64> {
    let mean = rate.iter().sum::<f64>() / rate.len().max(1) as f64;
    let mut out = Vec::with_capacity(rate.len() + 1);
    let mut sum = 0.0f64;
    out.push(0.0);
    out.extend(rate.iter().map(|v| {
        sum += v - mean;
        sum
    }));
    out
}

/// Largest averaging factor `kind` can use on `points` phase points: a deviation rests on at
/// least two terms (differences) for every kind.
pub fn max_factor(kind: Kind, points: usize) -> usize {
    match kind {
        Kind::Overlapping => points.saturating_sub(2) / 2,
        Kind::NonOverlapping => points.saturating_sub(1) / 3,
        Kind::Modified => points.saturating_sub(1) / 3,
        Kind::Hadamard => points.saturating_sub(2) / 3,
    }
}

/// The averaging factors of `grid` for a record of `points` phase points.
pub fn factors(kind: Kind, grid: Grid, points: usize) -> Vec<usize> {
    let max = max_factor(kind, points);
    let mut out = Vec::new();
    match grid {
        Grid::All => out.extend(1..=max),
        Grid::Octave => {
            let mut m = 1;
            while m <= max {
                out.push(m);
                m *= 2;
            }
        }
        Grid::Many => {
            // round(10^(k/10)), each factor once; exact powers of ten by integer steps.
            let mut k = 0u32;
            loop {
                let decade = 10usize.saturating_pow(k / 10);
                let m =
                    (decade as f64 * libm::pow(10.0, f64::from(k % 10) / 10.0)).round() as usize;
                if m > max || decade == usize::MAX {
                    break;
                }
                if out.last() != Some(&m) {
                    out.push(m);
                }
                k += 1;
            }
        }
        Grid::Decade => {
            let mut decade = 1usize;
            'outer: loop {
                for step in [1, 2, 5] {
                    let m = step * decade;
                    if m > max {
                        break 'outer;
                    }
                    out.push(m);
                }
                decade *= 10;
            }
        }
    }
    out
}

/// `Σ_i (c[i] − 2 b[i] + a[i])²`: the overlapping ADEV's second differences, summed in
/// [`LANES`] lanes (lane = i mod LANES) added pairwise at the end. On x86-64 with AVX2 the same code is compiled for
/// 256-bit vectors and chosen at run time; every lane adds the same terms in the same order
/// (and Rust never fuses a multiply and an add), so the result is bit-identical either way.
#[inline]
fn sum_second_differences(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { sum_second_differences_avx2(a, b, c) };
        }
    }
    second_differences_kernel(a, b, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn sum_second_differences_avx2(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    second_differences_kernel(a, b, c)
}

/// Lanes of the second-difference sum: enough independent accumulators to hide the add
/// latency (eight 256-bit registers with AVX2; measured: 16 lanes 360 ms, 32 lanes 285 ms, 64
/// lanes 278 ms for every tau of 10^5 samples).
const LANES: usize = 32;

#[inline(always)]
fn second_differences_kernel(a: &[f64], b: &[f64], c: &[f64]) -> f64 {
    let mut acc = [0.0f64; LANES];
    let chunks = a.len() / LANES;
    for ((a, b), c) in a
        .chunks_exact(LANES)
        .zip(b.chunks_exact(LANES))
        .zip(c.chunks_exact(LANES))
    {
        for lane in 0..LANES {
            let v = c[lane] - 2.0 * b[lane] + a[lane];
            acc[lane] += v * v;
        }
    }
    // A fixed pairwise order for the lanes.
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for lane in 0..width {
            acc[lane] += acc[lane + width];
        }
    }
    let mut total = acc[0];
    for i in LANES * chunks..a.len() {
        let v = c[i] - 2.0 * b[i] + a[i];
        total += v * v;
    }
    total
}

/// `Σ_i (c[i] + k1·b[i] + k0·a[i] + k2·d[i])²` over equal-length slices with four accumulators
/// (lane = i mod 4, summed at the end): fixed-size chunks let the compiler use packed
/// arithmetic, and the summation order is the same on every platform.
#[inline]
fn sum_squares(a: &[f64], b: &[f64], c: &[f64], d: &[f64], k: [f64; 3]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = a.len() / 4;
    let (a4, b4, c4, d4) = (
        a.chunks_exact(4),
        b.chunks_exact(4),
        c.chunks_exact(4),
        d.chunks_exact(4),
    );
    for (((a, b), c), d) in a4.zip(b4).zip(c4).zip(d4) {
        for lane in 0..4 {
            let v = c[lane] + k[1] * b[lane] + k[0] * a[lane] + k[2] * d[lane];
            acc[lane] += v * v;
        }
    }
    let mut total = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in 4 * chunks..a.len() {
        let v = c[i] + k[1] * b[i] + k[0] * a[i] + k[2] * d[i];
        total += v * v;
    }
    total
}

/// The deviation `kind` at averaging factor `m` from the phase `x` (see [`phase`]) of a
/// record sampled at `rate_hz`, with the number of terms it averaged. `None` when the record
/// is too short for `m`.
pub fn deviation(kind: Kind, x: &[f64], m: usize, rate_hz: f64) -> Option<(f64, usize)> {
    let n = x.len();
    if m == 0 || m > max_factor(kind, n) {
        return None;
    }
    let tau = m as f64 / rate_hz;
    let tau0 = 1.0 / rate_hz;
    // Phase in angle units: x · τ0.
    let (sum, terms, normalization) = match kind {
        Kind::Overlapping => {
            // x[i+2m] − 2x[i+m] + x[i]
            let terms = n - 2 * m;
            let (a, b, c) = (&x[..terms], &x[m..m + terms], &x[2 * m..2 * m + terms]);
            let s = sum_second_differences(a, b, c);
            (s, terms, 2.0 * terms as f64)
        }
        Kind::NonOverlapping => {
            let terms = (n - 1 - 2 * m) / m + 1;
            let mut s = 0.0;
            for j in 0..terms {
                let i = j * m;
                let v = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                s += v * v;
            }
            (s, terms, 2.0 * terms as f64)
        }
        Kind::Hadamard => {
            // x[i+3m] − 3x[i+2m] + 3x[i+m] − x[i]
            let terms = n - 3 * m;
            let (a, b, c, d) = (
                &x[..terms],
                &x[2 * m..2 * m + terms],
                &x[3 * m..3 * m + terms],
                &x[m..m + terms],
            );
            let s = sum_squares(a, b, c, d, [-1.0, -3.0, 3.0]);
            (s, terms, 6.0 * terms as f64)
        }
        Kind::Modified => {
            let terms = n - 3 * m + 1;
            let second = |i: usize| x[i + 2 * m] - 2.0 * x[i + m] + x[i];
            let mut window: f64 = (0..m).map(second).sum();
            let mut s = window * window;
            for j in 1..terms {
                window += second(j + m - 1) - second(j - 1);
                s += window * window;
            }
            (s, terms, 2.0 * (m * m) as f64 * terms as f64)
        }
    };
    let variance = sum * tau0 * tau0 / (normalization * tau * tau);
    Some((variance.sqrt(), terms))
}

/// Noise type at averaging factor `m` by the lag-1 autocorrelation of the m-averaged rate:
/// the power-law exponent α (2, 1, 0, −1, −2), or `None` with fewer than 32 averages.
pub fn noise_type(rate: &[f64], m: usize) -> Option<i32> {
    let m = m.max(1);
    let mut scratch = Vec::new();
    if m == 1 {
        type_of_averages(rate, &mut scratch)
    } else {
        let averages: Vec<f64> = rate
            .chunks_exact(m)
            .map(|c| c.iter().sum::<f64>() / m as f64)
            .collect();
        type_of_averages(&averages, &mut scratch)
    }
}

/// The noise type of a series of averages: from the lag-1 autocorrelation `r1` of the series
/// differenced `d` times, the first `d` (at most 2) where `ρ = r1/(1+r1) < 0.25` gives
/// `α = −2(ρ + d)`, rounded (Riley and Greenhall's lag-1 method). `scratch` holds the
/// differences when they are needed.
fn type_of_averages(averages: &[f64], scratch: &mut Vec<f64>) -> Option<i32> {
    if averages.len() < 32 {
        return None;
    }
    // α for the series differenced `d` times, or `None` to difference once more.
    let alpha = |r1: f64, d: usize| {
        let rho = r1 / (1.0 + r1);
        (rho < 0.25 || d >= 2).then(|| ((-2.0 * (rho + d as f64)).round() as i32).clamp(-2, 2))
    };
    if let Some(a) = alpha(lag_one_autocorrelation(averages), 0) {
        return Some(a);
    }
    scratch.clear();
    scratch.extend(averages.windows(2).map(|w| w[1] - w[0]));
    if let Some(a) = alpha(lag_one_autocorrelation(scratch), 1) {
        return Some(a);
    }
    for i in 0..scratch.len() - 1 {
        scratch[i] = scratch[i + 1] - scratch[i];
    }
    scratch.pop();
    alpha(lag_one_autocorrelation(scratch), 2)
}

/// Sum of `values` in four interleaved partial sums, which the compiler keeps in one vector
/// register (a single running sum would wait on every addition).
fn sum4(values: &[f64]) -> f64 {
    let mut partial = [0.0f64; 4];
    let chunks = values.chunks_exact(4);
    let tail: f64 = chunks.remainder().iter().sum();
    for chunk in chunks {
        for k in 0..4 {
            partial[k] += chunk[k];
        }
    }
    (partial[0] + partial[1]) + (partial[2] + partial[3]) + tail
}

/// Lag-1 autocorrelation of `z` about its mean (0 for a constant series): one pass for the
/// mean, one for the squares and the lagged products, each in four partial sums.
fn lag_one_autocorrelation(z: &[f64]) -> f64 {
    let n = z.len();
    let mean = sum4(z) / n as f64;
    let mut squares = [0.0f64; 4];
    let mut products = [0.0f64; 4];
    let (head, next) = (&z[..n - 1], &z[1..]);
    let pairs = head.chunks_exact(4).zip(next.chunks_exact(4));
    for (a, b) in pairs {
        for k in 0..4 {
            let centred = a[k] - mean;
            squares[k] += centred * centred;
            products[k] += centred * (b[k] - mean);
        }
    }
    let done = (n - 1) / 4 * 4;
    let mut square_tail = 0.0;
    let mut product_tail = 0.0;
    for i in done..n - 1 {
        let centred = z[i] - mean;
        square_tail += centred * centred;
        product_tail += centred * (z[i + 1] - mean);
    }
    let last = z[n - 1] - mean;
    square_tail += last * last;
    let denominator = (squares[0] + squares[1]) + (squares[2] + squares[3]) + square_tail;
    let numerator = (products[0] + products[1]) + (products[2] + products[3]) + product_tail;
    if denominator > 0.0 {
        numerator / denominator
    } else {
        0.0
    }
}

/// [`noise_type`] at each of `octaves` (powers of two, ascending; 0 where there are fewer than
/// 32 averages): `(octave, α)` in their order. The averages of each octave are the pairwise
/// means of the previous octave's (the same means as [`noise_type`]'s up to rounding), so the
/// whole pyramid costs one pass over the record and is kept one level at a time.
fn noise_types(rate: &[f64], octaves: &[usize]) -> Vec<(usize, i32)> {
    let mut scratch = Vec::new();
    let mut level: Vec<f64> = Vec::new();
    let mut m = 1usize;
    let mut types = Vec::with_capacity(octaves.len());
    for &octave in octaves {
        if !octave.is_power_of_two() || octave < m {
            types.push((octave, noise_type(rate, octave).unwrap_or(0)));
            continue;
        }
        while m < octave {
            if m == 1 {
                level = rate
                    .chunks_exact(2)
                    .map(|pair| (pair[0] + pair[1]) * 0.5)
                    .collect();
            } else {
                // In place: entry i reads entries 2i and 2i + 1, not yet overwritten.
                let halves = level.len() / 2;
                for i in 0..halves {
                    level[i] = (level[2 * i] + level[2 * i + 1]) * 0.5;
                }
                level.truncate(halves);
            }
            m *= 2;
        }
        let averages: &[f64] = if m == 1 { rate } else { &level };
        types.push((
            octave,
            type_of_averages(averages, &mut scratch).unwrap_or(0),
        ));
    }
    types
}

/// Equivalent degrees of freedom of the overlapping ADEV with `points` phase points at
/// averaging factor `m` for noise type `alpha` (NIST SP 1065 Table 5).
pub fn edf_overlapping(points: usize, m: usize, alpha: i32) -> f64 {
    let n = points as f64;
    let m = m as f64;
    let edf = match alpha {
        2 => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        1 => libm::exp(
            (libm::log((n - 1.0) / (2.0 * m)) * libm::log((2.0 * m + 1.0) * (n - 1.0) / 4.0))
                .sqrt(),
        ),
        0 => {
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n) * (4.0 * m * m)
                / (4.0 * m * m + 5.0)
        }
        -1 if m == 1.0 => 2.0 * (n - 2.0) / (2.3 * n - 4.9),
        -1 => 5.0 * n * n / (4.0 * m * (n + 3.0 * m)),
        _ => {
            (n - 2.0) / (m * (n - 3.0) * (n - 3.0))
                * ((n - 1.0) * (n - 1.0) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
        }
    };
    edf.max(1.0)
}

/// The `confidence` (e.g. 0.6827) interval `[lo, hi]` of a deviation `dev` with `edf`
/// degrees of freedom: `σ² edf / χ²(1 − p/2)` … `σ² edf / χ²(p/2)` (SP 1065 eq. 45).
pub fn confidence_interval(dev: f64, edf: f64, confidence: f64) -> (f64, f64) {
    let tail = (1.0 - confidence) / 2.0;
    let lo = dev * (edf / chi2_quantile(1.0 - tail, edf)).sqrt();
    let hi = dev * (edf / chi2_quantile(tail, edf)).sqrt();
    (lo, hi)
}

/// One point of an Allan curve.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Point {
    /// Averaging time, s.
    pub tau_s: f64,
    /// Averaging factor.
    pub m: usize,
    /// The deviation (units of the rate).
    pub dev: f64,
    /// Lower end of the 1σ confidence interval.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Equivalent degrees of freedom.
    pub edf: f64,
    /// Noise type used for the EDF (α; white FM when too few averages to tell).
    pub alpha: i32,
    /// Terms averaged.
    pub terms: usize,
}

/// The 1σ confidence level, erf(1/√2).
pub const ONE_SIGMA: f64 = 0.682_689_492_137_085_9;

/// Samples per block of the blocked overlapping-ADEV pass (256 KiB of phase: stays in L2).
const BLOCK: usize = 32 * 1024;

/// Overlapping ADEV at every factor of `factors` in one pass over the phase, block by block:
/// all factors are summed on a block while it is in cache, so the record is read from memory
/// about once rather than once per τ (only factors beyond a block stream from elsewhere).
fn overlapping_blocked(x: &[f64], factors: &[usize], rate_hz: f64) -> Vec<Option<(f64, usize)>> {
    let n = x.len();
    let mut sums = vec![0.0f64; factors.len()];
    let longest = factors
        .iter()
        .filter(|m| **m >= 1 && **m <= max_factor(Kind::Overlapping, n))
        .map(|m| n - 2 * m)
        .max()
        .unwrap_or(0);
    let mut start = 0;
    while start < longest {
        let end = (start + BLOCK).min(longest);
        for (sum, &m) in sums.iter_mut().zip(factors) {
            if m == 0 || m > max_factor(Kind::Overlapping, n) {
                continue;
            }
            let terms = n - 2 * m;
            if start >= terms {
                continue;
            }
            let stop = end.min(terms);
            *sum += sum_second_differences(
                &x[start..stop],
                &x[start + m..stop + m],
                &x[start + 2 * m..stop + 2 * m],
            );
        }
        start = end;
    }
    factors
        .iter()
        .zip(sums)
        .map(|(&m, sum)| {
            if m == 0 || m > max_factor(Kind::Overlapping, n) {
                return None;
            }
            let terms = n - 2 * m;
            let tau = m as f64 / rate_hz;
            let tau0 = 1.0 / rate_hz;
            Some((
                (sum * tau0 * tau0 / (2.0 * terms as f64 * tau * tau)).sqrt(),
                terms,
            ))
        })
        .collect()
}

/// The deviation `kind` at each factor of `factors` (see [`deviation`]): the overlapping ADEV
/// in one blocked pass, spread over two threads when there are many factors.
pub fn deviations(
    kind: Kind,
    x: &[f64],
    factors: &[usize],
    rate_hz: f64,
) -> Vec<Option<(f64, usize)>> {
    let compute = |ms: &[usize]| -> Vec<Option<(f64, usize)>> {
        match kind {
            Kind::Overlapping => overlapping_blocked(x, ms, rate_hz),
            _ => ms.iter().map(|m| deviation(kind, x, *m, rate_hz)).collect(),
        }
    };
    // Two threads once the passes outweigh a thread's start (a factor is a pass over x).
    if factors.len() < 2 || factors.len() * x.len() < 1 << 20 {
        return compute(factors);
    }
    // Interleaved halves balance the work (large m have fewer terms).
    let even: Vec<usize> = factors.iter().copied().step_by(2).collect();
    let odd: Vec<usize> = factors.iter().copied().skip(1).step_by(2).collect();
    std::thread::scope(|scope| {
        let odd = scope.spawn(|| compute(&odd));
        let even = compute(&even);
        let odd = odd.join().expect("deviations do not panic");
        let mut out = Vec::with_capacity(factors.len());
        for i in 0..factors.len() {
            out.push(if i % 2 == 0 { even[i / 2] } else { odd[i / 2] });
        }
        out
    })
}

impl Kind {
    /// The estimator's structure, for its degrees of freedom.
    pub fn estimator(self) -> edf::Estimator {
        edf::Estimator {
            d: if self == Kind::Hadamard { 3 } else { 2 },
            modified: self == Kind::Modified,
            overlapping: self != Kind::NonOverlapping,
        }
    }
}

/// The curve of `kind` over `grid` for a rate record at `rate_hz`, with 1σ confidence
/// intervals from the kind's own equivalent degrees of freedom ([`edf::edf`]). The noise type
/// is identified at each octave and used for the factors up to the next one.
pub fn curve(kind: Kind, rate: &[f64], rate_hz: f64, grid: Grid) -> Vec<Point> {
    curve_reporting(kind, rate, rate_hz, grid, &mut |_, _| {})
}

/// Factors per call of [`deviations`] in [`curve_reporting`]: a grid of more is computed in
/// chunks, each reported done.
const FACTORS_PER_CHUNK: usize = 256;

/// [`curve`], telling `progress(done, total)` of the factors as they are computed (every
/// factor of a long `Grid::All` is a pass over the record); the same points.
pub fn curve_reporting(
    kind: Kind,
    rate: &[f64],
    rate_hz: f64,
    grid: Grid,
    progress: &mut dyn FnMut(usize, usize),
) -> Vec<Point> {
    let x = phase(rate);
    let factors = factors(kind, grid, x.len());
    let octave_of = |m: usize| 1usize << (usize::BITS - 1 - m.leading_zeros());
    // The noise types need only the rate: found beside the deviations (an octave without a
    // deviation is typed but not used).
    let mut octaves: Vec<usize> = factors.iter().map(|m| octave_of(*m)).collect();
    octaves.dedup();
    let (values, alphas) = std::thread::scope(|scope| {
        let alphas = scope.spawn(|| noise_types(rate, &octaves));
        let mut values = Vec::with_capacity(factors.len());
        for chunk in factors.chunks(FACTORS_PER_CHUNK) {
            values.extend(deviations(kind, &x, chunk, rate_hz));
            progress(values.len(), factors.len());
        }
        (values, alphas.join().expect("noise typing does not panic"))
    });
    factors
        .iter()
        .zip(values)
        .filter_map(|(m, value)| {
            let (dev, terms) = value?;
            let octave = octave_of(*m);
            let alpha = alphas
                .iter()
                .find(|(o, _)| *o == octave)
                .map_or(0, |(_, a)| *a);
            let edf = edf::edf(kind.estimator(), alpha, *m, x.len()).unwrap_or(1.0);
            let (lo, hi) = confidence_interval(dev, edf, ONE_SIGMA);
            Some(Point {
                tau_s: *m as f64 / rate_hz,
                m: *m,
                dev,
                lo,
                hi,
                edf,
                alpha,
                terms,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests;
