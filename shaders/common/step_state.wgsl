// The state of the GPU-resident step loop: the host writes it before each submission (a chunk
// of steps, with time counted from the chunk's start) and reads it back after; no stage waits
// for the host in between.

struct StepState {
    dt: f32,                    // the step being taken, s (0 once the chunk is done)
    t_rel: f32,                 // time since the chunk started, s
    t_target: f32,              // the chunk ends when t_rel reaches it
    steps: u32,                 // steps taken in this chunk
    dt_min_bits: atomic<u32>,   // min over particles of the stable step, as f32 bits (> 0)
    status: atomic<u32>,        // health flags, see `Health` in solver/src/simulation.rs
    last_dt: f32,               // the CFL step of the last step taken, before landing on the target, s
    step_base: u32,             // steps taken before this chunk, modulo the Verlet Euler period
    dt_prev: f32,               // the step before the one being taken, s (Verlet's leapfrog span)
    dt_taken: f32,              // the last step actually taken, s
    eroded: atomic<u32>,        // sediment particles collected in this chunk (open flume)
    parked: atomic<u32>,        // particles parked in this chunk (open flume)
}

const STATUS_NON_FINITE: u32 = 1u;
const STATUS_DENSITY_RUNAWAY: u32 = 2u;
const STATUS_DT_COLLAPSE: u32 = 4u;
