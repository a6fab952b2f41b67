//! The block registry: every RTL block of the package, one module each, named after it.
//!
//! A block's module owns everything the generator, the writers, `verify` and `synth` need to
//! know about it: its ports with their formats and its parameters ([`RtlBlock::block`]), the
//! ROMs it owns ([`RtlBlock::roms`]), how its vectors are cut from the chain run
//! ([`RtlBlock::vectors`], a [`VectorBuilder`] of the run's interface) and its section of the
//! manifest ([`RtlBlock::manifest`]). Everything
//! downstream iterates over [`REGISTRY`]; nothing else matches on block names.
//!
//! Adding a block: a model module in `gyrofx-model`, a module here implementing [`RtlBlock`],
//! the RTL pair in `hdl/` (listed in [`crate::hdl::RTL_SOURCES`] and
//! [`crate::hdl::VHDL_SOURCES`], which keep VHDL's compile order), a page in `docs/blocks/`
//! and one line in [`REGISTRY`].

pub mod calibration;
pub mod cic;
pub mod demodulator;
pub mod estimator;
pub mod gyro_loop;
pub mod kf;
pub mod mean_filter;
pub mod nco;
pub mod pi;
pub mod sequencer;
pub mod system;
pub mod top;

#[cfg(test)]
mod tests;

use gyrofx_model::fx::{Format, Overflow, Rounding};
use gyrofx_model::gyro_loop::RtlParameter;
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::SplitMix64;

use crate::block::{Block, Param};
use crate::rom::{self, Rom, RomFormat};
use crate::text::Provenance;
use crate::vector_rows::StagedRows;
use crate::vectors::{Run, VectorBuilder};
use gyrofx_job::job::Job;

/// One RTL block.
pub trait RtlBlock: Sync {
    /// Folder, file prefix and doc page name, e.g. `kf`.
    fn name(&self) -> &'static str;

    /// The RTL module, e.g. `gyrofx_kf`.
    fn module(&self) -> &'static str;

    /// What the block is, one line.
    fn title(&self) -> &'static str;

    /// Whether `job`'s package has the block (every block's but the system's, which needs
    /// the resonator plant).
    fn in_package(&self, _job: &Job) -> bool {
        true
    }

    /// What the block's RTL needs of `job` beyond what [`Job::new`] validates (the system's:
    /// both loops share every parameter `gyrofx_system` gives them once).
    ///
    /// # Errors
    /// [`gyrofx_job::error::Error::Config`] naming the field.
    fn check(&self, _job: &Job) -> gyrofx_job::error::Result<()> {
        Ok(())
    }

    /// The ROMs the block owns (the package writes each in every format under `roms/`).
    fn roms(&self, _job: &Job) -> Vec<Rom> {
        Vec::new()
    }

    /// The block for `job` without vectors: its ports (after `clk`, `rst`, `ce`) with their
    /// formats, its parameters and the ROM images its DUT reads.
    fn block(&self, job: &Job, roms: &RomImages) -> Block;

    /// Whether the block has vectors and a testbench of its own ([`RtlBlock::vectors`] gives
    /// a builder): not so for a block tested inside its parent.
    fn has_vectors(&self) -> bool {
        true
    }

    /// The builder of its vectors from the chain run, or `None` for a block that has no
    /// testbench of its own (its vectors are its parent's).
    fn vectors<'a>(&self, job: &'a Job, block: Block) -> Option<Box<dyn VectorBuilder + 'a>>;

    /// Whether `synth --place-route` places and routes it, and under which name its serial
    /// variant goes beside it.
    fn placement(&self) -> Placement {
        Placement::Alone
    }

    /// Its section of the package manifest (key and value), if it has one.
    fn manifest(
        &self,
        _job: &Job,
        _roms: &RomImages,
        _run: &Run,
    ) -> Option<(&'static str, serde_json::Value)> {
        None
    }
}

/// How `synth --place-route` places and routes a block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Not placed.
    No,
    /// Placed as the job builds it.
    Alone,
    /// Placed as the job builds it, and beside it, under this name, as the job's serial
    /// variant builds it (whatever the job's architecture, so that one run measures both).
    WithSerial(&'static str),
    /// Only its serial variant is placed, under this name, as the job's serial variant builds
    /// it (the system: the parallel one fits no target).
    SerialOnly(&'static str),
}

/// The names `synth` places and routes under, in registry order: each placed block, its
/// serial variant after it.
pub fn placed_names() -> Vec<&'static str> {
    REGISTRY
        .iter()
        .flat_map(|b| match b.placement() {
            Placement::No => vec![],
            Placement::Alone => vec![b.name()],
            Placement::WithSerial(serial) => vec![b.name(), serial],
            Placement::SerialOnly(serial) => vec![serial],
        })
        .collect()
}

/// The block placed under `name` ([`placed_names`]), and whether that name is its serial
/// variant.
pub fn placed(name: &str) -> Option<(&'static dyn RtlBlock, bool)> {
    REGISTRY.iter().find_map(|b| match b.placement() {
        Placement::Alone if b.name() == name => Some((*b, false)),
        Placement::WithSerial(serial) if b.name() == name || serial == name => {
            Some((*b, serial == name))
        }
        Placement::SerialOnly(serial) if serial == name => Some((*b, true)),
        _ => None,
    })
}

