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

// Whether water particle at `x` moves at an imposed velocity: such a particle may be
// squeezed against its neighbours without moving apart, so its acceleration means nothing.
fn velocity_imposed(x: vec3<f32>, phase: u32) -> bool {
    return phase == params.flume.water_phase && (in_inlet(x) || in_duct(x));
}
