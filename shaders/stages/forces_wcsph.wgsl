// Weakly compressible SPH interaction (Eqs. 9-10 with the Tait pressure of Eq. 4):
// continuity with density diffusion (Molteni & Colagrossi 2009; hydrostatic correction of
// Fourtakas et al. 2019), pressure gradient, artificial (Monaghan 1992) or laminar (Morris et
// al. 1997) viscosity or the divergence of the viscous stress of the rheology pass (multiphase,
// Eq. 10 with sigma = -p I + tau), gravity; DBC walls (Crespo et al. 2007) only gather density,
// or under the generalised wall condition (Adami et al. 2012) the fluid's pressure around them,
// and get the density that gives it in place of a rate; so does held sediment in the
// Shields-only mode under that condition.
// Also the per-particle stable step of the variable time step, min-reduced into `state`.
// Reference: solver/src/physics/interaction.rs.

@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var vel_rho: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(4) var<storage, read_write> forces: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> state: StepState;
@group(0) @binding(6) var stress_a: texture_2d<f32>;
@group(0) @binding(7) var stress_b: texture_2d<f32>;

// The modes of solver/src/contract/blocks.rs (checked by solver/tests/shaders_validate.rs).
const VISCOSITY_MULTIPHASE: u32 = 2u;
const BOUNDARY_GENERALISED: u32 = 1u;

// The pressure of the momentum equation: Tait's, without tension when the case says so.
fn momentum_pressure(rho: f32, phase: u32) -> f32 {
    let p = tait_pressure(rho, phase);
    return select(p, max(p, 0.0), params.clamp_pressure != 0u);
}

// A particle's viscous stress over rho^2 from the rheology pass's (xx, xy, xz, yy) and
// (yz, zz, mu, region word) texels.
fn stress_over_rho2(i: u32, rho: f32) -> mat3x3<f32> {
    let a = textureLoad(stress_a, texel(i), 0);
    let b = textureLoad(stress_b, texel(i), 0);
    return mat3x3<f32>(a.xyz, vec3<f32>(a.y, a.w, b.x), vec3<f32>(a.z, b.x, b.y)) * (1.0 / (rho * rho));
}

// The held bed's contact force reaches CONTACT_REACH dp (`CONTACT_REACH` in interaction/mod.rs).
const CONTACT_REACH: f32 = 0.6;

// r0^2 = (CONTACT_REACH dp)^2, dp from the sand's particle volume (`PhaseConsts::contact2` in
// interaction/mod.rs).
fn bed_contact_r0_2() -> f32 {
    let sand = params.phases[params.sediment.phase];
    let v0 = sand.mass / sand.rho0;
    let dp2 = select(pow(v0, 2.0 / 3.0), v0, params.vertical_axis == 1u);
    return CONTACT_REACH * CONTACT_REACH * dp2;
}

// The contact force per unit mass of a held-bed particle on a particle of another phase r2
// away, over x_ij (`add_contact` in interaction/mod.rs): Monaghan's (1994) D ((r0 / r)^12 -
// (r0 / r)^4) / r^2 within r0, D = (c0 / 10)^2.
fn bed_contact(r2: f32, r0_2: f32) -> f32 {
    if (r2 >= r0_2) {
        return 0.0;
    }
    let q2 = r0_2 / r2;
    let q4 = q2 * q2;
    return 0.01 * params.c0 * params.c0 * (q4 * q4 * q4 - q4) / r2;
}

// Whether the rheology pass held particle i (sorted order) fixed: its region word is the stress
// texel's w.
fn held_here(i: u32) -> bool {
    return (u32(textureLoad(stress_b, texel(i), 0).w) & REGION_HELD) != 0u;
}

// The corrector's half-step forces do not set the step: only the predictor's do (DualSPHysics).
override REDUCE_DT: bool = true;

