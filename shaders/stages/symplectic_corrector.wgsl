// Symplectic position-Verlet integration as in DualSPHysics, second half step:
// v(n+1) = v(n) + dt a(n+1/2), x(n+1) = x(n) + dt (v(n) + v(n+1)) / 2,
// rho(n+1) = rho(n) (2 - eps) / (2 + eps) with eps = -dt drho(n+1/2) / rho(n+1/2).
// Writes the new state, in cell order, back to the state buffers, and raises health flags;
// runs over the active particles only (`parked_copy` writes the parked ones).
// Reference: solver/src/physics/integrate.rs.

@group(0) @binding(1) var<storage, read_write> state: StepState;
@group(0) @binding(2) var<storage, read> forces: array<vec4<f32>>;
@group(0) @binding(3) var positions_n: texture_2d<f32>;
@group(0) @binding(4) var vel_rho_n: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> ids_n: array<u32>;
@group(0) @binding(6) var vel_rho_half: texture_2d<f32>;
@group(0) @binding(7) var<storage, read_write> positions_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> vel_rho_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> ids_out: array<u32>;
@group(0) @binding(10) var<storage, read> regions: array<u32>;
@group(0) @binding(11) var<storage, read> cell_starts: array<u32>;

@compute @workgroup_size(128)
fn symplectic_corrector(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // An idle step (past the chunk's end, or after a blow-up) leaves the state as it is.
    if (i >= cell_starts[params.n_cells] || state.dt == 0.0) {
        return;
    }
    let dt = state.dt;
    let p = textureLoad(positions_n, texel(i), 0);
    let vr = textureLoad(vel_rho_n, texel(i), 0);
    let f = forces[i];
    let phase = bitcast<u32>(p.w);
    let ph = params.phases[phase];
    let eps = -(f.w / textureLoad(vel_rho_half, texel(i), 0).w) * dt;
    var rho = vr.w * (2.0 - eps) / (2.0 + eps);
    if (ph.mobile < 0.5) {
        rho = wall_density(rho, f.w, phase);
    } else if (held_bed_is_wall() && is_held(ids_n[i])) {
        // A held bed that stands as a wall takes its force pass's density (bed_wall in
        // integrate.rs).
        rho = max(f.w, ph.rho0);
    }
    ids_out[i] = ids_n[i];
    let v = vr.xyz + dt * f.xyz;
    store_state(i, ids_n[i], p, vr, p.xyz + dt * 0.5 * (vr.xyz + v), v, rho);
}
