//! [`FloatKf`]: the f64 golden model of the KF, with the same structure as the fixed one.

/// `x ← x + g (z − x1 − x2)`, `rate_hat = x1`, in f64 (°/s), one gain set per `bw_sel`.
///
/// Built from the quantized gains it checks the fixed model's arithmetic (see
/// [`super::bound`]); built from the designed gains it shows what coefficient quantization
/// costs.
#[derive(Clone, Debug)]
pub struct FloatKf {
    gains: Vec<[f64; 2]>,
    x: [f64; 2],
}

impl FloatKf {
    /// A model with these gain sets, in the reset state.
    pub fn new(gains: Vec<[f64; 2]>) -> Self {
        FloatKf {
            gains,
            x: [0.0, 0.0],
        }
    }

    /// Clears the state.
    pub fn reset(&mut self) {
        self.x = [0.0, 0.0];
    }

    /// One sample `z` (°/s) at `bw_sel`; returns `rate_hat` (°/s).
    ///
    /// # Panics
    /// When `bw_sel` addresses no gain set.
    #[inline]
    pub fn step(&mut self, z: f64, bw_sel: usize) -> f64 {
        let [g1, g2] = self.gains[bw_sel];
        let e = z - self.x[0] - self.x[1];
        self.x[0] += g1 * e;
        self.x[1] += g2 * e;
        self.x[0]
    }

    /// The state `[rate, bias]`, °/s.
    pub fn state(&self) -> [f64; 2] {
        self.x
    }
}
