//! `gyrofx population`'s work: every member drawn and studied on `jobs` threads
//! ([`crate::pool::ordered`]), each row streamed into `population.csv` in member order as it
//! is done (each line [`columns::csv_line`], as the Python package writes it), the summary
//! built from the rows' figures alone, then `summary.json`, the plots and the manifest: the
//! whole folder written all or nothing, as every package
//! ([`gyrofx_codegen::package::Staging`]). Memory is bounded whatever the members and seconds:
//! the rows wait for at most `2·jobs` members, the summary keeps a few numbers per member and
//! each member's study streams its run.

use std::io::Write;
use std::path::Path;

use gyrofx_codegen::output_folder::{Kind, Replace, MANIFEST};
use gyrofx_codegen::package::{FileEntry, Package, Staging};
use gyrofx_job::error::{Error, Result};
use gyrofx_job::population::summary::{self, Report, Summary};
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
    let mut csv = std::io::BufWriter::new(file);
    let io = |e: std::io::Error| Error::io(&csv_path, e);
    csv.write_all(columns::csv_line(&columns::header(population)).as_bytes())
        .map_err(io)?;
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
            csv.write_all(columns::csv_line(&columns::row(&result)).as_bytes())
                .map_err(io)?;
            summary.add(&result);
            gyro_samples += result.figures.as_ref().map_or(0, |f| f.gyro_samples);
            progress(1);
            Ok(())
        },
    )?;
    csv.flush().map_err(|e| Error::io(&csv_path, e))?;
    drop(csv);
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
    package.add(
        "summary.json",
        summary::json_text(population, request.members, &request.settings, &report),
    );
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

#[cfg(test)]
mod tests {
    use gyrofx_job::population::columns::csv_line;

    /// The job's lines are the `csv` crate's (what `population.csv` was written with before the
    /// Python package needed the same bytes): quotes only where a cell needs them.
    #[test]
    fn csv_lines_are_the_csv_crates() {
        let records: [&[&str]; 5] = [
            &["0", "ok", "", "1.5", "-2e-7"],
            &[
                "3",
                "unlocked",
                "gyro a: beyond the PLL's pull range; gyro b: x, y",
            ],
            &["quote \"q\"", "line\nbreak", "cr\r", ""],
            &[""],
            &["a", ""],
        ];
        for record in records {
            let mut writer = csv::Writer::from_writer(Vec::new());
            writer.write_record(record).unwrap();
            let expected = String::from_utf8(writer.into_inner().unwrap()).unwrap();
            assert_eq!(csv_line(record), expected, "{record:?}");
        }
    }
}
