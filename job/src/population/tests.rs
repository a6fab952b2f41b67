use super::targets::Target;
use super::*;

/// A short schedule (windows of 0.4 s) so that a second of chain run has calibrated output.
pub(crate) const SHORT: &str = "[sequencer]\ninterval_length = 40\nintervals = 2\nblank = 30\n";

fn population(extra: &str) -> Population {
    Population::new(&Config::from_toml(&format!("{SHORT}{extra}"), "t").unwrap()).unwrap()
}

/// Without spreads every member is the nominal pair: both gyros lock, the characterization's
/// residual is the closed form's within 1 mdps, the chain's output at rest is the residual
/// within a few mdps, and nothing saturates.
#[test]
fn the_nominal_member_locks_and_meets_its_closed_forms() {
    let p = population("");
    let settings = RunSettings {
        seconds: 1.0,
        noise: false,
    };
    let result = p.study(0, &settings);
    let f = result.figures.as_ref().unwrap();
    assert_eq!(columns::status(&result), "ok");
    for g in &f.gyros {
        assert!(g.lock.locked, "{:?}", g.lock);
        assert!(g.lock.lock_ms.unwrap() < 300.0, "{:?}", g.lock);
        let r = g.characterization.residual_bias_dps;
        assert!((r.measured - r.predicted).abs() < 1e-3, "{r:?}");
        assert_eq!(g.saturations_used, 0);
    }
    let mean = f.chain.output_mean_dps.unwrap();
    let residual = f.gyros[0].characterization.residual_bias_dps.measured;
    assert!((mean - residual).abs() < 5e-3, "{mean} vs {residual}");
    assert!(f.chain.output_samples >= 15, "{}", f.chain.output_samples);
    assert_eq!(f.chain.arw_deg_per_sqrt_h, None);
    assert!(f.gyro_samples > p.chain_run_gyro_samples(&settings));
    // The same member again: the same figures, bit for bit.
    assert_eq!(p.study(0, &settings), result);
    let target: Target = "residual_dps<=0.02".parse().unwrap();
    assert!(target.met_by_member(&result));
    let row = columns::row(&result);
    assert_eq!(row.len(), columns::header(&p).len());
}

/// A drive frequency far off the loop's nominal one does not lock, and says why; a drawn
/// parameter the physics refuses makes the member invalid, with the field named.
#[test]
fn members_that_cannot_lock_or_run_say_why() {
    let p = population(
        "[population.resonator]\ndrive_frequency_hz = { distribution = \"values\", values = [8600.0] }\n",
    );
    let settings = RunSettings {
        seconds: 0.1,
        noise: false,
    };
    let result = p.study(0, &settings);
    assert_eq!(columns::status(&result), "unlocked");
    let row = columns::row(&result);
    assert!(row[2].contains("beyond the PLL's pull range"), "{}", row[2]);
    let p = population(
        "[population.resonator]\nq_drive = { distribution = \"values\", values = [-1.0] }\n",
    );
    let result = p.study(3, &settings);
    assert_eq!(columns::status(&result), "invalid");
    assert!(result.figures.unwrap_err().contains("q_drive = -1"));
}
