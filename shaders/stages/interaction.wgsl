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

// Particle i as its neighbour sums read it: position (phase in w), velocity, density, phase,
// whether it moves (held sand standing as a wall does not), whether it is held fixed where it
// stands (the Shields-only mode's held sand where it is not a wall: only its density rate is
// summed, and it does not bound the step; `Side::fixed` in interaction/mod.rs), its momentum
// pressure over rho^2,
// rest density, Tait coefficient, viscosity and stress over rho^2; whether held sand is a wall
// and the reach of its contact force, squared.
struct Own {
    pos: vec4<f32>,
    vel: vec3<f32>,
    rho: f32,
    phase: u32,
    mobile: bool,
    fixed: bool,
    press: f32,
    rho0: f32,
    b: f32,
    mu: f32,
    tau: mat3x3<f32>,
    bed_walls: bool,
    bed_r0_2: f32,
}

fn own(i: u32) -> Own {
    var o: Own;
    o.pos = textureLoad(positions, texel(i), 0);
    let vr = textureLoad(vel_rho, texel(i), 0);
    o.vel = vr.xyz;
    o.rho = vr.w;
    o.phase = bitcast<u32>(o.pos.w);
    // Held sediment may stand as a wall (cpu/step.rs, bed_is_boundary).
    o.bed_walls = held_bed_is_wall();
    if (o.bed_walls) {
        o.bed_r0_2 = bed_contact_r0_2();
    }
    // The hold matters to a wall of held sand and to the Shields-only mode's fixed sand only.
    let held = (o.bed_walls || params.sediment.shields_only != 0u) && held_here(i);
    o.mobile = params.phases[o.phase].mobile > 0.5 && !(o.bed_walls && held);
    // Only the Shields-only mode's holds: a Drucker-Prager hold may be released after the
    // rheology pass wrote this word (hold.wgsl).
    o.fixed = o.mobile && held && !o.bed_walls && params.sediment.shields_only != 0u;
    o.press = momentum_pressure(o.rho, o.phase) / (o.rho * o.rho);
    o.rho0 = params.phases[o.phase].rho0;
    o.b = params.tait_b[o.phase];
    o.mu = params.phases[o.phase].mu;
    if (params.viscosity_mode == VISCOSITY_MULTIPHASE && o.mobile) {
        o.tau = stress_over_rho2(i, o.rho);
    }
    return o;
}

// What particle i gathers from its neighbours: acceleration, density rate, the largest
// |mu_ij|, and a wall's sums of the generalised wall condition (physics/boundary.rs).
struct Sums {
    acc: vec3<f32>,
    drho: f32,
    visc_max: f32,
    wall_w: f32,
    wall_pw: f32,
    wall_rho_r: vec3<f32>,
}

// Neighbour j as particle i sees it: its phase, whether it moves, the offset and velocity
// difference (i minus j), r^2, the kernel's gradient factor, the mass and density (a wall's
// scaled to i's phase), its momentum pressure over rho^2, v.r and the viscous mu_ij of
// Monaghan's term.
struct Neighbour {
    j: u32,
    phase: u32,
    mobile: bool,
    dx: vec3<f32>,
    dv: vec3<f32>,
    r2: f32,
    f: f32,
    m: f32,
    rho: f32,
    press: f32,
    vdotr: f32,
    mu_ij: f32,
}

// Density diffusion's rate from a neighbour of i's phase, `dz` above it (Fourtakas et al.'s
// hydrostatic correction in mode 2).
fn diffusion_rate(o: Own, n: Neighbour, dz: f32) -> f32 {
    var rho_h = 0.0;
    if (params.diffusion_mode == 2u) {
        // (1 + x)^(1/7) - 1 by its series: x = 7 g dz / c0^2 is below 1e-3 for neighbours
        // (dz < 2h), where three terms are exact in f32; pow is not cheap.
        let x = o.rho0 * params.gravity.w * dz / o.b;
        rho_h = o.rho0 * x * (1.0 / 7.0 + x * (-3.0 / 49.0 + x * (13.0 / 343.0)));
    }
    return params.delta_h_c0 * 2.0 * (n.rho - o.rho - rho_h) * (-n.r2 * n.f) / (n.r2 + params.eta2) * (n.m / n.rho);
}

// The pressure and viscous acceleration of mobile particle i from neighbour n.
fn pair_acc(o: Own, n: Neighbour) -> vec3<f32> {
    var coef = -n.m * (o.press + n.press);
    if (params.viscosity_mode == 0u || params.viscosity_mode == VISCOSITY_MULTIPHASE) {
        if (n.vdotr < 0.0) {
            let pi_ij = -params.alpha * params.c0 * n.mu_ij / (0.5 * (o.rho + n.rho));
            coef -= n.m * pi_ij;
        }
    }
    if (params.viscosity_mode == 0u) {
        return coef * n.f * n.dx;
    }
    if (params.viscosity_mode == VISCOSITY_MULTIPHASE) {
        var tau = o.tau;
        if (n.mobile) {
            tau += stress_over_rho2(n.j, n.rho);
        }
        return coef * n.f * n.dx + (n.m * n.f) * (tau * n.dx);
    }
    let mu_j = params.phases[n.phase].mu;
    return coef * n.f * n.dx + (n.m * (o.mu + mu_j) * (n.r2 * n.f) / (o.rho * n.rho * (n.r2 + params.eta2))) * n.dv;
}

