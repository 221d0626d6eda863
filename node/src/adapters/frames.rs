//! Particle frames for visualisers over iceoryx2 (zero-copy shared memory): every particle of
//! the flume, at most `rate` times a wall second, on the publish-subscribe service
//! `flume_twin/particles` as a slice of [`Particle`] with a [`FrameHeader`], and a notification
//! on the event service of the same name after each frame, to wake readers.
//!
//! The layout is versioned ([`FRAME_VERSION`]); Python reads it with a `ctypes.Structure` of the
//! same fields (`tests/interop/iox2_frames.py`). A reader never slows the twin: frames a reader
//! has not taken are dropped (backpressure: discard), and when every sample is held by readers
//! the frame is skipped and counted. Resources a crashed twin or reader left in shared memory
//! are removed when the twin starts.

use crate::twin::solver_thread::{FrameSink, Opener};
use crate::twin::visual::in_flume_frame;
use anyhow::{Context, Result, anyhow};
use flume_solver::{ParticleRegion, Particles, Simulation};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;
use std::time::{Duration, Instant};

pub const SERVICE: &str = "flume_twin/particles";
/// Bumped whenever [`Particle`] or [`FrameHeader`] changes.
pub const FRAME_VERSION: u32 = 1;
/// What the numbers mean, for a reader that checks.
pub const UNITS: &[u8; 32] = b"m, m/s, kg/m3; flume frame z up\0";

/// One particle in the flume frame (x along the flume, y across, z up; a 2-D case's vertical
/// is z).
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("flume_twin::Particle")]
pub struct Particle {
    /// m.
    pub position: [f32; 3],
    /// m/s.
    pub velocity: [f32; 3],
    /// kg/m3.
    pub density: f32,
    /// 0 walls, then the case's phases in order from 1 (water, sand), and one more for the
    /// water parked out of the flow in an open flume.
    pub phase: u8,
    /// The paper's region (Figure 2): 1 un-yielded, 2 yielded, 3 bed load, 4 suspended,
    /// 5 water; 0 walls, and sand before the first step has classified it.
    pub region: u8,
    /// 1 for sand held fixed (the Shields-only mode's grains that are not eroded).
    pub held: u8,
    pub reserved: u8,
}

#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("flume_twin::FrameHeader")]
pub struct FrameHeader {
    pub version: u32,
    /// The phase code of parked particles (0 without an open flume).
    pub parked_phase: u32,
    /// Particles in the frame.
    pub count: u64,
    pub step: u64,
    /// Simulated time, s.
    pub sim_time_s: f64,
    /// When the frame was sent, ns since the epoch (a reader's latency is its clock minus this).
    pub sent_unix_ns: u64,
    pub units: [u8; 32],
}

/// The twin's end: the publisher, its notifier, and the pacing.
pub struct Frames {
    // Field order is drop order: ports before the node that owns them.
    publisher: Publisher<ipc::Service, [Particle], FrameHeader>,
    notifier: Notifier<ipc::Service>,
    _node: Node<ipc::Service>,
    every: Duration,
    last: Option<Instant>,
    buffer: Vec<Particle>,
    parked_phase: u32,
    pub sent: u64,
    pub skipped: u64,
}

/// Removes what dead iceoryx2 nodes (a killed twin or reader) left in shared memory.
fn remove_dead_nodes() {
    let mut removed = 0;
    let listed = Node::<ipc::Service>::list(Config::global_config(), |state| {
        if let NodeState::Dead(view) = state {
            match view.try_remove_stale_resources() {
                Ok(()) => removed += 1,
                Err(e) => log::warn!("cannot remove a dead iceoryx2 node's resources: {e:?}"),
            }
        }
        CallbackProgression::Continue
    });
    if let Err(e) = listed {
        log::warn!("cannot list iceoryx2 nodes to clean up after dead ones: {e:?}");
    }
    if removed > 0 {
        println!("removed what {removed} dead iceoryx2 node(s) left in shared memory");
    }
}

