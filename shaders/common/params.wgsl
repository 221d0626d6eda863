// Simulation parameters shared by every stage, laid out as `SimParams` of
// solver/src/contract/blocks.rs (solver/tests/shaders_validate.rs checks the two layouts agree). Lengths in m, times in s, densities in kg/m3.

struct Phase {
    rho0: f32,      // rest density of the Tait equation
    mass: f32,      // particle mass (per metre of width in 2-D)
    mu: f32,        // dynamic viscosity, Pa s
    mobile: f32,    // 1 for fluid, 0 for DBC wall particles
}

// The sediment phase (Zubeldia et al. 2018); phase == 0 when the case has none.
struct Sediment {
    phase: u32,              // index of the sediment in `phases`
    water_phase: u32,        // index of the water it lies in
    shields_only: u32,       // 1: Shields only, sediment not eroded or suspended is held fixed
    water_speed: u32,        // 1: Shields reads the water's own velocity, 0: relative to the grain
    rho_s: f32,              // saturated density, kg/m3
    rho_w: f32,              // water density, kg/m3
    d50: f32,                // median grain diameter, m
    nu_w: f32,               // water kinematic viscosity, m2/s
    mu_w: f32,               // water dynamic viscosity, Pa s (Vand, Eq. 33)
    mu_s: f32,               // HBP mu_s, Pa s
    hbp_m: f32,              // Papanastasiou m, s
    hbp_n: f32,              // power-law index n
    ks: f32,                 // equivalent roughness, m
    surface_mass: f32,       // m_f times the sediment particle mass (Eq. 26)
    dp_alpha: f32,           // Drucker-Prager alpha (Eq. 29)
    dp_kappa: f32,           // Drucker-Prager kappa_c, Pa (Eq. 29)
    phi: f32,                // internal friction angle, rad
    mu_max: f32,             // cap on the apparent viscosity, Pa s
    submerged_weight: f32,   // (rho_s - rho_w) |g|, N/m3 (Eq. 16 without theta and d)
    pickup_per_s: f32,       // van Rijn's pick-up rate per unit T^1.5, 1/s (0: Shields releases at once)
    pickup_integrated: u32,  // 1: a held particle leaves once the rate's integral has taken its mass
    exner_step_per_stage: f32, // van Rijn's saltation length per unit T^0.9 over dp (0: no deposition)
    dp: f32,                 // particle spacing, m
    rests_beside_solid: u32, // 1: a moving grain is held again only with a solid beside it
}

// The open flume (2-D); enabled == 0 for a closed tank.
struct Flume {
    enabled: u32,
    water_phase: u32,
    parked_phase: u32,       // phase of parked particles (out of the flow, never interacting)
    parking_cols: u32,       // parking spots per row
    inlet_x_face: f32,       // water with x below this, in the opening, is the inlet buffer, m
    inlet_y_min: f32,        // the opening, m (y_min < y <= y_max; the buffer's lattice rows
    inlet_y_max: f32,        // lie strictly inside it)
    inlet_u: f32,            // inlet velocity, m/s: Q / (opening height x flume width)
    outlet_x: f32,           // fluid past this x has left over the weir, m
    collector_x_min: f32,    // sediment in this box is eroded, m
    collector_x_max: f32,
    collector_y_max: f32,
    parking_x0: f32,         // spot of particle id k: x0 + (k % cols) dp, y0 + (k / cols) dp
    parking_y0: f32,
    parking_dp: f32,
    duct_x_min: f32,         // a bottom outlet's duct: water with x >= duct_x_min and
    duct_y_min: f32,         // duct_y_min < y <= duct_y_max moves at duct_u, m/s (a valve);
    duct_y_max: f32,         // an empty box (duct_y_max = duct_y_min) when there is none
    duct_u: f32,
    pad: f32,
}

struct SimParams {
    n_particles: u32,
    n_cells: u32,
    viscosity_mode: u32,     // 0 artificial (Monaghan 1992), 1 laminar (Morris 1997), 2 multiphase stress
    diffusion_mode: u32,     // 0 none, 1 Molteni-Colagrossi 2009, 2 Fourtakas 2019
    grid_dims: vec4<u32>,    // cells along x, y, z (z = 1 in 2-D)
    grid_origin: vec4<f32>,  // xyz of the grid corner, w = 1 / cell size
    gravity: vec4<f32>,      // xyz, w = |g| along the vertical axis
    h: f32,
    kernel_ad: f32,          // Wendland C2 normalisation a_d
    c0: f32,
    eta2: f32,               // 0.01 h^2, keeps 1 / r^2 finite
    delta_h_c0: f32,         // density-diffusion delta * h * c0
    alpha: f32,              // artificial viscosity coefficient
    cfl: f32,
    dt_visc: f32,            // viscous bound 0.125 h^2 rho0 / mu (laminar), else huge
    dt_min: f32,             // a step below this is a blow-up
    rho_ratio_max: f32,      // |rho / rho0 - 1| above this is a runaway density
    vertical_axis: u32,      // 1 in 2-D (y up), 2 in 3-D (z up)
    n_probes: u32,
    euler_every: u32,        // Verlet: an Euler step every this many steps
    clamp_pressure: u32,     // 1: no tension: fluid density floored at rest, pressure >= 0
    boundary_mode: u32,      // 0: dynamic boundary particles, 1: generalised walls (Adami 2012)
    sps_length2: f32,        // (C_s dp)^2 of water's sub-particle-scale viscosity, m2 (0: none)
    phases: array<Phase, 4>,
    tait_b: vec4<f32>,       // c0^2 rho0 / 7 per phase
    sediment: Sediment,
    flume: Flume,
}

@group(0) @binding(0) var<uniform> params: SimParams;

// A wall's new density from its integrated `rho` and its force entry `f_w`: under the
// generalised wall condition the force pass gives the density itself (physics/boundary.rs).
// Walls never fall below rest (integrate.rs, wall_density).
fn wall_density(rho: f32, f_w: f32, phase: u32) -> f32 {
    let r = select(rho, f_w, params.boundary_mode == 1u);
    return max(r, params.phases[phase].rho0);
}

// Whether held sediment stands as a wall (`SimParams::held_bed_is_wall`): the Shields-only
// mode's holds under the generalised wall condition, with the multiphase model that holds them.
fn held_bed_is_wall() -> bool {
    let sd = params.sediment;
    return params.boundary_mode == 1u && params.viscosity_mode == 2u && sd.phase != 0u
        && sd.shields_only != 0u;
}

// A free particle's density as stored: without tension (the case's clamp_negative_pressure)
// never below its phase's rest, so that a sheet too thin for a full kernel does not thin out
// without end.
fn clamped_density(rho: f32, phase: u32) -> f32 {
    return select(rho, max(rho, params.phases[phase].rho0), params.clamp_pressure != 0u);
}

// An inlet buffer particle's density: the one it entered with, or under the generalised wall
// condition its own by continuity, without tension (cpu/store.rs, inlet_density).
fn inlet_density(entered: f32, integrated: f32, phase: u32) -> f32 {
    return select(entered, max(integrated, params.phases[phase].rho0), params.boundary_mode == 1u);
}
