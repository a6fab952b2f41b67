//! The random sources of one simulated resonator, each on its own seeded stream: the
//! Gauss–Markov drifts and the white sources, and the Cholesky factor that turns white
//! Gaussians into the thermomechanical noise of the discrete model.

use super::expm::Matrix;
use super::settings::GaussMarkov;
use crate::stimulus::{FastStream, Gaussian, ResonatorSource, Stream};

/// One drifting quantity: its process and its own random stream.
#[derive(Clone, Debug)]
pub(super) struct Drift {
    /// Current value (unit of the quantity).
    pub(super) value: f64,
    /// Per-update decay `e^{−N T / τ}` and innovation `std · sqrt(1 − decay²)`.
    pub(super) decay: f64,
    pub(super) innovation: f64,
    pub(super) source: Gaussian<FastStream>,
}

impl Drift {
    /// Stationary from the start; `None` when the process is off.
    pub(super) fn new(
        process: GaussMarkov,
        update_period_s: f64,
        seed: u64,
        source: ResonatorSource,
    ) -> Option<Self> {
        if process.std == 0.0 {
            return None;
        }
        let mut source = Gaussian::on(seed, Stream::Resonator(source));
        let decay = libm::exp(-update_period_s / process.correlation_time_s);
        Some(Drift {
            value: process.std * source.sample(),
            decay,
            innovation: process.std * (1.0 - decay * decay).sqrt(),
            source,
        })
    }

    pub(super) fn advance(&mut self) {
        self.value = self.decay * self.value + self.innovation * self.source.sample();
    }
}

/// The random sources of one resonator (all `None` with the noise switch off).
#[derive(Clone, Debug)]
pub(super) struct Sources {
    /// Thermomechanical force (four standard normals per sample, mixed by the Cholesky
    /// factor of the discrete process-noise covariance).
    pub(super) thermomechanical: Option<Gaussian<FastStream>>,
    /// Electronic noise of the x and y pick-offs, and its per-sample σ (V).
    pub(super) pickoff: Option<([Gaussian<FastStream>; 2], f64)>,
    /// Damping-split drift (fraction of the mean damping).
    pub(super) damping_split: Option<Drift>,
    /// Damping-angle drift (rad).
    pub(super) damping_angle: Option<Drift>,
    /// Phase drift (rad).
    pub(super) phase: Option<Drift>,
}

/// Lower Cholesky factor of a symmetric positive semidefinite 4×4 matrix (its symmetric part
/// is used; a pivot that rounding makes negative is taken as 0).
pub(super) fn cholesky(q: &Matrix<4>) -> Matrix<4> {
    let mut l = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..=i {
            let mut sum = (q[i][j] + q[j][i]) / 2.0;
            for (li, lj) in l[i][..j].iter().zip(&l[j][..j]) {
                sum -= li * lj;
            }
            if i == j {
                l[i][i] = sum.max(0.0).sqrt();
            } else if l[j][j] > 0.0 {
                l[i][j] = sum / l[j][j];
            }
        }
    }
    l
}
