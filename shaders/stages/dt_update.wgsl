// Variable time step (DualSPHysics): dt = CFL min(dt_force, dt_sound, dt_visc), landing exactly
// on the chunk's target time; one invocation, so the step never leaves the GPU.

@group(0) @binding(1) var<storage, read_write> state: StepState;

@compute @workgroup_size(1)
fn dt_update() {
    let stable = bitcast<f32>(atomicLoad(&state.dt_min_bits));
    atomicStore(&state.dt_min_bits, 0x7f7fffffu);
    let halted = atomicLoad(&state.status) != 0u;
    let next = next_step(
        params.cfl, stable, params.dt_visc, params.dt_min, state.t_rel, state.t_target, halted
    );
    if (next.kind == NEXT_COLLAPSE) {
        atomicOr(&state.status, STATUS_DT_COLLAPSE);
    }
    if (next.kind != NEXT_STEP) {
        state.dt = 0.0;
        return;
    }
    // The CFL step, before it is shortened to land on the target: what the next chunk's
    // number of steps is estimated from.
    state.last_dt = next.cfl_dt;
    state.dt = next.dt;
    state.dt_prev = state.dt_taken;
    state.dt_taken = next.dt;
    state.t_rel = next.t_next;
    state.steps += 1u;
}