/// Every block, in the order of the package (the chain's signal flow, then the blocks beside
/// it).
pub static REGISTRY: &[&dyn RtlBlock] = &[
    &sequencer::Sequencer,
    &estimator::Estimator,
    &calibration::Calibration,
    &kf::Kf,
    &top::Top,
    &mean_filter::MeanFilter,
    &nco::Nco,
    &demodulator::Demodulator,
    &pi::Pi,
    &cic::Cic,
    &gyro_loop::GyroLoop,
    &system::System,
];

/// The blocks of `job`'s package, in registry order.
pub fn of(job: &Job) -> impl Iterator<Item = &'static dyn RtlBlock> + '_ {
    REGISTRY.iter().copied().filter(|b| b.in_package(job))
}

/// [`Job::new`], then the check of every block in its package ([`RtlBlock::check`]): the job
/// every command that builds RTL, vectors or netlists starts from.
///
/// # Errors
/// The first config, design or plan error, then the first block's refusal.
pub fn checked_job(config: gyrofx_job::config::Config) -> gyrofx_job::error::Result<Job> {
    let job = Job::new(config)?;
    for block in of(&job) {
        block.check(&job)?;
    }
    Ok(job)
}

/// The registered block called `name`.
///
/// # Panics
/// When no block has that name (a programming error: names are static).
pub fn find(name: &str) -> &'static dyn RtlBlock {
    *REGISTRY
        .iter()
        .find(|b| b.name() == name)
        .unwrap_or_else(|| panic!("no block `{name}` in the registry"))
}

/// Where the chain run's vector builders write their blocks' files
/// ([`vector_builders`]).
#[derive(Clone, Copy, Debug)]
pub struct Streaming<'a> {
    /// The staging folder.
    pub root: &'a std::path::Path,
    /// Whether the CSV twins are written.
    pub csv: bool,
    /// Only these blocks' files (all when `None`); the others' rows are only counted.
    pub blocks: Option<&'a [String]>,
    /// The generated-by line's source.
    pub provenance: &'a Provenance,
}

/// The vector builders of every block of `job`'s package that has vectors, in registry
/// order, for [`crate::vectors::run`]. Without `streaming` each keeps its rows in memory;
/// with it, each writes its rows as they come into its files under `streaming.root`
/// ([`StagedRows`]), so that memory does not grow with the samples.
///
/// # Errors
/// A vector file that cannot be created.
pub fn vector_builders<'a>(
    job: &'a Job,
    roms: &RomImages,
    streaming: Option<Streaming>,
) -> gyrofx_job::error::Result<Vec<Box<dyn VectorBuilder + 'a>>> {
    let mut builders = Vec::new();
    for registered in of(job).filter(|b| b.has_vectors()) {
        let mut block = registered.block(job, roms);
        if let Some(streaming) = &streaming {
            let wanted = streaming
                .blocks
                .is_none_or(|names| names.iter().any(|n| n == block.name));
            let sink = if wanted {
                StagedRows::open(&block, streaming.root, streaming.csv, streaming.provenance)?
            } else {
                StagedRows::discard(&block)
            };
            block.stream_to(Box::new(sink));
        }
        builders.extend(registered.vectors(job, block));
    }
    Ok(builders)
}

/// A ROM's `$readmemh` image: the file a DUT reads.
#[derive(Clone, Debug)]
pub struct RomImage {
    /// The ROM.
    pub rom: Rom,
    /// File name of its `.mem` image.
    pub file: String,
    /// The image's text.
    pub text: String,
}

/// The `.mem` images of every registered block's ROMs.
#[derive(Clone, Debug)]
pub struct RomImages(Vec<RomImage>);

impl RomImages {
    /// The images of every ROM of the registry for `job`, in registry order.
    pub fn new(job: &Job, provenance: &Provenance) -> Self {
        RomImages(
            of(job)
                .flat_map(|b| b.roms(job))
                .map(|rom| RomImage {
                    file: RomFormat::Mem.file_name(&rom.name),
                    text: rom::write(&rom, RomFormat::Mem, provenance),
                    rom,
                })
                .collect(),
        )
    }

    /// The image of the ROM called `name` (e.g. `kf_coefficients`).
    ///
    /// # Panics
    /// When no registered block owns it (a programming error).
    pub fn get(&self, name: &str) -> &RomImage {
        self.0
            .iter()
            .find(|image| image.rom.name == name)
            .unwrap_or_else(|| panic!("no block owns the ROM `{name}`"))
    }

    /// The image's file name and text, as a block carries it.
    pub fn entry(&self, name: &str) -> (String, String) {
        let image = self.get(name);
        (image.file.clone(), image.text.clone())
    }

    /// Every image, in registry order.
    pub fn iter(&self) -> impl Iterator<Item = &RomImage> {
        self.0.iter()
    }
}

