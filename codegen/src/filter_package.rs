//! The KF's verification package for a filtered record (`gyrofx filter --vectors DIR`): the KF
//! block's vectors of exactly the samples `filter` ran (a reset, then one row per sample at
//! `bw_sel` 0), with the RTL, its Verilog, VHDL, cocotb and DPI-C testbenches, the coefficient
//! ROM, a Makefile and a manifest that records the recording's SHA-256 and the config, so that
//! `gyrofx.Plan.from_package` rebuilds the same KF.
//!
//! The rows stream into the staging folder as the filter runs (memory does not grow with the
//! record); the folder is replaced only at [`FilterPackage::finish`], and a package dropped
//! before it leaves nothing behind.

use std::path::Path;

use serde_json::json;

use crate::block::Block;
use crate::blocks::{kf, RomImages, RtlBlock};
use crate::generate::{block_files, block_manifest, BlockFile};
use crate::hdl;
use crate::output_folder::{Kind, Replace};
use crate::package::{Package, Staging};
use crate::text::Provenance;
use crate::vector_rows::StagedRows;
use crate::writers;
use gyrofx_job::error::Result;
use gyrofx_job::job::Job;

/// A KF package being written.
pub struct FilterPackage {
    staging: Staging,
    block: Block,
    samples: u64,
}

impl FilterPackage {
    /// Checks `out` (an empty folder, a filter package gyrofx wrote, or anything with
    /// [`Replace::Force`]) and opens the KF's vector files in a staging folder beside it, with
    /// the reset row.
    ///
    /// # Errors
    /// A folder gyrofx does not own, or one that cannot be written.
    pub fn create(
        out: &Path,
        job: &Job,
        provenance: &Provenance,
        replace: Replace,
    ) -> Result<FilterPackage> {
        let staging = Staging::create(out, Kind::Filter, replace)?;
        let roms = RomImages::new(job, provenance);
        let mut block = kf::Kf.block(job, &roms);
        let sink = StagedRows::open(&block, staging.path(), true, provenance)?;
        block.stream_to(Box::new(sink));
        block.push(true, &[0, 0], &[0, 0]);
        Ok(FilterPackage {
            staging,
            block,
            samples: 0,
        })
    }

    /// One filtered sample: the KF's input code `z` and its `rate_out`, at `bw_sel` 0.
    pub fn push(&mut self, z: i64, rate_out: i64) {
        self.block
            .push(false, &[0, i128::from(z)], &[1, i128::from(rate_out)]);
        self.samples += 1;
    }

    /// Writes the other files and the manifest (with `recording`: where the record came from)
    /// and moves the package into place. Returns its files.
    ///
    /// # Errors
    /// Write errors, or a folder that changed since [`FilterPackage::create`].
    pub fn finish(
        mut self,
        job: &Job,
        provenance: &Provenance,
        recording: serde_json::Value,
    ) -> Result<Vec<String>> {
        self.block.finish_rows()?;
        let blocks = [self.block];
        let block = &blocks[0];
        let mut package = Package::new(Kind::Filter, writers::build_outputs(&blocks));
        package.add("Makefile", writers::makefile(&blocks, provenance));
        package.add("README.md", readme(block, self.samples, provenance));
        for (name, source) in hdl::RTL_SOURCES.iter().chain(&hdl::VHDL_SOURCES) {
            package.add(format!("hdl/{name}"), *source);
        }
        for file in block_files(block, provenance) {
            match file {
                BlockFile::Text(path, text) => package.add(path, text),
                BlockFile::Written(entry) => package.add_written(entry),
            }
        }
        for (path, text) in crate::cocotb::files(&blocks, provenance)
            .into_iter()
            .chain(crate::dpi::files(&blocks, provenance))
        {
            package.add(path, text);
        }
        let mut manifest = json!({
            "tool": "gyrofx",
            "version": provenance.version,
            "command": provenance.command,
            "config_sha256": provenance.config_sha256,
            "config": job.config,
            "recording": recording,
            "samples": self.samples,
            "encoding": "vector files: one line per clock-enable; fields separated by one space, each a zero-padded two's-complement hex word of its format's width; line 1 is a generated-by comment, line 2 names the fields and formats",
            "blocks": {"kf": block_manifest(block)},
        });
        manifest
            .as_object_mut()
            .expect("an object")
            .insert("files".to_string(), json!(package.entries()));
        let mut text = serde_json::to_string_pretty(&manifest).expect("manifest serializes");
        text.push('\n');
        package.add(crate::output_folder::MANIFEST, text);
        let files = package.paths();
        package.write_staged(self.staging)?;
        Ok(files)
    }
}

fn readme(block: &Block, samples: u64, provenance: &Provenance) -> String {
    format!(
        "<!-- {line} -->
# gyrofx KF package of a filtered record

The KF block's vectors for the {samples} samples `gyrofx filter` ran (after one reset, all at
`bw_sel` 0): `kf/` holds `{stimulus}`, `{expected}`, the CSV twin, the parameters, the ROM and
the testbenches; `hdl/` the RTL. `manifest.json` records the recording's SHA-256 and the
config. Run the testbench without gyrofx:

    make iverilog-kf | verilator-kf | ghdl-kf
    make cocotb-kf                              # cocotb + the gyrofx Python package
    make dpi-kf GYROFX_CAPI_LIB=<path>/libgyrofx_capi.a

Each prints `PASS n=<N>` or the first mismatches and `FAIL ...`.
",
        line = provenance.line("").trim_start(),
        stimulus = block.file("stimulus.hex"),
        expected = block.file("expected.hex"),
    )
}
