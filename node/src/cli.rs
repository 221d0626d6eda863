//! The command line: one subcommand per way of running the solver.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "flume-twin",
    version,
    about = "GPU SPH digital twin of a laboratory flume"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a case offline: progress bar, gauge time series, particle snapshots and a summary.
    Simulate(SimulateArgs),
    /// Throughput (particle-steps/s) and real-time factor on this machine's adapter.
    Bench(BenchArgs),
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Case file (YAML), e.g. launch_configs/dambreak_water.yaml.
    pub case: PathBuf,
    /// Simulated time to stop at, s [default: the case's time.end_s].
    #[arg(long, value_name = "T_S", allow_negative_numbers = true)]
    pub until: Option<f64>,
    /// Output directory for gauges.csv and the particle snapshots [default: out/<case name>].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Write a particle snapshot every N output intervals.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub snapshot_every: u64,
    /// Write no particle snapshots (gauges.csv only).
    #[arg(long, conflicts_with = "snapshot_every")]
    pub no_snapshots: bool,
    /// Discharge time series for an open flume's inlet: CSV rows `t_s,q_m3_per_s`, each
    /// discharge held until the next row's time.
    #[arg(long, value_name = "FILE")]
    pub inflow: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct BenchArgs {
    /// Particle counts (fluid) of the synthetic 2-D dam breaks to time.
    #[arg(
        long,
        value_name = "N1,N2,...",
        value_delimiter = ',',
        default_value = "4000,16000,64000,256000"
    )]
    pub ladder: Vec<u64>,
    /// Case timed against the DualSPHysics reference figure.
    #[arg(
        long,
        value_name = "PATH",
        default_value = "launch_configs/dsph_dambreak_val2d.yaml"
    )]
    pub case: PathBuf,
    /// Open flume timed at its own resolution (the scour model with the inlet running).
    #[arg(
        long,
        value_name = "PATH",
        default_value = "launch_configs/ulbra_flume.yaml"
    )]
    pub flume: PathBuf,
    /// Wall-clock seconds each measurement should last (approximately).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    pub steps_seconds: f64,
}
