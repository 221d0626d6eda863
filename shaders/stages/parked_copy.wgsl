// Copies an open flume's parked particles, which the sort put after every cell, from the step's
// sorted copy back into the state buffers: the integrators write the new state in cell order
// but run over the active particles only, so the tail of that order is filled here. Dispatched
// over the parked particles only. A parked particle has no region (the rheology pass never
// sees it) and passes no bed load on, as the CPU backend has it.

@group(0) @binding(1) var<storage, read_write> state: StepState;
@group(0) @binding(2) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(3) var positions_n: texture_2d<f32>;
@group(0) @binding(4) var vel_rho_n: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> ids_n: array<u32>;
@group(0) @binding(6) var<storage, read_write> positions_out: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> vel_rho_out: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> ids_out: array<u32>;
@group(0) @binding(9) var<storage, read_write> vel_rho_prev_out: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> regions: array<u32>;

@compute @workgroup_size(128)
fn parked_copy(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = cell_starts[params.n_cells] + gid.x;
    // An idle step leaves the state in the order of the step before: the integrators wrote
    // nothing, so neither may this.
    if (k >= params.n_particles || state.dt == 0.0) {
        return;
    }
    let vr = textureLoad(vel_rho_n, texel(k), 0);
    positions_out[k] = textureLoad(positions_n, texel(k), 0);
    vel_rho_out[k] = vr;
    ids_out[k] = ids_n[k];
    // At rest in both of Verlet's sequences, as the inlet places it.
    vel_rho_prev_out[k] = vr;
    regions[ids_n[k]] = 0u;
    // Nor any bed load passed on, in either step's slot (NO_FLUX; REGION_SLOTS of state.rs).
    let no_flux = bitcast<u32>(-1.0);
    regions[params.n_particles + ids_n[k]] = no_flux;
    regions[2u * params.n_particles + ids_n[k]] = no_flux;
}
