//! `gyrofx init`: the annotated default config, or a preset, on stdout.

use std::process::ExitCode;

use anyhow::Result;

use gyrofx_job::config::{preset, DEFAULT_TOML};

/// Print the annotated default config, or a preset (an overlay of it).
#[derive(clap::Args)]
pub struct Args {
    /// gu2019 (paper 004), xue2015 (paper 000) or mpu6050.
    #[arg(long)]
    preset: Option<String>,
}

/// Prints the config text as is, to be saved and edited.
pub fn run(args: Args) -> Result<ExitCode> {
    match args.preset {
        Some(name) => {
            super::options::check_preset(&name)?;
            print!("{}", preset(&name)?)
        }
        None => print!("{DEFAULT_TOML}"),
    }
    Ok(ExitCode::SUCCESS)
}