@compute @workgroup_size(64)
fn forces_wcsph(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // Dispatched over the active particles (cell_starts[n_cells]: parked ones sort after every
    // cell and are in no stencil), rounded up to whole workgroups.
    if (i >= cell_starts[params.n_cells] || chunk_idle(REDUCE_DT)) {
        return;
    }
    let pos_i = textureLoad(positions, texel(i), 0);
    let vr_i = textureLoad(vel_rho, texel(i), 0);
    let phase_i = bitcast<u32>(pos_i.w);
    // Held sediment may stand as a wall (cpu/step.rs, bed_is_boundary).
    let bed_walls = held_bed_is_wall();
    var bed_r0_2 = 0.0;
    if (bed_walls) {
        bed_r0_2 = bed_contact_r0_2();
    }
    let mobile_i = params.phases[phase_i].mobile > 0.5 && !(bed_walls && held_here(i));
    let rho_i = vr_i.w;
    let press_i = momentum_pressure(rho_i, phase_i) / (rho_i * rho_i);
    let h = params.h;
    let four_h2 = 4.0 * h * h;
    let r2_min = 1e-12 * h * h;
    let vert = params.vertical_axis;
    let g_vert = params.gravity.w;
    let rho0_i = params.phases[phase_i].rho0;
    let b_i = params.tait_b[phase_i];
    let mu_i = params.phases[phase_i].mu;
    let multiphase = params.viscosity_mode == VISCOSITY_MULTIPHASE;
    var tau_i = mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    if (multiphase && mobile_i) {
        tau_i = stress_over_rho2(i, rho_i);
    }

    var acc = vec3<f32>(0.0);
    var drho = 0.0;
    var visc_max = 0.0;
    // A wall's sums of the generalised wall condition (physics/boundary.rs).
    let generalised = params.boundary_mode == BOUNDARY_GENERALISED;
    var wall_w = 0.0;
    var wall_pw = 0.0;
    var wall_rho_r = vec3<f32>(0.0);
    let cell = cell_coords(pos_i.xyz);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            let pos_j = textureLoad(positions, texel(j), 0);
            let dx = pos_i.xyz - pos_j.xyz;
            let r2 = dot(dx, dx);
            if (r2 >= four_h2 || r2 < r2_min) {
                continue;
            }
            let phase_j = bitcast<u32>(pos_j.w);
            let mobile_j = params.phases[phase_j].mobile > 0.5 && !(bed_walls && held_here(j));
            if (!mobile_i && !mobile_j) {
                continue;
            }
            let vr_j = textureLoad(vel_rho, texel(j), 0);
            let dv = vr_i.xyz - vr_j.xyz;
            let f = kernel_grad_factor(sqrt(r2));
            // A wall seen from a fluid particle stands in for that fluid (`wall_scale` in
            // interaction.rs): its mass and density scaled by the ratio of rest densities.
            var scale = 1.0;
            if (mobile_i && !mobile_j) {
                scale = rho0_i / params.phases[phase_j].rho0;
            }
            let m_j = params.phases[phase_j].mass * scale;
            let rho_j = vr_j.w * scale;
            let vdotr = dot(dv, dx);
            drho += m_j * vdotr * f;
            if (!mobile_i) {
                if (generalised && !velocity_imposed(pos_j.xyz, phase_j)) {
                    let w = kernel_w(sqrt(r2));
                    wall_w += w;
                    wall_pw += momentum_pressure(vr_j.w, phase_j) * w;
                    wall_rho_r += vr_j.w * dx * w;
                }
                continue;
            }
            // Only held sand is a wall of a mobile phase.
            if (bed_walls && !mobile_j && params.phases[phase_j].mobile > 0.5 && phase_j != phase_i) {
                acc += bed_contact(r2, bed_r0_2) * dx;
            }
            if (params.diffusion_mode != 0u && mobile_j && phase_j == phase_i) {
                var rho_h = 0.0;
                if (params.diffusion_mode == 2u) {
                    let dz = pos_i[vert] - pos_j[vert];
                    // (1 + x)^(1/7) - 1 by its series: x = 7 g dz / c0^2 is below 1e-3 for
                    // neighbours (dz < 2h), where three terms are exact in f32; pow is not cheap.
                    let x = rho0_i * g_vert * dz / b_i;
                    rho_h = rho0_i * x * (1.0 / 7.0 + x * (-3.0 / 49.0 + x * (13.0 / 343.0)));
                }
                drho += params.delta_h_c0 * 2.0 * (rho_j - rho_i - rho_h) * (-r2 * f) / (r2 + params.eta2) * (m_j / rho_j);
            }
            let press_j = momentum_pressure(vr_j.w, phase_j) / (rho_j * rho_j);
            var coef = -m_j * (press_i + press_j);
            let mu_ij = h * vdotr / (r2 + params.eta2);
            visc_max = max(visc_max, abs(mu_ij));
            if (params.viscosity_mode == 0u) {
                if (vdotr < 0.0) {
                    let pi_ij = -params.alpha * params.c0 * mu_ij / (0.5 * (rho_i + rho_j));
                    coef -= m_j * pi_ij;
                }
                acc += coef * f * dx;
            } else if (multiphase) {
                if (vdotr < 0.0) {
                    let pi_ij = -params.alpha * params.c0 * mu_ij / (0.5 * (rho_i + rho_j));
                    coef -= m_j * pi_ij;
                }
                var tau = tau_i;
                if (mobile_j) {
                    tau += stress_over_rho2(j, rho_j);
                }
                acc += coef * f * dx + (m_j * f) * (tau * dx);
            } else {
                let mu_j = params.phases[phase_j].mu;
                acc += coef * f * dx + (m_j * (mu_i + mu_j) * (r2 * f) / (rho_i * rho_j * (r2 + params.eta2))) * dv;
            }
        }
    }
    var dt_i = 3.0e38;
    if (mobile_i) {
        acc += params.gravity.xyz;
        let force_bound = !velocity_imposed(pos_i.xyz, phase_i);
        dt_i = stable_step(h, params.c0, length(acc), force_bound, visc_max);
        if (multiphase) {
            // The explicit viscous limit with the particle's own apparent viscosity.
            let mu_app = textureLoad(stress_b, texel(i), 0).z;
            dt_i = min(dt_i, viscous_step(h, rho_i, mu_app));
        }
    } else {
        acc = vec3<f32>(0.0);
        if (generalised) {
            // The wall's density in place of its rate: that of the fluid's pressure around it.
            drho = rho0_i;
            if (wall_w > 0.0) {
                let p = (wall_pw + dot(params.gravity.xyz, wall_rho_r)) / wall_w;
                drho = rho0_i * pow(max(1.0 + p / b_i, 0.0), 1.0 / 7.0);
            }
        }
    }
    forces[i] = vec4<f32>(acc, drho);
    if (REDUCE_DT) {
        // Most particles are not the minimum: read first, so few of them touch the atomic.
        let bits = bitcast<u32>(dt_i);
        if (bits < atomicLoad(&state.dt_min_bits)) {
            atomicMin(&state.dt_min_bits, bits);
        }
    }
}
