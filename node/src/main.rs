//! flume-twin: the command-line front end of the flume digital twin.
//!
//! The node moves data between the world and the solver and knows nothing about SPH; every
//! subcommand lives in `commands/`, the twin's rules in `twin/`, the transports and files in
//! `adapters/`; `main` only dispatches.

mod adapters;
mod cli;
mod commands;
mod twin;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    keep_freed_memory();
    // ROS tools append `--ros-args ...`; it is ROS's grammar, not ours, so it goes around clap.
    let mut args: Vec<String> = std::env::args().collect();
    let ros_args = match args.iter().position(|a| a == "--ros-args") {
        Some(k) => args.split_off(k),
        None => Vec::new(),
    };
    let cli = cli::Cli::parse_from(args);
    // Warnings by default so a CI log shows solver trouble without drowning in detail.
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,rustdds=error"),
    )
    .init();
    let result = match cli.command {
        cli::Command::Simulate(args) => commands::simulate::run(&args),
        cli::Command::Bench(args) => commands::bench::run(&args),
        cli::Command::Run(args) => commands::run::run(&args, &ros_args),
        // `replay --publish` plays the recording on the wire instead of through the twin.
        cli::Command::Replay(args) if args.publish => commands::play::run(&args, &ros_args),
        cli::Command::Replay(args) => commands::replay::run(&args, &ros_args),
        cli::Command::MakeSession(args) => commands::make_session::run(&args),
        cli::Command::Sweep(args) => commands::sweep::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            report(&err);
            ExitCode::FAILURE
        }
    }
}

/// Keeps the memory the process frees for its own next allocations. The CPU backend builds a
/// step's sorted state, sides and sums afresh each step, some hundred kilobytes each; glibc
/// otherwise serves blocks that size with mmap, or hands the top of its heap back to the
/// system, and the next step faults every page in again (on the CI flume 10 % of the wall
/// time, all of the system time).
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets two of glibc's tuning values; it is called before any thread
    // starts.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 64 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 256 << 20);
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
