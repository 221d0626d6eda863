// Gathers the particle state into cell order, so that neighbours are adjacent in memory.

@group(0) @binding(1) var<storage, read> sorted_index: array<u32>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> vel_rho: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> ids: array<u32>;
@group(0) @binding(5) var<storage, read_write> sorted_positions: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> sorted_vel_rho: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> sorted_ids: array<u32>;

@compute @workgroup_size(128)
fn reorder(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_particles) {
        return;
    }
    let src = sorted_index[k];
    sorted_positions[k] = positions[src];
    sorted_vel_rho[k] = vel_rho[src];
    sorted_ids[k] = ids[src];
}
