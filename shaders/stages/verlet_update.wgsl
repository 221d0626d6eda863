// Verlet time integration as in DualSPHysics (Verlet 1967), one force pass a step:
// x(n+1) = x(n) + dt v(n) + dt^2 / 2 a(n), v(n+1) = v(n-1) + (dt_prev + dt) a(n),
// rho(n+1) = rho(n-1) + (dt_prev + dt) drho(n), the leapfrog over the two steps actually taken
// (they differ where a step is shortened to land on an output time);
// every `euler_every` steps (and the first) an Euler step v(n+1) = v(n) + dt a(n),
// rho(n+1) = rho(n) + dt drho(n) brings the two interleaved sequences back together.
// Walls (DBC) keep position and velocity and never drop below rho0. Writes the new state,
// in cell order, to the state buffers and the current one to `vel_rho_prev` (at rest for held
// sediment); over the active particles only (`parked_copy` writes the parked ones).
// Reference: solver/src/physics/integrate.rs.

@group(0) @binding(1) var<storage, read_write> state: StepState;
@group(0) @binding(2) var<storage, read> forces: array<vec4<f32>>;
@group(0) @binding(3) var positions_n: texture_2d<f32>;
@group(0) @binding(4) var vel_rho_n: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> ids_n: array<u32>;
@group(0) @binding(6) var<storage, read> vel_rho_before: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> positions_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> vel_rho_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> ids_out: array<u32>;
@group(0) @binding(10) var<storage, read_write> vel_rho_prev_out: array<vec4<f32>>;
@group(0) @binding(11) var<storage, read> regions: array<u32>;
@group(0) @binding(12) var<storage, read> cell_starts: array<u32>;

@compute @workgroup_size(128)
fn verlet_update(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let dt = state.dt;
    if (i >= cell_starts[params.n_cells] || dt == 0.0) {
        return;
    }
    let p = textureLoad(positions_n, texel(i), 0);
    let vr = textureLoad(vel_rho_n, texel(i), 0);
    let f = forces[i];
    let phase = bitcast<u32>(p.w);
    let ph = params.phases[phase];
    // dt_update has counted this step already.
    let euler = (state.step_base + state.steps - 1u) % params.euler_every == 0u;
    var base = vel_rho_before[i];
    var span = state.dt_prev + dt;
    if (euler) {
        base = vr;
        span = dt;
    }
    var rho = base.w + span * f.w;
    if (ph.mobile < 0.5) {
        rho = wall_density(rho, f.w, phase);
    } else if (held_bed_is_wall() && is_held(ids_n[i])) {
        // A held bed that stands as a wall takes its force pass's density (bed_wall in
        // integrate.rs).
        rho = max(f.w, ph.rho0);
    }
    ids_out[i] = ids_n[i];
    // Held sediment is at rest in both interleaved sequences: a particle held at n and
    // released at n + 1 must not take back the velocity it had at n - 1.
    let held = ph.mobile > 0.5 && is_held(ids_n[i]);
    vel_rho_prev_out[i] = select(vr, vec4<f32>(0.0, 0.0, 0.0, vr.w), held);
    let x = p.xyz + dt * vr.xyz + (0.5 * dt * dt) * f.xyz;
    store_state(i, ids_n[i], p, vr, x, base.xyz + span * f.xyz, rho);
}
