// Symplectic position-Verlet integration as in DualSPHysics, first half step:
// x(n+1/2) = x(n) + dt/2 v(n), v(n+1/2) = v(n) + dt/2 a(n), rho(n+1/2) = rho(n) + dt/2 drho(n).
// Walls (DBC) keep position and velocity; their density never drops below rho0 so that they
// never pull fluid in; held sediment stays at rest; an open flume's inlet buffer moves at the
// inlet velocity. Runs over the active particles only: an open flume's parked ones sort after
// every cell and nothing moves them. Reference: solver/src/physics/integrate.rs.

@group(0) @binding(1) var<storage, read_write> state: StepState;
@group(0) @binding(2) var<storage, read> forces: array<vec4<f32>>;
@group(0) @binding(3) var positions_n: texture_2d<f32>;
@group(0) @binding(4) var vel_rho_n: texture_2d<f32>;
@group(0) @binding(5) var positions_half: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var vel_rho_half: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var<storage, read> regions: array<u32>;
@group(0) @binding(8) var<storage, read> ids_n: array<u32>;
@group(0) @binding(9) var<storage, read> cell_starts: array<u32>;

// REGION_HELD of shaders/common/sediment.wgsl (checked by solver/tests/shaders_validate.rs).
const REGION_HELD_BIT: u32 = 256u;

@compute @workgroup_size(128)
fn symplectic_predictor(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // An idle step (past the chunk's end, or after a blow-up) leaves the state as it is.
    if (i >= cell_starts[params.n_cells] || state.dt == 0.0) {
        return;
    }
    let half_dt = 0.5 * state.dt;
    let p = textureLoad(positions_n, texel(i), 0);
    let vr = textureLoad(vel_rho_n, texel(i), 0);
    let f = forces[i];
    let phase = bitcast<u32>(p.w);
    let rho = vr.w + half_dt * f.w;
    if (carried_by_inlet(p.xyz, phase)) {
        // The inlet buffer moves at the inlet velocity, at its density (store_rule.wgsl).
        let u = vec3<f32>(params.flume.inlet_u, 0.0, 0.0);
        textureStore(positions_half, texel(i), vec4<f32>(p.xyz + half_dt * u, p.w));
        textureStore(vel_rho_half, texel(i), vec4<f32>(u, inlet_density(vr.w, rho, phase)));
    } else if (params.phases[phase].mobile > 0.5 && (regions[ids_n[i]] & REGION_HELD_BIT) != 0u) {
        // A held bed that stands as a wall takes its force pass's density (bed_wall in
        // integrate.rs).
        let r = select(rho, max(f.w, params.phases[phase].rho0), held_bed_is_wall());
        textureStore(positions_half, texel(i), p);
        textureStore(vel_rho_half, texel(i), vec4<f32>(0.0, 0.0, 0.0, r));
    } else if (params.phases[phase].mobile > 0.5) {
        textureStore(positions_half, texel(i), vec4<f32>(p.xyz + half_dt * vr.xyz, p.w));
        let r = clamped_density(rho, phase);
        textureStore(vel_rho_half, texel(i), vec4<f32>(vr.xyz + half_dt * f.xyz, r));
    } else {
        textureStore(positions_half, texel(i), p);
        textureStore(vel_rho_half, texel(i), vec4<f32>(vr.xyz, wall_density(rho, f.w, phase)));
    }
}
