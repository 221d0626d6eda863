// Gathers the particle state into cell order, so that neighbours are adjacent in memory, into
// the textures the neighbour loops read.

@group(0) @binding(1) var<storage, read> sorted_index: array<u32>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> vel_rho: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> ids: array<u32>;
@group(0) @binding(5) var sorted_positions: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var sorted_vel_rho: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var<storage, read_write> sorted_ids: array<u32>;
@group(0) @binding(8) var<storage, read> vel_rho_prev: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> sorted_vel_rho_prev: array<vec4<f32>>;

// Only the Verlet integrator needs the previous step's velocity and density.
override WITH_PREVIOUS: bool = false;

@compute @workgroup_size(128)
fn reorder(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_particles) {
        return;
    }
    let src = sorted_index[k];
    textureStore(sorted_positions, texel(k), positions[src]);
    textureStore(sorted_vel_rho, texel(k), vel_rho[src]);
    sorted_ids[k] = ids[src];
    if (WITH_PREVIOUS) {
        sorted_vel_rho_prev[k] = vel_rho_prev[src];
    }
}
