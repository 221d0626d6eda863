// Kernel sums at probe points: sum_j V_j p_j W (Shepard-corrected pressure) and the "fullness"
// sum_j V_j W of each fluid phase (phases 1-3), whose total places the free surface (as
// DualSPHysics' SWL gauge) and each of which places the top of its own layer. A case with a
// sediment has two fluid phases; the third slot then holds the fullness of the immobile
// (region 1) sediment, whose top is the bed interface Zb.
// Reference: physics/probe.rs.

@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var vel_rho: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(4) var<storage, read> probe_points: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> probe_sums: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> ids: array<u32>;
@group(0) @binding(7) var<storage, read> regions: array<u32>;

// REGION_UNYIELDED of shaders/common/sediment.wgsl, as a word (checked by solver/tests/shaders_validate.rs).
const REGION_UNYIELDED_WORD: u32 = 1u;

@compute @workgroup_size(64)
fn probe_interpolate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= params.n_probes) {
        return;
    }
    let x = probe_points[k].xyz;
    let four_h2 = 4.0 * params.h * params.h;
    // x: pressure sum; y, z, w: fullness of phases 1, 2, 3.
    var sums = vec4<f32>(0.0);
    let cell = cell_coords(x);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            let pos_j = textureLoad(positions, texel(j), 0);
            let dx = x - pos_j.xyz;
            let r2 = dot(dx, dx);
            let phase_j = bitcast<u32>(pos_j.w);
            if (r2 >= four_h2 || params.phases[phase_j].mobile < 0.5) {
                continue;
            }
            let rho_j = textureLoad(vel_rho, texel(j), 0).w;
            let vw = params.phases[phase_j].mass / rho_j * kernel_w(sqrt(r2));
            sums.x += vw * tait_pressure(rho_j, phase_j);
            sums[phase_j] += vw;
            let sediment = params.sediment.phase;
            if (sediment != 0u && phase_j == sediment && (regions[ids[j]] & 255u) == REGION_UNYIELDED_WORD) {
                sums.w += vw;
            }
        }
    }
    probe_sums[k] = sums;
}
