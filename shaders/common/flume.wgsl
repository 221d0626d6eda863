// Where an open flume imposes the velocity of its water (the inlet buffer, a bottom outlet's
// duct); shared by the integrators, which impose it, and the force pass, which lets no such
// particle set the step.

// Whether a particle at `x` is in the inlet buffer, whose velocity is imposed: behind the
// buffer's face, in the opening. Water that wanders in is pushed out with the buffer.
fn in_inlet(x: vec3<f32>) -> bool {
    let f = params.flume;
    return f.enabled != 0u && x.x < f.inlet_x_face && x.y > f.inlet_y_min && x.y <= f.inlet_y_max;
}

// Whether a particle at `x` is in a bottom outlet's duct, where a valve sets the velocity.
fn in_duct(x: vec3<f32>) -> bool {
    let f = params.flume;
    return f.enabled != 0u && x.x >= f.duct_x_min && x.y > f.duct_y_min && x.y <= f.duct_y_max;
}

// Whether the inlet carries a particle of `phase` at `x` out at its velocity: water, or
// sediment, in its buffer (no grain rests in an orifice's jet; `Store::carried_by_inlet`).
fn carried_by_inlet(x: vec3<f32>, phase: u32) -> bool {
    let sediment = params.sediment.phase != 0u && phase == params.sediment.phase;
    return (phase == params.flume.water_phase || sediment) && in_inlet(x);
}

// Whether a particle at `x` moves at an imposed velocity: such a particle may be squeezed
// against its neighbours without moving apart, so its acceleration means nothing.
fn velocity_imposed(x: vec3<f32>, phase: u32) -> bool {
    return carried_by_inlet(x, phase) || (phase == params.flume.water_phase && in_duct(x));
}
