//! The solver on a thread of its own: GPU work never blocks the async runtime. The node sends
//! chunks (advance to t, changing the discharge on the way) and gets back one report per chunk.

use crate::twin::visual::{CloudPoint, in_flume_frame};
use anyhow::{Context, Result};
use flume_solver::Particles;
use flume_solver::{Backend, Case, InflowSchedule, Observations, Simulation};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Instant;
use tokio::sync::mpsc as async_mpsc;

pub enum Command {
    /// Advance to `to_s`, changing the discharge at each `(t, q)`; with `cloud`, read the
    /// particles back for the visualisers.
    Advance {
        to_s: f64,
        inflow: Vec<(f64, f64)>,
        cloud: bool,
    },
    /// Back to the case's initial state.
    Reset,
}

/// What a chunk did.
#[derive(Debug, Clone)]
pub struct Report {
    pub obs: Observations,
    /// Wall time the chunk took, s.
    pub wall_s: f64,
    /// Steps the chunk took.
    pub steps: u64,
    /// Discharges the solver refused in this chunk (each also logged).
    pub refused_inflows: u64,
    /// The particles in the flow (not the parked ones), when asked for.
    pub cloud: Option<Vec<CloudPoint>>,
    /// This report is the initial state after a reset.
    pub reset: bool,
    /// Particle frames sent to visualisers and skipped, since the start.
    pub frames_sent: u64,
    pub frames_skipped: u64,
}

/// Where and how often the solver thread offers particle frames (iceoryx2).
/// Where a run keeps its chunks besides the reports: its output files.
pub trait Recorder {
    /// The observations after chunk `k`, kept.
    fn record(&mut self, sim: &Simulation, k: u64) -> Result<Observations>;
    /// The run starts again from the case.
    fn restart(&mut self);
}

/// Where the particle frames for visualisers go.
pub trait FrameSink {
    /// Whether a frame is due now.
    fn due(&self) -> bool;
    fn offer(&mut self, sim: &Simulation, p: &Particles);
    /// A due frame that could not be read back, and why.
    fn skip(&mut self, why: &str);
    /// Frames sent and skipped so far.
    fn counts(&self) -> (u64, u64);
}

/// Makes a run's recorder or frame sink from the simulation, on the solver's own thread (a
/// shared-memory port stays on the thread that opened it).
pub type Opener<T> = Box<dyn FnOnce(&Simulation) -> Result<Box<T>> + Send>;

/// Where a run's chunks go besides its reports, as the adapters open them.
#[derive(Default)]
pub struct ChunkSinks {
    pub recorder: Option<Opener<dyn Recorder>>,
    pub frames: Option<Opener<dyn FrameSink>>,
}

/// The solver thread's end of the channels, and what it says when it starts.
pub struct SolverThread {
    pub link: SolverLink,
    pub reports: async_mpsc::UnboundedReceiver<Result<Report, String>>,
    pub handle: JoinHandle<()>,
}

/// What the twin keeps of the solver: where its commands go, and what it said at the start.
pub struct SolverLink {
    pub commands: mpsc::Sender<Command>,
    pub adapter: String,
    pub particles: usize,
    /// The observations at t = 0.
    pub first: Observations,
}

/// Starts the solver for `case` on its own thread; returns once the GPU is open and the case
/// built, with the observations at t = 0. With `out`, the thread writes the same CSV files as
/// `simulate`, one row per chunk; with `frames`, it offers the particles to visualisers after
/// each chunk, when a frame is due (a frame service that cannot be opened is logged and left
/// out: the twin runs without it).
pub fn spawn(case: Case, sinks: ChunkSinks) -> Result<SolverThread> {
    let (cmd_tx, cmd_rx) = mpsc::channel::<Command>();
    let (rep_tx, rep_rx) = async_mpsc::unbounded_channel();
    let (ready_tx, ready_rx) = mpsc::channel::<Result<(String, usize, Observations), String>>();
    let handle = std::thread::Builder::new()
        .name("flume-solver".into())
        .spawn(move || {
            let mut worker = match Worker::start(case, sinks.recorder) {
                Ok(w) => w,
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return;
                }
            };
            let said = (worker.sim.backend_name(), worker.sim.particle_count());
            match worker.observe() {
                Ok(obs) => {
                    let _ = ready_tx.send(Ok((said.0, said.1, obs)));
                }
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return;
                }
            }
            worker.open_frames(sinks.frames);
            while let Ok(command) = cmd_rx.recv() {
                let report = worker.handle(command);
                let failed = report.is_err();
                if rep_tx.send(report).is_err() || failed {
                    return;
                }
            }
        })
        .context("cannot start the solver thread")?;
    let (adapter, particles, first) = ready_rx
        .recv()
        .context("the solver thread stopped while starting")?
        .map_err(|e| anyhow::anyhow!(e))?;
    Ok(SolverThread {
        link: SolverLink {
            commands: cmd_tx,
            adapter,
            particles,
            first,
        },
        reports: rep_rx,
        handle,
    })
}

/// What the solver thread holds: the case (to reset to), the simulation, and its outputs.
struct Worker {
    case: Case,
    backend: Backend,
    sim: Simulation,
    recorder: Option<Box<dyn Recorder>>,
    frames: Option<Box<dyn FrameSink>>,
    /// Chunks handled, the row number of the CSV files.
    chunks: u64,
}

