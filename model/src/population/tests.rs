use super::distribution::{Distribution, Spread};
use super::draw::{member, GyroPhysics, Parameter};
use crate::resonator::{PhysicsSettings, ResonatorParams};

fn nominal() -> [GyroPhysics; 2] {
    let gyro = GyroPhysics {
        params: ResonatorParams::paper_004(),
        front_end: PhysicsSettings::example(),
        seed: 0,
    };
    [gyro, gyro]
}

fn normal(std: f64, relative: bool) -> Spread {
    Spread {
        distribution: Distribution::Normal { mean: None, std },
        relative,
    }
}

/// The same seed and member give the same physics; another member or seed other physics;
/// a member's draws do not depend on which members were drawn before it.
#[test]
fn draws_are_a_function_of_seed_and_member_only() {
    let spreads = [
        (Parameter::QDrive, normal(0.1, true)),
        (Parameter::StiffnessAngleDeg, normal(0.2, false)),
    ];
    let a = member(&nominal(), &spreads, 7, 3);
    let _ = member(&nominal(), &spreads, 7, 2);
    assert_eq!(member(&nominal(), &spreads, 7, 3), a);
    assert_ne!(member(&nominal(), &spreads, 7, 4).drawn, a.drawn);
    assert_ne!(member(&nominal(), &spreads, 8, 3).drawn, a.drawn);
    assert_eq!(a.drawn.len(), 4);
    assert_eq!(a.gyros[0].params.q_drive, a.drawn[0]);
    assert_eq!(a.gyros[1].params.stiffness_angle_deg, a.drawn[3]);
    assert_ne!(a.gyros[0].seed, a.gyros[1].seed);
    // Adding a spread keeps the noise seeds.
    let more = member(&nominal(), &spreads[..1], 7, 3);
    assert_eq!(more.gyros.map(|g| g.seed), a.gyros.map(|g| g.seed));
}

/// 2 000 normal draws: mean and standard deviation within 4 standard errors; uniform draws
/// within their range with the right mean; list draws only take listed values, each about as
/// often.
#[test]
fn distributions_have_their_statistics() {
    let n = 2000;
    let draws = |spread: &Spread, nominal: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let m = member(
                    &nominal_with_q(nominal),
                    &[(Parameter::QDrive, spread.clone())],
                    11,
                    i,
                );
                m.drawn[0]
            })
            .collect()
    };
    let stats = |v: &[f64]| {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        (mean, var.sqrt())
    };
    let (mean, std) = stats(&draws(&normal(0.05, true), 200.0));
    let se = 10.0 / (n as f64).sqrt();
    assert!((mean - 200.0).abs() < 4.0 * se, "{mean}");
    assert!(
        (std - 10.0).abs() < 4.0 * 10.0 / (2.0 * n as f64).sqrt(),
        "{std}"
    );
    let uniform = Spread {
        distribution: Distribution::Uniform {
            low: 100.0,
            high: 300.0,
        },
        relative: false,
    };
    let v = draws(&uniform, 184.0);
    assert!(v.iter().all(|x| (100.0..300.0).contains(x)));
    let (mean, std) = stats(&v);
    assert!(
        (mean - 200.0).abs() < 4.0 * 57.7 / (n as f64).sqrt(),
        "{mean}"
    );
    assert!((std - 57.7).abs() < 4.0, "{std}");
    let values = Spread {
        distribution: Distribution::Values(vec![-0.1, 0.0, 0.1]),
        relative: true,
    };
    let v = draws(&values, 200.0);
    for x in [180.0, 200.0, 220.0] {
        let count = v.iter().filter(|y| (**y - x).abs() < 1e-9).count();
        assert!((560..=780).contains(&count), "{x}: {count}");
    }
}

fn nominal_with_q(q: f64) -> [GyroPhysics; 2] {
    let mut n = nominal();
    for g in &mut n {
        g.params.q_drive = q;
    }
    n
}

#[test]
fn parameters_are_named_as_the_config_names_them() {
    use super::draw::Section;
    assert_eq!(
        Parameter::named(Section::Resonator, "q_drive"),
        Some(Parameter::QDrive)
    );
    assert_eq!(Parameter::named(Section::FrontEnd, "q_drive"), None);
    assert_eq!(
        Parameter::named(Section::FrontEnd, "pickoff_gain_y_v_per_m"),
        Some(Parameter::PickoffGainYVPerM)
    );
    assert_eq!(
        Parameter::names(Section::Resonator).len() + Parameter::names(Section::FrontEnd).len(),
        Parameter::ALL.len()
    );
}
