//! A deterministic matrix exponential for small fixed-size matrices.
//!
//! Scaling and squaring around a degree-18 Taylor polynomial: `A` is halved `s` times until
//! its 1-norm is at most 1/2 (halving is exact in binary floating point), `e^{A/2^s}` is the
//! Taylor polynomial evaluated by Horner's rule, and the result is squared `s` times. With
//! `‖A/2^s‖₁ ≤ 1/2` the truncation error is below `0.5¹⁹/19! ≈ 2e-23` relative, far under an
//! ulp. Only `+`, `×` and `/` are used, in a fixed order, so the result is bit-identical on
//! every IEEE-754 platform (unlike `nalgebra`'s `exp`, whose Padé order and scaling come from
//! the platform's `log2` and `powf`).
//!
//! Callers scale their states so that the matrix is well balanced (entries of similar size):
//! the number of squarings follows the norm, and every squaring costs accuracy.

/// A square matrix, row-major.
pub type Matrix<const N: usize> = [[f64; N]; N];

/// Taylor degree; with `‖X‖₁ ≤ 1/2` the next term is below 2e-23.
const TAYLOR_DEGREE: u32 = 18;

/// The identity.
pub fn identity<const N: usize>() -> Matrix<N> {
    let mut m = [[0.0; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// `a · b`, summing in index order.
pub fn multiply<const N: usize>(a: &Matrix<N>, b: &Matrix<N>) -> Matrix<N> {
    let mut c = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            let mut sum = 0.0;
            for k in 0..N {
                sum += a[i][k] * b[k][j];
            }
            c[i][j] = sum;
        }
    }
    c
}

/// The 1-norm (largest column sum of magnitudes).
pub fn one_norm<const N: usize>(a: &Matrix<N>) -> f64 {
    (0..N)
        .map(|j| (0..N).map(|i| a[i][j].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// `e^A`.
///
/// # Panics
/// When an entry of `a` is not finite.
pub fn expm<const N: usize>(a: &Matrix<N>) -> Matrix<N> {
    assert!(
        a.iter().flatten().all(|v| v.is_finite()),
        "the matrix exponential needs finite entries"
    );
    let mut squarings = 0;
    let mut scale = 1.0;
    let norm = one_norm(a);
    while norm * scale > 0.5 {
        scale *= 0.5;
        squarings += 1;
    }
    let mut x = *a;
    for v in x.iter_mut().flatten() {
        *v *= scale;
    }
    // Horner: e^X ≈ I + X (I + X/2 (I + X/3 (… (I + X/n)))).
    let mut e = identity::<N>();
    for k in (1..=TAYLOR_DEGREE).rev() {
        let mut next = multiply(&x, &e);
        let inverse_k = 1.0 / f64::from(k);
        for (i, row) in next.iter_mut().enumerate() {
            for v in row.iter_mut() {
                *v *= inverse_k;
            }
            row[i] += 1.0;
        }
        e = next;
    }
    for _ in 0..squarings {
        e = multiply(&e, &e);
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_close<const N: usize>(got: &Matrix<N>, want: &Matrix<N>, tolerance: f64) {
        for i in 0..N {
            for j in 0..N {
                assert!(
                    (got[i][j] - want[i][j]).abs() <= tolerance,
                    "({i},{j}): {} vs {}",
                    got[i][j],
                    want[i][j]
                );
            }
        }
    }

    #[test]
    fn rotation_generator_gives_a_rotation() {
        // e^{[[0, −a], [a, 0]]} = [[cos a, −sin a], [sin a, cos a]], also for a far beyond the
        // Taylor range (many squarings).
        for a in [0.1, 1.0, 3.0, 25.0] {
            let e = expm(&[[0.0, -a], [a, 0.0]]);
            let (c, s) = (libm::cos(a), libm::sin(a));
            assert_close(&e, &[[c, -s], [s, c]], 1e-13 * a.max(1.0));
        }
    }

    #[test]
    fn damped_oscillator_matches_its_analytic_solution() {
        // x'' + 2ζw x' + w² x = 0 with the state [x, x'/w]: A = w [[0, 1], [−1, −2ζ]].
        // For ζ < 1: e^{At} = e^{−ζwt} [[c + ζ/β s, s/β], [−s/β, c − ζ/β s]] with
        // β = sqrt(1 − ζ²), c = cos(βwt), s = sin(βwt).
        let (w, zeta, t): (f64, f64, f64) = (2.0, 0.05, 0.7);
        let a = [[0.0, w * t], [-w * t, -2.0 * zeta * w * t]];
        let beta = (1.0 - zeta * zeta).sqrt();
        let (c, s) = (libm::cos(beta * w * t), libm::sin(beta * w * t));
        let decay = libm::exp(-zeta * w * t);
        let want = [
            [decay * (c + zeta / beta * s), decay * s / beta],
            [-decay * s / beta, decay * (c - zeta / beta * s)],
        ];
        assert_close(&expm(&a), &want, 1e-15);
    }

    #[test]
    fn diagonal_nilpotent_and_inverse() {
        let d = expm(&[[1.0, 0.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 0.0]]);
        let want = [
            [libm::exp(1.0), 0.0, 0.0],
            [0.0, libm::exp(-2.0), 0.0],
            [0.0, 0.0, 1.0],
        ];
        // Two squarings (‖A‖₁ = 2): a few ulp.
        assert_close(&d, &want, 3e-15);
        // Nilpotent: e^N = I + N + N²/2 exactly.
        let n = expm(&[[0.0, 2.0, 3.0], [0.0, 0.0, 4.0], [0.0, 0.0, 0.0]]);
        assert_close(
            &n,
            &[[1.0, 2.0, 3.0 + 4.0], [0.0, 1.0, 4.0], [0.0, 0.0, 1.0]],
            1e-14,
        );
        // e^A e^{−A} = I for a dense, non-normal matrix.
        let a = [
            [0.3, -1.2, 0.5, 0.1],
            [0.7, -0.2, 0.0, 2.0],
            [-0.4, 0.9, -0.6, 0.3],
            [1.1, 0.0, 0.2, -0.8],
        ];
        let mut minus = a;
        for v in minus.iter_mut().flatten() {
            *v = -*v;
        }
        assert_close(&multiply(&expm(&a), &expm(&minus)), &identity(), 1e-14);
    }
}
