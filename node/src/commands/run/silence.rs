//! With no sensor on the network, a recorded session plays the sensors' part: which session,
//! and its samples sent to the twin at their recorded pace until a real sensor speaks.

use crate::adapters::bag::BagFile;
use crate::adapters::bag::samples::{decode, role};
use crate::cli::RunArgs;
use crate::twin::samples::Sample;
use flume_msgs::builtin_interfaces::Time;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tokio::sync::mpsc;

/// Starts the recorded session that plays the sensors' part when none is heard, if there is
/// one; its samples come on the receiver.
pub(super) fn start_session_for_silence(
    args: &RunArgs,
    gauge_names: &[String],
    heard: &Arc<AtomicBool>,
    on_sim_time: bool,
) -> (mpsc::Receiver<Sample>, bool) {
    let (to_twin, samples) = mpsc::channel::<Sample>(64);
    let Some(path) = session_for_silence(args, on_sim_time) else {
        return (samples, false);
    };
    let wait = Duration::from_secs_f64(args.silent_wait_s);
    let gauges = gauge_names.to_vec();
    tokio::spawn(play_when_silent(
        path,
        gauges,
        wait,
        Arc::clone(heard),
        to_twin,
    ));
    (samples, true)
}

/// With no sensor on the network, a recorded session plays the sensors' part: the session to
/// play, if there is one. On simulated time the session is the player's to play, on the wire.
fn session_for_silence(args: &RunArgs, on_sim_time: bool) -> Option<PathBuf> {
    if on_sim_time && !args.no_replay {
        println!("use_sim_time: no recorded session plays the sensors here");
    }
    args.replay_when_silent
        .clone()
        .filter(|_| !args.no_replay && !on_sim_time)
        .filter(|path| {
            let exists = path.exists();
            if !exists {
                log::warn!(
                    "{} does not exist: with no sensors the twin runs on the clock",
                    path.display()
                );
            }
            exists
        })
}

/// With no sensor heard for `wait`, plays the inflow and gauge topics of the recording at
/// `path` as the sensors, at their recorded pace, restamped on this node's clock; stops at
/// the first sample a real sensor sends.
async fn play_when_silent(
    path: PathBuf,
    gauges: Vec<String>,
    wait: Duration,
    heard: Arc<AtomicBool>,
    to_twin: tokio::sync::mpsc::Sender<Sample>,
) {
    tokio::time::sleep(wait).await;
    if heard.load(Ordering::Relaxed) {
        return;
    }
    let read = tokio::task::spawn_blocking({
        let path = path.clone();
        move || BagFile::read(&path)
    })
    .await;
    let recording = match read {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            log::error!("no sensors, and the session to replay cannot be read: {e:#}");
            return;
        }
        Err(e) => {
            log::error!("no sensors, and reading the session to replay failed: {e}");
            return;
        }
    };
    if let Some(damage) = &recording.damage {
        log::warn!("{damage}; replaying what comes before it");
    }
    let mut samples: Vec<(u64, Sample)> = recording
        .messages
        .iter()
        .filter_map(|m| role(m, &gauges).map(|r| (m, r)))
        .filter_map(|(m, r)| match decode(m, r) {
            Ok(s) => Some((m.log_ns, s)),
            Err(e) => {
                log::warn!("{e:#}");
                None
            }
        })
        .collect();
    samples.sort_by_key(|(log_ns, _)| *log_ns);
    let Some(first) = samples.first().map(|(_, s)| s.stamp().as_secs_f64()) else {
        log::warn!(
            "{} has no sensor topic of this case to replay",
            path.display()
        );
        return;
    };
    let span = samples.last().map_or(0.0, |(_, s)| s.stamp().as_secs_f64()) - first;
    println!(
        "no sensors in {:.0} s: {} plays the sensors ({} samples over {span:.0} s)",
        wait.as_secs_f64(),
        path.display(),
        samples.len()
    );
    let start = crate::twin::clock::system_s();
    let started = Instant::now();
    for (_, mut sample) in samples {
        let offset = sample.stamp().as_secs_f64() - first;
        if let Some(rest) = Duration::from_secs_f64(offset.max(0.0)).checked_sub(started.elapsed())
        {
            tokio::time::sleep(rest).await;
        }
        if heard.load(Ordering::Relaxed) {
            println!("a sensor spoke: the recorded session stops");
            return;
        }
        sample.set_stamp(Time::from_secs_f64(start + offset).unwrap_or_default());
        if to_twin.send(sample).await.is_err() {
            return;
        }
    }
    println!("the recorded session has ended: the twin holds its last discharge");
}