impl Frames {
    /// Offers frames of `count` particles on `service`, at most `rate_hz` per wall second.
    pub fn open(service: &str, count: usize, parked_phase: u32, rate_hz: f64) -> Result<Frames> {
        // iceoryx2 warns when it finds no config file of its own and runs on its defaults,
        // as its readers (its Python binding among them) then do: nothing to act on, so the
        // look-up is quiet. A config file, when there is one, is still read.
        set_log_level(LogLevel::Error);
        Config::global_config();
        set_log_level(LogLevel::Warn);
        remove_dead_nodes();
        let node = NodeBuilder::new()
            // The node's own SIGINT/SIGTERM handling stays the node's (tokio's).
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .name(&"flume_twin".try_into().map_err(|e| anyhow!("{e:?}"))?)
            .create::<ipc::Service>()
            .map_err(|e| anyhow!("cannot create the iceoryx2 node: {e:?}"))?;
        let name: ServiceName = service
            .try_into()
            .map_err(|e| anyhow!("{service:?} is not an iceoryx2 service name: {e:?}"))?;
        let pubsub = node
            .service_builder(&name)
            .publish_subscribe::<[Particle]>()
            .user_header::<FrameHeader>()
            .max_publishers(1)
            .max_subscribers(8)
            .history_size(0)
            .subscriber_max_buffer_size(2)
            .subscriber_max_borrowed_samples(2)
            .open_or_create()
            .map_err(|e| anyhow!("cannot offer the iceoryx2 service {service}: {e:?}"))?;
        let publisher = pubsub
            .publisher_builder()
            .initial_max_slice_len(count)
            .allocation_strategy(AllocationStrategy::Static)
            .backpressure_strategy(BackpressureStrategy::DiscardData)
            .create()
            .map_err(|e| anyhow!("cannot publish on {service}: {e:?}"))?;
        let notifier = node
            .service_builder(&name)
            .event()
            .open_or_create()
            .map_err(|e| anyhow!("cannot offer the iceoryx2 event {service}: {e:?}"))?
            .notifier_builder()
            .create()
            .map_err(|e| anyhow!("cannot notify on {service}: {e:?}"))?;
        Ok(Frames {
            publisher,
            notifier,
            _node: node,
            every: Duration::from_secs_f64(1.0 / rate_hz),
            last: None,
            buffer: Vec::with_capacity(count),
            parked_phase,
            sent: 0,
            skipped: 0,
        })
    }

    /// Whether a frame is due: at most `rate_hz` a wall second.
    pub fn due(&self) -> bool {
        self.last.is_none_or(|t| t.elapsed() >= self.every)
    }

    /// Publishes `p`, `sim`'s particles as read back for this chunk, as the next frame. A
    /// frame that cannot go out is skipped with a log line; the solver never waits for a
    /// reader.
    pub fn offer(&mut self, sim: &Simulation, p: &Particles) {
        self.last = Some(Instant::now());
        let sent = self
            .fill(sim, p)
            .and_then(|()| self.publish(sim.steps(), sim.time_s()));
        if let Err(e) = sent {
            self.skip(&format!("{e:#}"));
        }
    }

    /// Counts a frame that did not go out, and says why.
    pub fn skip(&mut self, why: &str) {
        self.last = Some(Instant::now());
        self.skipped += 1;
        log::warn!("particle frame skipped: {why}");
    }

    /// Takes `p`, `sim`'s particles, into the frame buffer, with their regions.
    pub fn fill(&mut self, sim: &Simulation, p: &Particles) -> Result<()> {
        let regions = sim.regions().context("cannot read the regions back")?;
        let two_d = sim.case().dim() == 2;
        self.buffer.clear();
        self.buffer.extend((0..p.len()).map(|i| {
            let [x, y, z, _] = p.positions[i];
            let [u, v, w, rho] = p.vel_rho[i];
            let region = ParticleRegion::from_word(regions[i]);
            Particle {
                position: in_flume_frame(two_d, [x, y, z]),
                velocity: in_flume_frame(two_d, [u, v, w]),
                density: rho,
                phase: u8::try_from(p.phase(i)).unwrap_or(u8::MAX),
                region: region.number(),
                held: u8::from(region.held),
                reserved: 0,
            }
        }));
        Ok(())
    }

    /// Sends the frame buffer, stamped `step` and `sim_time_s`, and wakes the readers.
    pub fn publish(&mut self, step: u64, sim_time_s: f64) -> Result<()> {
        let sample = self
            .publisher
            .loan_slice_uninit(self.buffer.len())
            .map_err(|e| anyhow!("no shared memory to loan (readers hold every sample): {e:?}"))?;
        let mut sample = sample.write_from_slice(&self.buffer);
        *sample.user_header_mut() = FrameHeader {
            version: FRAME_VERSION,
            parked_phase: self.parked_phase,
            count: self.buffer.len() as u64,
            step,
            sim_time_s,
            sent_unix_ns: 0,
            units: *UNITS,
        };
        sample.user_header_mut().sent_unix_ns = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64);
        sample
            .send()
            .map_err(|e| anyhow!("cannot send the frame: {e:?}"))?;
        self.notifier
            .notify()
            .map_err(|e| anyhow!("cannot wake the readers: {e:?}"))?;
        self.sent += 1;
        Ok(())
    }
}

impl FrameSink for Frames {
    fn due(&self) -> bool {
        Frames::due(self)
    }

    fn offer(&mut self, sim: &Simulation, p: &Particles) {
        Frames::offer(self, sim, p);
    }

    fn skip(&mut self, why: &str) {
        Frames::skip(self, why);
    }

    fn counts(&self) -> (u64, u64) {
        (self.sent, self.skipped)
    }
}

/// The solver thread's opener of frames on `service` at most `rate_hz` a wall second, for
/// every particle of its simulation.
pub fn frames_on(service: String, rate_hz: f64) -> Opener<dyn FrameSink> {
    Box::new(move |sim: &Simulation| {
        let parked = sim.parked_phase().unwrap_or(0);
        let frames = Frames::open(&service, sim.particle_count(), parked, rate_hz)?;
        println!("particle frames: iceoryx2 service {service}");
        Ok(Box::new(frames) as Box<dyn FrameSink>)
    })
}
