//! flume-twin: the command-line front end of the flume digital twin.
//!
//! The node moves data between the world and the solver and knows nothing about SPH; every
//! subcommand lives in `commands/`, the twin's rules in `twin/`, the transports and files in
//! `adapters/`; `main` only dispatches.

mod adapters;
// Its doc comments are the `--help` text clap prints verbatim: a `<case name>` there is a
// placeholder for the reader, not HTML.
#[allow(rustdoc::invalid_html_tags)]
mod cli;
mod commands;
#[cfg(test)]
mod test_support;
mod twin;

use clap::Parser;
use std::os::unix::fs::DirBuilderExt;
use std::process::ExitCode;

fn main() -> ExitCode {
    keep_freed_memory();
    give_mesa_a_runtime_dir();
    // ROS tools append `--ros-args ...`; it is ROS's grammar, not ours, so it goes around clap.
    let mut args: Vec<String> = std::env::args().collect();
    let ros_args = match args.iter().position(|a| a == "--ros-args") {
        Some(k) => args.split_off(k),
        None => Vec::new(),
    };
    let cli = cli::Cli::parse_from(args);
    // Warnings by default so a CI log shows solver trouble without drowning in detail; from
    // ros2-client, only the warnings that ask something of the user (see `QUIET`).
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(QUIET)).init();
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

/// The default log filter. RustDDS warns about every peer it cannot reach on some interface.
/// ros2-client warns when `ROS_DISTRO` is unset (no ROS install: nothing to match, and a
/// distribution that differs is still an error), and for every service request that carries
/// its id in the sample rather than in inline QoS (ros2-client's own clients do; the id it
/// falls back to is the right one for them, and the node answers rmw_cyclonedds's clients
/// through their own mapping).
const QUIET: &str =
    "warn,rustdds=error,ros2_client::distributions=error,ros2_client::service::wrappers=error";

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

/// Mesa's Vulkan device-select layer, loaded whenever the adapters are listed (even when the
/// CPU backend is chosen), prints an error when `XDG_RUNTIME_DIR` is unset or not a directory,
/// as it is under a service manager or `sudo`; it only looks for a display there. A private
/// directory of our own quiets it.
fn give_mesa_a_runtime_dir() {
    let usable =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if usable {
        return;
    }
    // SAFETY: getuid cannot fail.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir().join(format!("flume-twin-runtime-{uid}"));
    let made = std::fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(&dir);
    if made.is_ok() {
        // SAFETY: no other thread runs yet; nothing reads the environment concurrently.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
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
