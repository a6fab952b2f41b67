//! The integration tests: one binary, so it links once and the test harness spreads every test
//! over the cores. Each module is one subject; `cargo test --test main <module>::` runs one.

mod common;

mod analysis;
mod bad_input;
mod blocks;
mod docs;
mod dpi;
mod end_to_end;
mod explore;
mod filter_vectors;
mod formats;
mod fusesoc;
mod fuzz_parsers;
mod golden;
mod gyro_loop;
mod layers;
mod loop_blocks;
mod memory;
mod output_folder;
mod population;
mod random_configs;
mod recording;
mod roms;
mod rtl;
mod serial;
mod synth;
mod testbench_options;
