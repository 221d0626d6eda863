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
    run_steps: u32,             // steps taken before this chunk since the run started, wrapping
    pad: u32,
    excluded_log: array<ExcludedParticle, EXCLUDED_LOG_LEN>, // the first ones of the chunk
}

const STATUS_NON_FINITE: u32 = 1u;
const STATUS_DENSITY_RUNAWAY: u32 = 2u;
const STATUS_DT_COLLAPSE: u32 = 4u;

// A mobile particle's stable step from its forces, s (`stable_step` in physics/timestep.rs):
// min(sqrt(h / |a|), h / (c0 + visc_max)), without the force bound where the particle's
// velocity is imposed or it has no acceleration.
fn stable_step(h: f32, c0: f32, accel: f32, force_bound: bool, visc_max: f32) -> f32 {
    var dt = 3.0e38;
    if (accel > 0.0 && force_bound) {
        dt = sqrt(h / accel);
    }
    return min(dt, h / (c0 + visc_max));
}

// One particle's explicit viscous bound 0.125 h^2 rho / mu, s (`particle_viscous_bound` in
// physics/timestep.rs); 3e38 without a positive viscosity.
fn viscous_step(h: f32, rho: f32, mu: f32) -> f32 {
    if (mu > 0.0) {
        return 0.125 * h * h * rho / mu;
    }
    return 3.0e38;
}

const NEXT_STOP: u32 = 0u;
const NEXT_COLLAPSE: u32 = 1u;
const NEXT_STEP: u32 = 2u;

// What the step loop does next (`NextStep` in physics/timestep.rs): stop, collapse, or step
// `dt` to `t_next`, with `cfl_dt` the CFL step before it was shortened to land on the target.
struct NextStep {
    kind: u32,
    dt: f32,
    t_next: f32,
    cfl_dt: f32,
}

// The variable step (`next_step` in physics/timestep.rs): dt = cfl min(stable, dt_visc),
// landing exactly on the chunk's target, in two equal steps rather than a full one and a sliver.
fn next_step(
    cfl: f32, stable: f32, dt_visc: f32, dt_min: f32, t_rel: f32, t_target: f32, halted: bool
) -> NextStep {
    let dt = cfl * min(stable, dt_visc);
    let remaining = t_target - t_rel;
    if (halted || remaining <= 0.0) {
        return NextStep(NEXT_STOP, 0.0, t_rel, dt);
    }
    // NaN is a collapse too.
    if (!(dt >= dt_min)) {
        return NextStep(NEXT_COLLAPSE, 0.0, t_rel, dt);
    }
    if (dt >= remaining) {
        return NextStep(NEXT_STEP, remaining, t_target, dt);
    }
    if (2.0 * dt > remaining) {
        return NextStep(NEXT_STEP, 0.5 * remaining, t_rel + 0.5 * remaining, dt);
    }
    return NextStep(NEXT_STEP, dt, t_rel + dt, dt);
}
