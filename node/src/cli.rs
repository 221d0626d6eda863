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
    /// The twin as a ROS 2 node: sensor topics in, bed profile, eroded mass, gauge comparison,
    /// /clock and /diagnostics out. ROS arguments follow `--ros-args`, as ros2 run passes them.
    Run(RunArgs),
    /// Feed a recorded session's sensor topics to the twin in-process (no DDS), as fast as
    /// the adapter goes or paced, and record the twin's outputs.
    Replay(ReplayArgs),
    /// Write a synthetic flume session (the inflow and gauge topics) as an MCAP recording:
    /// a simple hydraulic model of the case's flume plus a stated sensor noise model.
    MakeSession(MakeSessionArgs),
    /// Run a case once per value of one field (a roughness ladder, say) and report the eroded
    /// sediment mass each run ends with: a table, sweep.csv and a bar chart, sweep.png.
    Sweep(SweepArgs),
}

#[derive(Debug, Args)]
pub struct RunArgs {
    /// Case file (YAML) with an open flume, e.g. launch_configs/ulbra_flume.yaml.
    pub case: PathBuf,
    /// Override a field of the case, e.g. `--set numerics.dp_m=0.01` (repeatable; a number
    /// in the key indexes a list: `phases.1.sediment.ks_over_d50=7`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Real-time factor to run at when no sensor drives the twin (simulated s per wall s).
    #[arg(long = "target-rtf", value_name = "X", default_value_t = 1.0, value_parser = positive)]
    pub target_rtf: f64,
    /// Most often the outputs are published, per wall second (the solver may report faster).
    #[arg(long, value_name = "HZ", default_value_t = 2.0, value_parser = positive)]
    pub publish_rate_hz: f64,
    /// Most often the particle cloud is published, per wall second.
    #[arg(long, value_name = "HZ", default_value_t = 1.0, value_parser = positive)]
    pub cloud_rate_hz: f64,
    /// Most particles in a published cloud (every k-th particle is sent).
    #[arg(long, value_name = "N", default_value_t = 20000)]
    pub cloud_max_points: usize,
    /// A sensor silent for this long is stale; the twin then runs on the clock, s.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = positive)]
    pub stale_after_s: f64,
    /// Largest stretch of simulated time the solver runs between looks at the inputs, s.
    #[arg(long, value_name = "S", default_value_t = 0.1, value_parser = positive)]
    pub max_chunk_s: f64,
    /// How far ahead of this machine's clock a sensor stamp may be (clock skew), s.
    #[arg(long, value_name = "S", default_value_t = 0.5, value_parser = positive)]
    pub future_tolerance_s: f64,
    /// Hold at t = 0 until the first sensor sample: simulated time 0 is then the flume's start.
    #[arg(long)]
    pub wait_for_sensors: bool,
    /// What the gauges publish: a level (flume_msgs/WaterLevel), or an ultrasonic range down to
    /// the water (sensor_msgs/Range; level = the parameter gauge_mount_height_m.<gauge>, by
    /// default the flume's height, minus the range).
    #[arg(long, value_enum, default_value_t = GaugeMsg::WaterLevel)]
    pub gauge_msg: GaugeMsg,
    /// DDS domain (as ROS_DOMAIN_ID).
    #[arg(long, env = "ROS_DOMAIN_ID", default_value_t = 0)]
    pub domain_id: u16,
    /// Keep DDS on the loopback interface (tests, a single machine).
    #[arg(long)]
    pub loopback: bool,
    /// Also write gauges.csv, bed_profile.csv and eroded_mass.csv here, a row per chunk, and
    /// at the end gauges.png (the published levels, predicted against measured) and
    /// eroded_mass.png.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Stop once simulated time reaches this, s (scripted runs and tests).
    #[arg(long, value_name = "T_S", value_parser = positive)]
    pub until: Option<f64>,
    /// Record every input and output topic to this rosbag2 bag directory (metadata.yaml and
    /// BAG_0.mcap), or to this file alone if it ends in .mcap.
    #[arg(long, value_name = "BAG")]
    pub record: Option<PathBuf>,
    /// With no sensor heard in --silent-wait-s, this recording's inflow and gauge topics play
    /// the sensors (the path is relative to the working directory, the repository's root).
    #[arg(
        long,
        value_name = "FILE",
        default_value = "tests/data/ulbra_session.mcap"
    )]
    pub replay_when_silent: Option<PathBuf>,
    /// Never play a recording in the sensors' place: with no sensors, run on the clock.
    #[arg(long)]
    pub no_replay: bool,
    /// How long to wait for a sensor before the recording plays, s.
    #[arg(long, value_name = "S", default_value_t = 3.0, value_parser = positive)]
    pub silent_wait_s: f64,
    /// The iceoryx2 service on which every particle goes to visualisers (shared memory).
    #[arg(long, value_name = "NAME", default_value = crate::adapters::frames::SERVICE)]
    pub frames_service: String,
    /// Most particle frames per wall second.
    #[arg(long, value_name = "HZ", default_value_t = 10.0, value_parser = positive)]
    pub frames_rate_hz: f64,
    /// Offer no particle frames.
    #[arg(long)]
    pub no_frames: bool,
    /// Serve the live view to Foxglove (its WebSocket protocol) on this port: every topic
    /// with its ros2msg schema, the particles included (0: a free port, printed).
    #[arg(long, value_name = "PORT")]
    pub foxglove: Option<u16>,
}

