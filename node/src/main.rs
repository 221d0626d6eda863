//! flume-twin: the command-line front end of the flume digital twin.
//!
//! The node moves data between the world and the solver and knows nothing about SPH; every
//! subcommand lives in its own module and `main` only dispatches.

mod bench;
mod cli;
mod inflow;
mod output;
mod simulate;
mod table;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    // Warnings by default so a CI log shows solver trouble without drowning in detail.
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let result = match cli.command {
        cli::Command::Simulate(args) => simulate::run(&args),
        cli::Command::Bench(args) => bench::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            report(&err);
            ExitCode::FAILURE
        }
    }
}

/// Prints an error and its causes one per line: a long `a: b: c` line is hard to read in a log.
fn report(err: &anyhow::Error) {
    eprintln!("error: {err}");
    let mut previous = err.to_string();
    for cause in err.chain().skip(1) {
        let text = cause.to_string();
        // Some errors repeat their source's text in their own message; say it once.
        if !previous.contains(&text) {
            eprintln!("  caused by: {text}");
        }
        previous = text;
    }
}
