//! `gyrofx population`'s work: every member drawn and studied on `jobs` threads
//! ([`crate::pool::ordered`]), each row streamed into `population.csv` in member order as it
//! is done, the summary built from the rows' figures alone, then `summary.json`, the plots and
//! the manifest: the whole folder written all or nothing, as every package
//! ([`gyrofx_codegen::package::Staging`]). Memory is bounded whatever the members and seconds:
//! the rows wait for at most `2·jobs` members, the summary keeps a few numbers per member and
//! each member's study streams its run.

use std::io::Write;
use std::path::Path;

use gyrofx_codegen::output_folder::{Kind, Replace, MANIFEST};
use gyrofx_codegen::package::{FileEntry, Package, Staging};
use gyrofx_job::error::{Error, Result};
use gyrofx_job::population::summary::{Report, Summary};
use gyrofx_job::population::targets::Target;
use gyrofx_job::population::{columns, Population, RunSettings};

mod plots;

/// What to run and where to write it.
#[derive(Clone, Debug)]
pub struct Request<'a> {
    /// The output folder.
    pub out: &'a Path,
    /// Whether a folder gyrofx did not write may be replaced.
    pub replace: Replace,
    /// Members (gyro pairs).
    pub members: u64,
    /// Threads.
    pub jobs: usize,
    /// Each member's run.
    pub settings: RunSettings,
    /// The targets the yield is counted against.
    pub targets: Vec<Target>,
    /// The command line, as the manifest records it.
    pub command: String,
}

/// What a run gives.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The summary.
    pub report: Report,
    /// The files written.
    pub files: Vec<String>,
    /// Gyro-samples simulated.
    pub gyro_samples: u64,
}

/// Runs the study and writes the folder; `progress(n)` after each `n` members.
///
/// # Errors
/// An output folder that may not be replaced, a failure to write, or no font for the plots;
/// nothing is left behind.
pub fn run(
    population: &Population,
    request: &Request,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Outcome> {
    let staging = Staging::create(request.out, Kind::Population, request.replace)?;
    let csv_path = staging.path().join("population.csv");
    let file = std::fs::File::create(&csv_path).map_err(|e| Error::io(&csv_path, e))?;
    let mut csv = csv::Writer::from_writer(std::io::BufWriter::new(file));
    let io = |e: csv::Error| Error::io(&csv_path, std::io::Error::other(e.to_string()));
    csv.write_record(columns::header(population)).map_err(io)?;
    let mut summary = Summary::new(&request.targets);
    let mut gyro_samples = 0u64;
    crate::pool::ordered(
        request.members,
        request.jobs,
        |index| population.study(index, &request.settings),
        |_, result| {
            if gyrofx_codegen::output_folder::interrupted() {
                return Err(Error::io(
                    &csv_path,
                    std::io::Error::from(std::io::ErrorKind::Interrupted),
                ));
            }
            csv.write_record(columns::row(&result)).map_err(io)?;
            summary.add(&result);
            gyro_samples += result.figures.as_ref().map_or(0, |f| f.gyro_samples);
            progress(1);
            Ok(())
        },
    )?;
    let mut writer = csv
        .into_inner()
        .map_err(|e| Error::io(&csv_path, std::io::Error::other(e.to_string())))?;
    writer.flush().map_err(|e| Error::io(&csv_path, e))?;
    drop(writer);
    let report = summary.report(
        population.chain.estimator.schedule.interval_length,
        population.chain_rate_hz(),
    );
    let mut package = Package::new(Kind::Population, Vec::new());
    package.add_written(FileEntry {
        path: "population.csv".into(),
        sha256: gyrofx_job::hash::file_sha256(&csv_path)?,
        bytes: std::fs::metadata(&csv_path)
            .map_err(|e| Error::io(&csv_path, e))?
            .len() as usize,
    });
    let text = serde_json::to_string_pretty(&summary_json(population, request, &report))
        .expect("the summary serializes");
    package.add("summary.json", text + "\n");
    for (name, svg) in plots::render(&summary, &report)? {
        package.add(name, svg);
    }
    let mut files = package.paths();
    files.push(MANIFEST.into());
    let manifest = serde_json::json!({
        "tool": "gyrofx",
        "version": env!("CARGO_PKG_VERSION"),
        "command": request.command,
        "files": package.entries(),
    });
    package.add(
        MANIFEST,
        serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n",
    );
    package.write_staged(staging)?;
    Ok(Outcome {
        report,
        files,
        gyro_samples,
    })
}

/// `summary.json`: the run's settings and the [`Report`]. Nothing in it depends on the threads
/// or the clock.
fn summary_json(population: &Population, request: &Request, report: &Report) -> serde_json::Value {
    let spreads: Vec<String> = population
        .spreads
        .iter()
        .map(|(parameter, spread)| format!("{}: {spread:?}", parameter.name()))
        .collect();
    serde_json::json!({
        "tool": "gyrofx",
        "seed": population.seed,
        "members": request.members,
        "seconds": request.settings.seconds,
        "noise": request.settings.noise,
        "startup_s": gyrofx_job::population::STARTUP_S,
        "chain_rate_hz": population.chain_rate_hz(),
        "spreads": spreads,
        "report": report,
    })
}
