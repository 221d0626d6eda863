//! `flume-twin bench --frames`: how many particle frames iceoryx2 carries per second at a case's
//! particle count, and their latency. The frame is the case's first state, taken from the
//! solver once; the twin's own publisher (`Frames`) then sends it as fast as it can, without
//! the solver, on a service of its own, to a reader that opens the service as any visualiser
//! does, with its own iceoryx2 node, and reads every particle of each frame it takes. The
//! reader is a thread of this process: the frames still go through the shared memory
//! iceoryx2 maps for another process, and the figure is not a Python reader's.

use crate::adapters::frames::{FrameHeader, Frames, Particle};
use crate::adapters::table::{Table, sig};
use anyhow::{Context, Result, anyhow};
use flume_solver::{Case, GpuContext, Simulation};
use iceoryx2::prelude::*;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

fn unix_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// What the reader saw: frames taken, their latencies (ns, send to first look), and the
/// sum of the densities it read (so that reading every particle is not optimised away).
struct Read {
    frames: u64,
    latency_ns: Vec<u64>,
    density_sum: f64,
}

fn read(service: String, stop: Arc<AtomicBool>, ready: Arc<AtomicBool>) -> Result<Read> {
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| anyhow!("reader node: {e:?}"))?;
    let name: ServiceName = service
        .as_str()
        .try_into()
        .map_err(|e| anyhow!("service name: {e:?}"))?;
    let subscriber = node
        .service_builder(&name)
        .publish_subscribe::<[Particle]>()
        .user_header::<FrameHeader>()
        .open()
        .map_err(|e| anyhow!("reader cannot open {service}: {e:?}"))?
        .subscriber_builder()
        .create()
        .map_err(|e| anyhow!("reader: {e:?}"))?;
    let listener = node
        .service_builder(&name)
        .event()
        .open()
        .map_err(|e| anyhow!("reader cannot open the event {service}: {e:?}"))?
        .listener_builder()
        .create()
        .map_err(|e| anyhow!("reader: {e:?}"))?;
    ready.store(true, Ordering::Release);
    let mut out = Read {
        frames: 0,
        latency_ns: Vec::new(),
        density_sum: 0.0,
    };
    while !stop.load(Ordering::Acquire) {
        listener
            .timed_wait(|_| {}, Duration::from_millis(50))
            .map_err(|e| anyhow!("reader wait: {e:?}"))?;
        while let Some(sample) = subscriber
            .receive()
            .map_err(|e| anyhow!("reader receive: {e:?}"))?
        {
            let seen = unix_ns();
            out.latency_ns
                .push(seen.saturating_sub(sample.user_header().sent_unix_ns));
            out.density_sum += sample
                .payload()
                .iter()
                .map(|p| f64::from(p.density))
                .sum::<f64>();
            out.frames += 1;
        }
    }
    Ok(out)
}

fn percentile(sorted: &[u64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let k = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[k] as f64 * 1e-6
}

/// Sends frames of `case`'s particles for about `seconds` of wall time and prints the rates.
pub fn run(case_path: &std::path::Path, seconds: f64) -> Result<()> {
    let case = Case::from_path(case_path)
        .with_context(|| format!("cannot load {}", case_path.display()))?;
    let gpu = Arc::new(GpuContext::new().context("cannot open a GPU adapter")?);
    let sim = Simulation::new(Arc::clone(&gpu), &case)
        .with_context(|| format!("cannot set up {}", case.name))?;
    let count = sim.particle_count();
    let service = format!("flume_twin/bench_frames_{}", std::process::id());
    let parked = sim.parked_phase().unwrap_or(0);
    let mut frames = Frames::open(&service, count, parked, f64::INFINITY)?;
    let particles = sim
        .read_particles()
        .context("cannot read the particles back")?;
    frames.fill(&sim, &particles)?;
    let bytes = count * std::mem::size_of::<Particle>();
    println!(
        "particle frames over iceoryx2: case {} ({}), {count} particles, {} bytes a frame; \
         sent as fast as the publisher goes for about {seconds} s",
        case.name,
        case_path.display(),
        bytes + std::mem::size_of::<FrameHeader>()
    );
    let stop = Arc::new(AtomicBool::new(false));
    let ready = Arc::new(AtomicBool::new(false));
    let reader = std::thread::spawn({
        let (service, stop, ready) = (service.clone(), Arc::clone(&stop), Arc::clone(&ready));
        move || read(service, stop, ready)
    });
    while !ready.load(Ordering::Acquire) && !reader.is_finished() {
        std::thread::sleep(Duration::from_millis(10));
    }
    let started = Instant::now();
    let (mut sent, mut failed) = (0u64, 0u64);
    // A reader that failed to open ends at once; its error comes out of `join` below.
    while started.elapsed().as_secs_f64() < seconds && !reader.is_finished() {
        match frames.publish(sent, 0.0) {
            Ok(()) => sent += 1,
            Err(e) => {
                failed += 1;
                log::debug!("{e:#}");
            }
        }
    }
    let wall = started.elapsed().as_secs_f64();
    // The reader takes what is still in its buffer.
    std::thread::sleep(Duration::from_millis(200));
    stop.store(true, Ordering::Release);
    let read = reader
        .join()
        .map_err(|_| anyhow!("the reader thread panicked"))??;
    let mut latency = read.latency_ns.clone();
    latency.sort_unstable();
    let mut table = Table::new([
        "frames sent/s",
        "MB/s sent",
        "frames read/s",
        "MB/s read",
        "no sample to loan",
        "latency median ms",
        "latency p99 ms",
    ]);
    let mb = bytes as f64 / 1e6;
    table.row([
        sig(sent as f64 / wall),
        sig(sent as f64 * mb / wall),
        sig(read.frames as f64 / wall),
        sig(read.frames as f64 * mb / wall),
        failed.to_string(),
        sig(percentile(&latency, 0.5)),
        sig(percentile(&latency, 0.99)),
    ]);
    print!("{table}");
    println!(
        "the reader read every particle of {} of {sent} frames (mean density {} kg/m3); the \
         rest were discarded unread, as the twin's publisher does for a slow reader",
        read.frames,
        sig(read.density_sum / (read.frames.max(1) as f64 * count as f64))
    );
    Ok(())
}
