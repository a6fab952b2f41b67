//! gyrofx: the command line. Parsing and dispatch here, one module per command in `commands/`,
//! the work in gyrofx-model and gyrofx-codegen.

mod commands;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::{
    allan, ar, davar, denoise, design, explore, filter, formats, generate, gyro_loop, init,
    population, reproduce, synth, verify,
};

#[derive(Parser)]
#[command(
    name = "gyrofx",
    version,
    about = "Bit-accurate fixed-point model, vector and testbench generator for a MEMS-gyro FPGA signal chain",
    // Help wraps at 100 columns on any terminal, as the reference page has it.
    term_width = 100,
    max_term_width = 100
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The commands in the order `--help` lists them; each one's help text is its `Args`' doc.
#[derive(Subcommand)]
enum Command {
    Allan(allan::Args),
    Ar(ar::Args),
    Davar(davar::Args),
    Denoise(denoise::Args),
    Init(init::Args),
    Design(design::Args),
    Formats(formats::Args),
    Explore(explore::Args),
    Generate(generate::Args),
    Synth(synth::Args),
    Loop(gyro_loop::Args),
    Population(population::Args),
    Verify(verify::Args),
    Filter(filter::Args),
    Reproduce(reproduce::Args),
}

fn main() -> ExitCode {
    // Ctrl-C or SIGTERM: end the programs gyrofx started (they would go on writing into the
    // folders removed next), remove the staging folders, temporary and lock files, then end as
    // a shell expects of an interrupted program (128 + SIGINT).
    let _ = ctrlc::set_handler(|| {
        gyrofx_lab::processes::end_all();
        gyrofx_codegen::output_folder::remove_registered();
        std::process::exit(130);
    });
    quiet_on_closed_stdout();
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Allan(args) => allan::run(args),
        Command::Ar(args) => ar::run(args),
        Command::Davar(args) => davar::run(args),
        Command::Denoise(args) => denoise::run(args),
        Command::Init(args) => init::run(args),
        Command::Design(args) => design::run(args),
        Command::Formats(args) => formats::run(args),
        Command::Explore(args) => explore::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Synth(args) => synth::run(args),
        Command::Loop(args) => gyro_loop::run(args),
        Command::Population(args) => population::run(args),
        Command::Verify(args) => verify::run(args),
        Command::Filter(args) => filter::run(args),
        Command::Reproduce(args) => reproduce::run(args),
    };
    if gyrofx_lab::processes::ending() || gyrofx_codegen::output_folder::interrupted() {
        // A child the handler ended made the command fail: the handler is still removing
        // files, and it ends the process with 130 when done.
        loop {
            std::thread::park();
        }
    }
    match outcome {
        Ok(code) => code,
        Err(e) => {
            // One line: a cause whose text the message already carries is not repeated.
            let mut message = e.to_string();
            for cause in e.chain().skip(1) {
                let cause = cause.to_string();
                if !message.contains(&cause) {
                    message = format!("{message}: {cause}");
                }
            }
            eprintln!("error: {message}");
            if e.downcast_ref::<commands::Usage>().is_some() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// A reader that closes stdout early (`gyrofx init | head -1`) ends the program quietly with
/// exit 0, as ripgrep does, instead of the panic `println!` raises on the broken pipe. Every
/// command prints with `println!`, so this is caught where that panic starts: the hook
/// recognises std's message for a failed stdout write with the pipe's OS error (EPIPE) and
/// leaves every other panic to the default hook.
fn quiet_on_closed_stdout() {
    let broken_pipe = std::io::Error::from_raw_os_error(32).to_string();
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if cfg!(unix)
            && message.starts_with("failed printing to stdout")
            && message.ends_with(&broken_pipe)
        {
            std::process::exit(0);
        }
        default(info);
    }));
}
