// Whether the neighbour passes (rheology, forces) skip this step; the importing stage declares
// `state`. Steps recorded past the end of a chunk (or after a blow-up) skip the costly passes:
// before dt_update the chunk has ended when its time is reached, after it when the step is zero.
fn chunk_idle(before_dt: bool) -> bool {
    let ended = select(state.dt == 0.0, state.t_rel >= state.t_target, before_dt);
    return ended || atomicLoad(&state.status) != 0u;
}
