// Release of held sediment (Drucker-Prager mode), after each rheology pass: a held particle
// yields when the stress its moving sediment neighbours carry, their Shepard average
// sum_j V_j W_ij tau_j / sum_j V_j W_ij, exceeds the stress at which its HBP law flows,
// FLOW_ONSET times its yield stress (Eqs. 15, 30-31; hold.rs says why); it then becomes region
// 2 and moves. Which neighbours move is read from the rheology pass's region
// word in stress_b.w, which this stage does not write, so the result does not depend on the
// order threads run. Reference: solver/src/physics/sediment/hold.rs.

@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var vel_rho: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(4) var<storage, read_write> state: StepState;
@group(0) @binding(5) var stress_a: texture_2d<f32>;
@group(0) @binding(6) var stress_b: texture_2d<f32>;
@group(0) @binding(7) var<storage, read_write> regions: array<u32>;
@group(0) @binding(8) var<storage, read> ids: array<u32>;

// FLOW_ONSET of solver/src/physics/sediment/hold.rs (checked by solver/tests/shaders_validate.rs).
const FLOW_ONSET: f32 = 2.0;

// As the rheology pass it follows.
override BEFORE_DT: bool = true;

fn held_in_rheology(i: u32) -> bool {
    return (u32(textureLoad(stress_b, texel(i), 0).w) & REGION_HELD) != 0u;
}

@compute @workgroup_size(64)
fn hold(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let sd = params.sediment;
    // Over the active particles only, as the force pass.
    if (i >= cell_starts[params.n_cells] || sd.shields_only != 0u || chunk_idle(BEFORE_DT)) {
        return;
    }
    let pos_i = textureLoad(positions, texel(i), 0);
    if (bitcast<u32>(pos_i.w) != sd.phase || !held_in_rheology(i)) {
        return;
    }
    let h = params.h;
    let four_h2 = 4.0 * h * h;
    let mass = params.phases[sd.phase].mass;
    var weight = 0.0;
    // Symmetric: (xx, xy, xz, yy) and (yz, zz).
    var sum_a = vec4<f32>(0.0);
    var sum_b = vec2<f32>(0.0);
    let cell = cell_coords(pos_i.xyz);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            let pos_j = textureLoad(positions, texel(j), 0);
            let dx = pos_i.xyz - pos_j.xyz;
            let r2 = dot(dx, dx);
            if (j == i || r2 >= four_h2 || bitcast<u32>(pos_j.w) != sd.phase || held_in_rheology(j)) {
                continue;
            }
            let w = mass / textureLoad(vel_rho, texel(j), 0).w * kernel_w(sqrt(r2));
            weight += w;
            sum_a += w * textureLoad(stress_a, texel(j), 0);
            sum_b += w * textureLoad(stress_b, texel(j), 0).xy;
        }
    }
    if (!(weight > 0.0)) {
        return;
    }
    let a = sum_a / weight;
    let b = sum_b / weight;
    // J2 = 1/2 t_ab t_ab with each off-diagonal entry twice.
    let j2 = 0.5 * (a.x * a.x + a.w * a.w + b.y * b.y) + a.y * a.y + a.z * a.z + b.x * b.x;
    let rho_i = textureLoad(vel_rho, texel(i), 0).w;
    if (sqrt(j2) > FLOW_ONSET * drucker_prager_yield(rho_i)) {
        // Under Exner's balance a released particle carries what was worn off it (hold.rs).
        let exner = params.sediment.exner_step_per_stage > 0.0;
        let units = select(0u, regions[ids[i]] & ~((1u << PICKUP_SHIFT) - 1u), exner);
        regions[ids[i]] = REGION_YIELDED | units;
    }
}