// Adds neighbour j (sorted order) to particle i's sums.
fn add_neighbour(sums: ptr<function, Sums>, o: Own, j: u32) {
    let h = params.h;
    let pos_j = textureLoad(positions, texel(j), 0);
    var n: Neighbour;
    n.j = j;
    n.dx = o.pos.xyz - pos_j.xyz;
    n.r2 = dot(n.dx, n.dx);
    if (n.r2 >= 4.0 * h * h || n.r2 < 1e-12 * h * h) {
        return;
    }
    n.phase = bitcast<u32>(pos_j.w);
    n.mobile = params.phases[n.phase].mobile > 0.5 && !(o.bed_walls && held_here(j));
    if (!o.mobile && !n.mobile) {
        return;
    }
    let vr_j = textureLoad(vel_rho, texel(j), 0);
    n.dv = o.vel - vr_j.xyz;
    n.f = kernel_grad_factor(sqrt(n.r2));
    // A wall seen from a fluid particle stands in for that fluid (`wall_scale` in
    // interaction.rs): its mass and density scaled by the ratio of rest densities.
    var scale = 1.0;
    if (o.mobile && !n.mobile) {
        scale = o.rho0 / params.phases[n.phase].rho0;
    }
    n.m = params.phases[n.phase].mass * scale;
    n.rho = vr_j.w * scale;
    n.vdotr = dot(n.dv, n.dx);
    (*sums).drho += n.m * n.vdotr * n.f;
    if (!o.mobile) {
        if (params.boundary_mode == BOUNDARY_GENERALISED && !velocity_imposed(pos_j.xyz, n.phase)) {
            let w = kernel_w(sqrt(n.r2));
            (*sums).wall_w += w;
            (*sums).wall_pw += momentum_pressure(vr_j.w, n.phase) * w;
            (*sums).wall_rho_r += vr_j.w * n.dx * w;
        }
        return;
    }
    if (params.diffusion_mode != 0u && n.mobile && n.phase == o.phase) {
        let dz = o.pos[params.vertical_axis] - pos_j[params.vertical_axis];
        (*sums).drho += diffusion_rate(o, n, dz);
    }
    // A fixed particle's acceleration is never read.
    if (o.fixed) {
        return;
    }
    // Only held sand is a wall of a mobile phase.
    if (o.bed_walls && !n.mobile && params.phases[n.phase].mobile > 0.5 && n.phase != o.phase) {
        (*sums).acc += bed_contact(n.r2, o.bed_r0_2) * n.dx;
    }
    n.press = momentum_pressure(vr_j.w, n.phase) / (n.rho * n.rho);
    n.mu_ij = h * n.vdotr / (n.r2 + params.eta2);
    (*sums).visc_max = max((*sums).visc_max, abs(n.mu_ij));
    (*sums).acc += pair_acc(o, n);
}

// A wall's density under the generalised condition: that of the fluid's pressure around it,
// rest density with no fluid near.
fn generalised_wall_density(sums: Sums, rho0: f32, b: f32) -> f32 {
    if (sums.wall_w <= 0.0) {
        return rho0;
    }
    let p = (sums.wall_pw + dot(params.gravity.xyz, sums.wall_rho_r)) / sums.wall_w;
    return rho0 * pow(max(1.0 + p / b, 0.0), 1.0 / 7.0);
}

// Mobile particle i's stable step from its acceleration and largest mu_ij, and in the
// multiphase mode its own apparent viscosity's explicit limit.
fn particle_step(i: u32, o: Own, acc: vec3<f32>, visc_max: f32) -> f32 {
    let force_bound = !velocity_imposed(o.pos.xyz, o.phase);
    var dt_i = stable_step(params.h, params.c0, length(acc), force_bound, visc_max);
    if (params.viscosity_mode == VISCOSITY_MULTIPHASE) {
        let mu_app = textureLoad(stress_b, texel(i), 0).z;
        dt_i = min(dt_i, viscous_step(params.h, o.rho, mu_app));
    }
    return dt_i;
}

@compute @workgroup_size(64)
fn interaction(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // Dispatched over the active particles (cell_starts[n_cells]: parked ones sort after every
    // cell and are in no stencil), rounded up to whole workgroups.
    if (i >= cell_starts[params.n_cells] || chunk_idle(REDUCE_DT)) {
        return;
    }
    let o = own(i);
    var sums: Sums;
    let cell = cell_coords(o.pos.xyz);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            add_neighbour(&sums, o, j);
        }
    }
    var dt_i = 3.0e38;
    var acc = vec3<f32>(0.0);
    var drho = sums.drho;
    if (o.mobile && !o.fixed) {
        acc = sums.acc + params.gravity.xyz;
        dt_i = particle_step(i, o, acc, sums.visc_max);
    } else if (!o.mobile && params.boundary_mode == BOUNDARY_GENERALISED) {
        // The wall's density in place of its rate.
        drho = generalised_wall_density(sums, o.rho0, o.b);
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