impl RunArgs {
    /// The pace the command line sets, before any parameter.
    pub fn pace(&self) -> crate::twin::settings::Pace {
        crate::twin::settings::Pace {
            target_rtf: self.target_rtf,
            publish_rate_hz: self.publish_rate_hz,
            stale_after_s: self.stale_after_s,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum GaugeMsg {
    WaterLevel,
    Range,
}

/// A parser of numbers from `lo` to `hi`, both included.
fn within(lo: f64, hi: f64) -> impl Fn(&str) -> Result<f64, String> + Clone + Send + Sync {
    move |s| match s.parse::<f64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        Ok(v) => Err(format!("must be from {lo} to {hi}, got {v}")),
        Err(e) => Err(e.to_string()),
    }
}

fn positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("must be a positive number, got {v}")),
        Err(e) => Err(e.to_string()),
    }
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Case file (YAML), e.g. launch_configs/dambreak_water.yaml.
    pub case: PathBuf,
    /// Override a field of the case, e.g. `--set numerics.dp_m=0.01` (repeatable; a number
    /// in the key indexes a list: `phases.1.sediment.ks_over_d50=7`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
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
pub struct SweepArgs {
    /// Case file (YAML) with an open flume, e.g. launch_configs/ulbra_flume.yaml.
    pub case: PathBuf,
    /// The field to vary and its values, one run each in this order, e.g.
    /// `phases.1.sediment.ks_over_d50=1,2,3,5,7,10` (the key as for --set).
    #[arg(long = "set-values", value_name = "KEY=V1,V2,...")]
    pub set_values: String,
    /// Override a field of every run's case, e.g. `--set numerics.dp_m=0.01` (repeatable; a
    /// number in the key indexes a list).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Simulated time each run stops at, where the eroded mass is read, s [default: the
    /// case's time.end_s].
    #[arg(long, value_name = "T_S", allow_negative_numbers = true, value_parser = positive)]
    pub until: Option<f64>,
    /// Output directory for sweep.csv and sweep.png [default: out/<case name>_sweep].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The recording (a bag directory or an MCAP file) whose inflow and gauge topics drive
    /// the twin.
    pub recording: PathBuf,
    /// Case file (YAML) with an open flume, e.g. launch_configs/ulbra_flume.yaml.
    #[arg(
        long,
        value_name = "CASE",
        required_unless_present = "publish",
        conflicts_with = "publish"
    )]
    pub config: Option<PathBuf>,
    /// Override a field of the case, e.g. `--set numerics.dp_m=0.01` (repeatable; a number
    /// in the key indexes a list: `phases.1.sediment.ks_over_d50=7`).
    #[arg(long = "set", value_name = "KEY=VALUE", conflicts_with = "publish")]
    pub set: Vec<String>,
    /// Write the replayed inputs and the twin's outputs to this recording (a bag directory,
    /// or a file if it ends in .mcap).
    #[arg(long, value_name = "BAG", conflicts_with = "publish")]
    pub out: Option<PathBuf>,
    /// Also write gauges.csv, bed_profile.csv and eroded_mass.csv here, a row per chunk, and
    /// at the end gauges.png (predicted against measured levels) and eroded_mass.png.
    #[arg(long, value_name = "DIR", conflicts_with = "publish")]
    pub csv: Option<PathBuf>,
    /// Pace the replay at this many recorded seconds per wall second, 0.001 to 1000 [default:
    /// as fast as the adapter goes; 1 with --publish].
    #[arg(long, value_name = "X", value_parser = within(1e-3, 1e3))]
    pub rate: Option<f64>,
    /// Play the sensor topics on the wire (ROS 2 over DDS) with /clock on the recording's
    /// time, as `ros2 bag play --clock` does, instead of feeding a twin in-process; a twin
    /// run with `--ros-args -p use_sim_time:=true` follows that clock. Topics keep their
    /// recorded names; `--ros-args -r FROM:=TO` renames them.
    #[arg(long)]
    pub publish: bool,
    // The player's options conflict with --config, which only an in-process replay takes:
    // `requires = "publish"` never fires, as clap counts a flag's default (false) as given.
    /// /clock messages per wall second, 0.1 to 1000 (with --publish); /clock also goes out
    /// just before each sample.
    #[arg(long, value_name = "HZ", default_value_t = 40.0, value_parser = within(0.1, 1e3), conflicts_with = "config")]
    pub clock_hz: f64,
    /// With --publish, /clock holds at the start this long before the first sample goes
    /// out, so that subscribers have matched, s (at most an hour).
    #[arg(long, value_name = "S", default_value_t = 1.0, value_parser = within(0.0, 3600.0), conflicts_with = "config")]
    pub delay_s: f64,
    /// DDS domain (with --publish).
    #[arg(long, default_value_t = 0, conflicts_with = "config")]
    pub domain_id: u16,
    /// With --publish, DDS on the loopback interface only.
    #[arg(long, conflicts_with = "config")]
    pub loopback: bool,
    /// Replay only these recorded topics (comma-separated) [default: every inflow and gauge
    /// topic of the case; with --publish, every inflow and gauge topic].
    #[arg(long, value_name = "T1,T2,...", value_delimiter = ',')]
    pub topics: Vec<String>,
    /// Start this far into the recording, s. In-process, the discharge in force then holds
    /// from the start; with --publish, as `ros2 bag play --start-offset`, nothing before it
    /// goes out (the twin keeps its discharge until the next inflow sample).
    #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = within(0.0, 1e9))]
    pub start_s: f64,
    /// Stop at this simulated time, s, counted from the start (with --publish, recorded
    /// seconds after the start) [default: the last replayed sample].
    #[arg(long, value_name = "T_S", value_parser = positive)]
    pub until: Option<f64>,
    /// The solver's chunk: outputs are written at multiples of it, s.
    #[arg(long, value_name = "S", default_value_t = 0.1, value_parser = positive, conflicts_with = "publish")]
    pub output_interval_s: f64,
    /// A gauge whose last sample is older than this at an output is flagged stale, s.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = positive, conflicts_with = "publish")]
    pub stale_after_s: f64,
    /// How far ahead of its logging time a sample's stamp may be, s.
    #[arg(long, value_name = "S", default_value_t = 0.5, value_parser = positive, conflicts_with = "publish")]
    pub future_tolerance_s: f64,
}