impl Worker {
    fn start(case: Case, recorder: Option<Opener<dyn Recorder>>) -> Result<Worker, String> {
        let started = (|| -> Result<Worker> {
            let backend = Backend::choose().context("cannot open a backend")?;
            let sim =
                Simulation::new(backend.clone(), &case).context("cannot set up the simulation")?;
            let recorder = recorder.map(|open| open(&sim)).transpose()?;
            Ok(Worker {
                case,
                backend,
                sim,
                recorder,
                frames: None,
                chunks: 0,
            })
        })();
        started.map_err(|e| format!("{e:#}"))
    }

    /// Opens the frame sink; without it the run goes on, with the reason logged.
    fn open_frames(&mut self, open: Option<Opener<dyn FrameSink>>) {
        self.frames = open.and_then(|open| match open(&self.sim) {
            Ok(sink) => Some(sink),
            Err(e) => {
                log::error!("no particle frames for visualisers: {e:#}");
                None
            }
        });
    }

    fn handle(&mut self, command: Command) -> Result<Report, String> {
        self.chunks += 1;
        match command {
            Command::Advance {
                to_s,
                inflow,
                cloud,
            } => self.advance(to_s, &inflow, cloud),
            Command::Reset => {
                let started = Instant::now();
                self.sim = Simulation::new(self.backend.clone(), &self.case)
                    .map_err(|e| format!("cannot rebuild the case: {e}"))?;
                if let Some(r) = &mut self.recorder {
                    r.restart();
                }
                let mut report = self.report(started.elapsed().as_secs_f64(), 0, 0, None)?;
                report.reset = true;
                Ok(report)
            }
        }
    }

    fn advance(&mut self, to_s: f64, inflow: &[(f64, f64)], cloud: bool) -> Result<Report, String> {
        let (wall_s, steps, refused) = run_chunk(&mut self.sim, to_s, inflow)?;
        let particles = read_back(&self.sim, cloud, self.frames.as_mut())?;
        let parked = self.sim.parked_phase();
        let points = particles
            .as_ref()
            .filter(|_| cloud)
            .map(|p| cloud_points(&self.sim, p, parked));
        self.report(wall_s, steps, refused, points)
    }

    fn observe(&mut self) -> Result<Observations, String> {
        match &mut self.recorder {
            Some(r) => r
                .record(&self.sim, self.chunks)
                .map_err(|e| format!("{e:#}")),
            None => self
                .sim
                .observe()
                .map_err(|e| format!("cannot read the observations back from the GPU: {e}")),
        }
    }

    fn report(
        &mut self,
        wall_s: f64,
        steps: u64,
        refused_inflows: u64,
        cloud: Option<Vec<CloudPoint>>,
    ) -> Result<Report, String> {
        Ok(Report {
            obs: self.observe()?,
            wall_s,
            steps,
            refused_inflows,
            cloud,
            reset: false,
            frames_sent: self.frames.as_ref().map_or(0, |f| f.counts().0),
            frames_skipped: self.frames.as_ref().map_or(0, |f| f.counts().1),
        })
    }
}

/// Advances to `to_s`, setting each discharge at its time. A discharge the solver refuses
/// (its inlet velocity above the Mach bound) is logged and counted; the previous one holds.
fn run_chunk(
    sim: &mut Simulation,
    to_s: f64,
    inflow: &[(f64, f64)],
) -> Result<(f64, u64, u64), String> {
    let started = Instant::now();
    let steps0 = sim.steps();
    let schedule = InflowSchedule::new(inflow.to_vec());
    let refused = sim
        .advance_through(to_s, &schedule)
        .map_err(|e| format!("{e}"))?;
    for r in &refused {
        log::warn!(
            "discharge {} m3/s at t = {:.3} s refused by the solver: {}",
            r.inflow_m3_per_s,
            r.time_s,
            r.error
        );
    }
    Ok((
        started.elapsed().as_secs_f64(),
        sim.steps() - steps0,
        refused.len() as u64,
    ))
}

/// The particles in the flume frame (z up), without the parked ones.
/// After a chunk, the particles read back once for the cloud and a due frame, which goes out.
/// A failed readback fails the chunk only when the cloud needed it; a frame is just skipped.
fn read_back(
    sim: &Simulation,
    cloud: bool,
    frames: Option<&mut Box<dyn FrameSink>>,
) -> Result<Option<Particles>, String> {
    let frame = frames.filter(|f| f.due());
    if !cloud && frame.is_none() {
        return Ok(None);
    }
    match sim.read_particles() {
        Ok(p) => {
            if let Some(f) = frame {
                f.offer(sim, &p);
            }
            Ok(Some(p))
        }
        Err(e) if cloud => Err(format!("cannot read the particles back from the GPU: {e}")),
        Err(e) => {
            if let Some(f) = frame {
                f.skip(&format!("cannot read the particles back: {e}"));
            }
            Ok(None)
        }
    }
}

fn cloud_points(sim: &Simulation, p: &Particles, parked: Option<u32>) -> Vec<CloudPoint> {
    let two_d = sim.case().dim() == 2;
    (0..p.len())
        .filter(|&i| Some(p.phase(i)) != parked)
        .map(|i| {
            let [x, y, z, _] = p.positions[i];
            let [u, v, w, _] = p.vel_rho[i];
            CloudPoint {
                position: in_flume_frame(two_d, [x, y, z]),
                speed: (u * u + v * v + w * w).sqrt(),
                phase: u8::try_from(p.phase(i)).unwrap_or(u8::MAX),
            }
        })
        .collect()
}
