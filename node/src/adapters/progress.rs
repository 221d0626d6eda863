//! The progress bar of the offline commands (`simulate`, `sweep`), in simulated time.

use indicatif::{ProgressBar, ProgressStyle};

/// The bar counts simulated microseconds: an integer position with ample resolution.
const TICKS_PER_S: f64 = 1e6;

/// A bar from 0 to `end_s` of simulated time.
pub fn bar(end_s: f64) -> ProgressBar {
    let bar = ProgressBar::new((end_s * TICKS_PER_S) as u64);
    // A template typo is a programming error, caught the first time anyone runs the command.
    if let Ok(style) =
        ProgressStyle::with_template("[{elapsed_precise}] {wide_bar} {msg}, ETA {eta}")
    {
        bar.set_style(style);
    }
    bar
}

/// Moves `bar` to simulated time `t_s`.
pub fn set_time(bar: &ProgressBar, t_s: f64) {
    bar.set_position((t_s * TICKS_PER_S) as u64);
}
