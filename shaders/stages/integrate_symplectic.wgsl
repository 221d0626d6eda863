// Symplectic position-Verlet time integration as in DualSPHysics (two half steps per step).
// Walls (DBC) keep position and velocity; their density never drops below rho0 so that they
// never pull fluid in. Reference: solver/src/physics/integrate.rs.

@group(0) @binding(1) var<storage, read_write> state: StepState;
@group(0) @binding(2) var<storage, read> forces: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> positions_n: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> vel_rho_n: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> ids_n: array<u32>;
@group(0) @binding(6) var<storage, read_write> positions_half: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> vel_rho_half: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> positions_out: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> vel_rho_out: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read_write> ids_out: array<u32>;

// x(n+1/2) = x(n) + dt/2 v(n), v(n+1/2) = v(n) + dt/2 a(n), rho(n+1/2) = rho(n) + dt/2 drho(n).
@compute @workgroup_size(128)
fn predictor(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_particles) {
        return;
    }
    let half_dt = 0.5 * state.dt;
    let p = positions_n[i];
    let vr = vel_rho_n[i];
    let f = forces[i];
    let phase = bitcast<u32>(p.w);
    var rho = vr.w + half_dt * f.w;
    if (params.phases[phase].mobile > 0.5) {
        positions_half[i] = vec4<f32>(p.xyz + half_dt * vr.xyz, p.w);
        vel_rho_half[i] = vec4<f32>(vr.xyz + half_dt * f.xyz, rho);
    } else {
        positions_half[i] = p;
        vel_rho_half[i] = vec4<f32>(vr.xyz, max(rho, params.phases[phase].rho0));
    }
}

// v(n+1) = v(n) + dt a(n+1/2), x(n+1) = x(n) + dt (v(n) + v(n+1)) / 2,
// rho(n+1) = rho(n) (2 - eps) / (2 + eps) with eps = -dt drho(n+1/2) / rho(n+1/2).
@compute @workgroup_size(128)
fn corrector(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.n_particles) {
        return;
    }
    let dt = state.dt;
    let p = positions_n[i];
    let vr = vel_rho_n[i];
    let f = forces[i];
    let phase = bitcast<u32>(p.w);
    let ph = params.phases[phase];
    let eps = -(f.w / vel_rho_half[i].w) * dt;
    var rho = vr.w * (2.0 - eps) / (2.0 + eps);
    ids_out[i] = ids_n[i];
    if (ph.mobile > 0.5) {
        let v = vr.xyz + dt * f.xyz;
        let x = p.xyz + dt * 0.5 * (vr.xyz + v);
        positions_out[i] = vec4<f32>(x, p.w);
        vel_rho_out[i] = vec4<f32>(v, rho);
        var flags = 0u;
        let s = dot(x, x) + dot(v, v) + rho;
        // NaN compares false with everything; infinities exceed the largest finite f32.
        if (!(abs(s) <= 3.0e38)) {
            flags |= STATUS_NON_FINITE;
        } else if (abs(rho / ph.rho0 - 1.0) > params.rho_ratio_max) {
            flags |= STATUS_DENSITY_RUNAWAY;
        }
        if (flags != 0u) {
            atomicOr(&state.status, flags);
        }
    } else {
        positions_out[i] = p;
        vel_rho_out[i] = vec4<f32>(vr.xyz, max(rho, ph.rho0));
    }
}