/// The `ROUNDING` and `SATURATE` parameters every quantizing block takes.
pub fn mode_params(rounding: Rounding, overflow: Overflow) -> [Param; 2] {
    [
        Param::integer("ROUNDING", rounding.rtl_code().into(), rounding.name()),
        Param::integer("SATURATE", overflow.rtl_code().into(), overflow.name()),
    ]
}

/// A parameter holding a signed code of `width` bits (a Verilog `[width-1:0]` literal, a
/// VHDL bit string), e.g. a PI's gain.
pub(crate) fn signed(name: &str, width: u32, code: i128, comment: impl Into<String>) -> Param {
    let mask = if width >= 128 {
        u128::MAX
    } else {
        (1u128 << width) - 1
    };
    Param::bits(name, width, (code as u128) & mask, comment)
}

/// The parameters of one of the gyro loop's leaf modules from its plan's `rtl_parameters`
/// (in the RTL's order, each under its own name): `KP`, `KI`, `INT_MIN` and `INT_MAX` as codes
/// of the widths `KP_W`, `KI_W` and `INT_W` the list also gives, `ROUNDING` and `SATURATE`
/// from `modes`, every other an integer; then `ROM_FILE` when the module reads a ROM image.
pub(crate) fn leaf_params(
    all: &[RtlParameter],
    modes: Option<(Rounding, Overflow)>,
    rom_file: Option<&str>,
    what: &str,
) -> Vec<Param> {
    let width_of = |name: &str| {
        all.iter()
            .find(|(n, _)| *n == name)
            .map(|(_, w)| *w as u32)
            .unwrap_or_else(|| panic!("{what}: no {name} among the RTL parameters"))
    };
    // `X_W` and `X_F` describe one format: both say it.
    let format_of = |prefix: &str| {
        let fraction = all.iter().find(|(n, _)| *n == format!("{prefix}_F"))?.1;
        Some(format!("s{}.{fraction}", width_of(&format!("{prefix}_W"))))
    };
    let mut params: Vec<Param> = all
        .iter()
        .filter(|(name, _)| !matches!(*name, "ROUNDING" | "SATURATE"))
        .map(|&(name, value)| {
            let coded = match name {
                "KP" | "KI" => Some(name),
                "INT_MIN" | "INT_MAX" => Some("INT"),
                _ => None,
            };
            let pair = name
                .strip_suffix("_W")
                .or_else(|| name.strip_suffix("_F"))
                .and_then(|prefix| Some((prefix, format_of(prefix)?)));
            match (coded, pair) {
                (Some(prefix), _) => {
                    let format: Format = format_of(prefix)
                        .and_then(|f| f.parse().ok())
                        .unwrap_or_else(|| panic!("{what}: {prefix} has no format"));
                    let comment = format!("{what}: {name} = {:e} ({format})", format.to_f64(value));
                    signed(name, format.width, value, comment)
                }
                (None, Some((prefix, format))) => {
                    Param::integer(name, value as i64, format!("{what}: {prefix} {format}"))
                }
                (None, None) => Param::integer(name, value as i64, format!("{what}: {name}")),
            }
        })
        .collect();
    if let Some((rounding, overflow)) = modes {
        params.extend(mode_params(rounding, overflow));
    }
    if let Some(file) = rom_file {
        params.push(Param::string("ROM_FILE", file, format!("{what} ROM image")));
    }
    params
}

/// A deterministic stream of pseudo-random words: the model's SplitMix64 (`rand_xoshiro`),
/// the same codes on every platform for one seed.
pub(crate) struct Words(SplitMix64);

impl Words {
    /// The stream of `seed`.
    pub(crate) fn new(seed: u64) -> Self {
        Words(SplitMix64::seed_from_u64(seed))
    }

    /// The next word.
    pub(crate) fn next(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// A code of `format` (up to 64 bits wide), uniform over its range.
    pub(crate) fn code(&mut self, format: Format) -> i128 {
        format.from_bits(u128::from(self.next()))
    }
}

/// The vector builder of a block that drives its own stimulus (the gyro loop's leaf modules):
/// the chain's samples are not used; `fill` pushes every row when the run ends.
pub(crate) struct OwnStimulus<'a> {
    block: Block,
    fill: Box<dyn FnOnce(&mut Block) + 'a>,
}

impl<'a> OwnStimulus<'a> {
    /// `block`'s builder, whose rows `fill` pushes.
    pub(crate) fn boxed(
        block: Block,
        fill: impl FnOnce(&mut Block) + 'a,
    ) -> Box<dyn VectorBuilder + 'a> {
        Box::new(OwnStimulus {
            block,
            fill: Box::new(fill),
        })
    }
}

impl VectorBuilder for OwnStimulus<'_> {
    fn reset(&mut self) {}

    fn sample(&mut self, _sample: &crate::vectors::ChainSample) {}

    fn finish(self: Box<Self>, _results: &mut crate::vectors::BlockResults) -> Block {
        let OwnStimulus { mut block, fill } = *self;
        fill(&mut block);
        block
    }
}

/// A flag's code.
pub(crate) fn flag(b: bool) -> i128 {
    i128::from(b)
}

/// A mode's code: 1 normal, 0 reverse.
pub(crate) fn mode_bit(p: i8) -> i128 {
    i128::from(p > 0)
}
