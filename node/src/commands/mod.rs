//! One module per subcommand: each parses nothing (clap has) and holds only what its command
//! does with the twin and the adapters; none imports another.

pub mod bench;
mod bench_frames;
mod bench_levels;
mod bench_steadiness;
pub mod make_session;
pub mod play;
pub mod replay;
pub mod run;
pub mod simulate;
pub mod sweep;
