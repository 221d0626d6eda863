// Variable time step (DualSPHysics): dt = CFL min(dt_force, dt_sound, dt_visc), landing exactly
// on the chunk's target time; one invocation, so the step never leaves the GPU.

@group(0) @binding(1) var<storage, read_write> state: StepState;

@compute @workgroup_size(1)
fn dt_update() {
    let stable = bitcast<f32>(atomicLoad(&state.dt_min_bits));
    atomicStore(&state.dt_min_bits, 0x7f7fffffu);
    var dt = params.cfl * min(stable, params.dt_visc);
    let remaining = state.t_target - state.t_rel;
    if (atomicLoad(&state.status) != 0u || remaining <= 0.0) {
        state.dt = 0.0;
        return;
    }
    if (!(dt >= params.dt_min)) {
        atomicOr(&state.status, STATUS_DT_COLLAPSE);
        state.dt = 0.0;
        return;
    }
    // The CFL step, before it is shortened to land on the target: what the next chunk's
    // number of steps is estimated from.
    state.last_dt = dt;
    var t_next = state.t_rel + dt;
    if (dt >= remaining) {
        dt = remaining;
        t_next = state.t_target;
    } else if (2.0 * dt > remaining) {
        // Two equal steps rather than a full one and a sliver.
        dt = 0.5 * remaining;
        t_next = state.t_rel + dt;
    }
    state.dt = dt;
    state.dt_prev = state.dt_taken;
    state.dt_taken = dt;
    state.t_rel = t_next;
    state.steps += 1u;
}
