// The state of the GPU-resident step loop: the host writes it before each submission (a chunk
// of steps, with time counted from the chunk's start) and reads it back after; no stage waits
// for the host in between.

// A particle as it was when it was excluded (`exclude` in store_state.wgsl).
struct ExcludedParticle {
    id: u32,
    phase: u32,
    x: f32,
    y: f32,
    u: f32,
    v: f32,
    rho: f32,
    pad: u32,
}

// `EXCLUDED_LOG_LEN` of solver/src/contract/blocks.rs (checked by solver/tests/shaders_validate.rs).
const EXCLUDED_LOG_LEN: u32 = 8u;

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
    excluded: atomic<u32>,      // particles excluded for a density out of range in this chunk
    excluded_sediment: atomic<u32>, // of which sediment (they are recycled as water)
    pad0: u32,
    pad1: u32,
    excluded_log: array<ExcludedParticle, EXCLUDED_LOG_LEN>, // the first ones of the chunk
}

const STATUS_NON_FINITE: u32 = 1u;
const STATUS_DENSITY_RUNAWAY: u32 = 2u;
const STATUS_DT_COLLAPSE: u32 = 4u;
