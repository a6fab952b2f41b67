//! A population study as plain data, for `gyrofx.population` (python/gyrofx/_population.py):
//! what `gyrofx population` writes, computed by the job's own functions, with nothing but
//! strings, integers and floats going in and coming out, so that a batch of members can be
//! studied in another process or on another machine (a `dask.distributed` worker) and the
//! results put together here give the CLI's `population.csv` and `summary.json` byte for byte.
//!
//! Every function takes the run's definition again (the config's text and where it came from,
//! the preset, the seed, the seconds and the noise) instead of an object: a member is a pure
//! function of it and its index ([`Population::study`]).

use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::PyDict;

use gyrofx_job::config::{self, Config};
use gyrofx_job::population::summary::{self, Summary};
use gyrofx_job::population::targets::{Record, Target};
use gyrofx_job::population::{columns, Population, RunSettings, MAX_SECONDS, STARTUP_S};

use crate::refused;

/// What a population is resolved from: the config's text, its origin, the preset, the seed.
type Definition = (Option<String>, String, Option<String>, Option<u64>);

/// The populations resolved last in this process, newest last: resolving one (the job's plans,
/// its proven formats) takes about as long as studying a member, and a worker is given the same
/// definition with every batch. A cache, not a state: a population is a function of its
/// definition.
static RESOLVED: Mutex<Vec<(Definition, Arc<Population>)>> = Mutex::new(Vec::new());

/// Populations [`RESOLVED`] keeps.
const RESOLVED_KEPT: usize = 4;

/// The population of the embedded default overlaid by `preset` and then by the TOML text
/// `config` (`origin` names it in errors, as the CLI names a `--config` file by its path), its
/// seed replaced by `seed`.
fn resolve(
    config: Option<&str>,
    origin: &str,
    preset: Option<&str>,
    seed: Option<u64>,
) -> Result<Arc<Population>, gyrofx_job::error::Error> {
    let key: Definition = (
        config.map(str::to_string),
        origin.to_string(),
        preset.map(str::to_string),
        seed,
    );
    let cached = |cache: &Vec<(Definition, Arc<Population>)>| {
        cache
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, p)| Arc::clone(p))
    };
    if let Some(population) = cached(&RESOLVED.lock().unwrap_or_else(|e| e.into_inner())) {
        return Ok(population);
    }
    let mut overlays: Vec<(String, String)> = Vec::new();
    if let Some(name) = preset {
        overlays.push((config::preset(name)?.to_string(), format!("preset {name}")));
    }
    if let Some(text) = config {
        overlays.push((text.to_string(), origin.to_string()));
    }
    let refs: Vec<(&str, &str)> = overlays
        .iter()
        .map(|(t, o)| (t.as_str(), o.as_str()))
        .collect();
    let mut config = Config::from_overlays(&refs)?;
    if let Some(seed) = seed {
        config.seed = seed;
    }
    let population = Arc::new(Population::new(&config)?);
    let mut cache = RESOLVED.lock().unwrap_or_else(|e| e.into_inner());
    if cached(&cache).is_none() {
        if cache.len() == RESOLVED_KEPT {
            cache.remove(0);
        }
        cache.push((key, Arc::clone(&population)));
    }
    Ok(population)
}

/// `seconds` and `noise` checked as `--seconds` is.
fn settings(seconds: f64, noise: bool) -> PyResult<RunSettings> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_SECONDS) {
        return Err(refused(format!(
            "seconds {seconds} is not allowed: a number of seconds in (0, {MAX_SECONDS}]"
        )));
    }
    Ok(RunSettings { seconds, noise })
}

fn targets(texts: &[String]) -> PyResult<Vec<Target>> {
    texts.iter().map(|t| t.parse().map_err(refused)).collect()
}

/// The run checked and described: `seed` (resolved), `columns` and `header` (the CSV's first
/// line), `chain_rate_hz`, `startup_s` and `spreads` (one line each). Raises `GyrofxError`
/// for a bad config (the CLI's message), preset, seconds or target.
#[pyfunction]
#[pyo3(signature = (config, origin, preset, seed, seconds, noise, targets))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _population_describe<'py>(
    py: Python<'py>,
    config: Option<&str>,
    origin: &str,
    preset: Option<&str>,
    seed: Option<u64>,
    seconds: f64,
    noise: bool,
    targets: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    settings(seconds, noise)?;
    self::targets(&targets)?;
    let population = py
        .detach(|| resolve(config, origin, preset, seed))
        .map_err(refused)?;
    let header = columns::header(&population);
    let dict = PyDict::new(py);
    dict.set_item("seed", population.seed)?;
    dict.set_item("header", columns::csv_line(&header))?;
    dict.set_item("columns", header)?;
    dict.set_item("chain_rate_hz", population.chain_rate_hz())?;
    dict.set_item("startup_s", STARTUP_S)?;
    dict.set_item("spreads", summary::spreads(&population))?;
    Ok(dict)
}

/// One member as `_population_members` returns it: its index, its line of `population.csv`,
/// its status and its figures (the summary's record).
type MemberRow = (u64, String, &'static str, Vec<Option<f64>>);

/// Members `first .. first + count` drawn and studied, in order, without the GIL: per member
/// `(index, csv_line, status, figures)`.
#[pyfunction]
#[pyo3(signature = (config, origin, preset, seed, first, count, seconds, noise))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _population_members(
    py: Python<'_>,
    config: Option<&str>,
    origin: &str,
    preset: Option<&str>,
    seed: Option<u64>,
    first: u64,
    count: u64,
    seconds: f64,
    noise: bool,
) -> PyResult<Vec<MemberRow>> {
    let settings = settings(seconds, noise)?;
    let last = first
        .checked_add(count)
        .ok_or_else(|| refused(format!("members {first} + {count} overflow")))?;
    py.detach(|| -> Result<Vec<MemberRow>, gyrofx_job::error::Error> {
        let population = resolve(config, origin, preset, seed)?;
        Ok((first..last)
            .map(|index| {
                let result = population.study(index, &settings);
                let record = Record::of(&result);
                (
                    index,
                    columns::csv_line(&columns::row(&result)),
                    record.status,
                    record.figures.to_vec(),
                )
            })
            .collect())
    })
    .map_err(refused)
}

/// `summary.json`'s text from every member's `(status, figures)` in member order, as the CLI
/// writes it.
#[pyfunction]
#[pyo3(signature = (config, origin, preset, seed, seconds, noise, targets, records))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn _population_summary(
    py: Python<'_>,
    config: Option<&str>,
    origin: &str,
    preset: Option<&str>,
    seed: Option<u64>,
    seconds: f64,
    noise: bool,
    targets: Vec<String>,
    records: Vec<(String, Vec<Option<f64>>)>,
) -> PyResult<String> {
    let settings = settings(seconds, noise)?;
    let targets = self::targets(&targets)?;
    let population = py
        .detach(|| resolve(config, origin, preset, seed))
        .map_err(refused)?;
    let mut sum = Summary::new(&targets);
    for (status, figures) in &records {
        sum.add_record(&Record::new(status, figures).map_err(refused)?);
    }
    let report = sum.report(
        population.chain.estimator.schedule.interval_length,
        population.chain_rate_hz(),
    );
    Ok(summary::json_text(
        &population,
        records.len() as u64,
        &settings,
        &report,
    ))
}
