use super::*;

/// The stationary covariance of the discrete model, `P = Φ P Φᵀ + L Lᵀ`, is the
/// continuous system's equilibrium, `k_B T K⁻¹` for `q` and `k_B T / m` for `q′`, with no
/// statistical error: a check of Van Loan's `Q_d` and of its scaling.
#[test]
fn discrete_noise_covariance_has_the_equilibrium_as_its_fixed_point() {
    let params = ResonatorParams {
        sense_frequency_hz: 6000.0,
        q_drive: 20.0,
        q_sense: 30.0,
        stiffness_angle_deg: 20.0,
        damping_angle_deg: -10.0,
        ..ResonatorParams::paper_004()
    };
    let mut settings = PhysicsSettings::example();
    settings.pickoff_noise_v_per_sqrt_hz = 0.0;
    settings.damping_split_drift = GaussMarkov::OFF;
    settings.damping_angle_drift = GaussMarkov::OFF;
    settings.phase_drift = GaussMarkov::OFF;
    let mut r = Resonator::new(&params, &settings, 1).unwrap();
    r.set_rate(0.3);
    let l = r.noise_factor;
    let mut q = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            q[i][j] = (0..4).map(|k| l[i][k] * l[j][k]).sum();
        }
    }
    let phi = r.transition;
    let mut p = [[0.0; 4]; 4];
    for _ in 0..20_000 {
        let phi_p = super::super::expm::multiply(&phi, &p);
        let mut next = q;
        for i in 0..4 {
            for j in 0..4 {
                next[i][j] += (0..4).map(|k| phi_p[i][k] * phi[j][k]).sum::<f64>();
            }
        }
        p = next;
    }
    let kt = BOLTZMANN_J_PER_K * settings.temperature_k;
    let k = params.matrices().k;
    let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    let w0 = r.velocity_scale;
    let scaled_velocity = kt / params.mass_kg / (w0 * w0);
    let want = [
        [kt * k[1][1] / det, -kt * k[0][1] / det, 0.0, 0.0],
        [-kt * k[0][1] / det, kt * k[0][0] / det, 0.0, 0.0],
        [0.0, 0.0, scaled_velocity, 0.0],
        [0.0, 0.0, 0.0, scaled_velocity],
    ];
    let scale = want[0][0].max(want[1][1]);
    for i in 0..4 {
        for j in 0..4 {
            assert!(
                (p[i][j] - want[i][j]).abs() < 1e-9 * scale,
                "P[{i}][{j}] = {} vs {}",
                p[i][j],
                want[i][j]
            );
        }
    }
}