#[derive(Debug, Args)]
pub struct MakeSessionArgs {
    /// Case file (YAML) with an open flume.
    pub case: PathBuf,
    /// Override a field of the case, e.g. `--set numerics.dp_m=0.01` (repeatable; a number
    /// in the key indexes a list: `phases.1.sediment.ks_over_d50=7`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// The recording to write (a bag directory, or a file if it ends in .mcap).
    #[arg(long, value_name = "BAG")]
    pub out: PathBuf,
    /// Length of the session, s.
    #[arg(long, value_name = "S", default_value_t = 75.0, value_parser = positive)]
    pub duration_s: f64,
    /// When the discharge changes, s (on a filled flume).
    #[arg(long, value_name = "S", default_value = "40", value_parser = positive)]
    pub change_at_s: Option<f64>,
    /// The discharge from then on, m3/h.
    #[arg(long, value_name = "Q", default_value = "2.5", value_parser = positive)]
    pub change_to_m3_per_h: Option<f64>,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 2018)]
    pub seed: u64,
    /// The session's start, s since the epoch [default: 2026-11-21 09:00 UTC].
    #[arg(long, value_name = "S", default_value_t = 1_795_251_600.0, value_parser = positive)]
    pub start_epoch_s: f64,
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
    /// Time the particle frames over iceoryx2 instead (at the --flume case's particle count:
    /// frames and bytes per second, and latency).
    #[arg(long, conflicts_with_all = ["ladder", "case"])]
    pub frames: bool,
    /// Wall-clock seconds each measurement should last (approximately).
    #[arg(
        long,
        value_name = "S",
        default_value_t = 5.0,
        allow_negative_numbers = true
    )]
    pub steps_seconds: f64,
    /// Run the --flume case at a constant discharge to a steady state at each --dp instead,
    /// and print its levels against the 1-D hydraulic reference, its outflow against its
    /// inflow, the run in 10 s windows with the one from which it stayed steady, and the
    /// water's stand-off from the bed.
    #[arg(long, conflicts_with_all = ["ladder", "case", "frames"])]
    pub levels: bool,
    /// With --levels: the resolutions to run, m.
    #[arg(
        long,
        value_name = "DP1,DP2,...",
        value_delimiter = ',',
        default_value = "0.01,0.007,0.005",
        requires = "levels",
        allow_negative_numbers = true
    )]
    pub dp: Vec<f64>,
    /// With --levels: the constant discharge, m3/h.
    #[arg(long, value_name = "Q", default_value_t = 2.0, requires = "levels", value_parser = positive)]
    pub m3_per_h: f64,
    /// With --levels: how long each run lasts, s of flume time (at least 20: the levels are
    /// averaged over the last 10 s and the drift taken against the 10 s before).
    #[arg(long, value_name = "T_S", default_value_t = 60.0, requires = "levels")]
    pub until: f64,
    /// With --levels: the sand bed replaced by a fixed wall block of its shape (clear water).
    #[arg(long, requires = "levels")]
    pub fixed_bed: bool,
    /// With --levels: the sand bed's collector pit empty at the start, as the case writes it.
    /// By default it starts full of still water to the crest, as in a flume that has run
    /// before: the pit's current, and at dp = 5 mm the levels, depend on how the pit filled.
    #[arg(long, requires = "levels", conflicts_with = "fixed_bed")]
    pub empty_pit: bool,
    /// Override a field of the flume case (repeatable), as `simulate --set`: of the timed
    /// flume, or with --levels of the flume run to a steady state.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Run the timed flume to this flume time before timing it, s (the CI-size twin has filled
    /// by 20 s); 0: from the dry start.
    #[arg(
        long,
        value_name = "T_S",
        default_value_t = 0.0,
        conflicts_with = "levels",
        allow_negative_numbers = true
    )]
    pub from: f64,
}
