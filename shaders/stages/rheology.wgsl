// Rheology pass of the water-sediment model (Zubeldia et al. 2018): per particle, the velocity
// gradient and strain rate (Eqs. 12-13); for sediment the Drucker-Prager yield stress
// (Eqs. 27-31), the bed-surface test (Eq. 26), the Shields criterion with the nearest water
// particle (Eqs. 16-25), the concentration (Eq. 32), the region of Figure 2 and its apparent
// viscosity (Eqs. 15, 33); then the viscous stress tau = 2 mu eps that the force pass
// differentiates. Un-yielded sediment is held (REGION_HELD); in the Drucker-Prager mode a held
// particle stays held here unless Shields makes it bed load, and the hold stage that
// follows releases it. Reference: solver/src/physics/sediment/pass.rs.

@group(0) @binding(1) var positions: texture_2d<f32>;
@group(0) @binding(2) var vel_rho: texture_2d<f32>;
@group(0) @binding(3) var<storage, read> cell_starts: array<u32>;
@group(0) @binding(4) var<storage, read_write> state: StepState;
@group(0) @binding(5) var stress_a: texture_storage_2d<rgba32float, write>;
@group(0) @binding(6) var stress_b: texture_storage_2d<rgba32float, write>;
@group(0) @binding(7) var<storage, read_write> regions: array<u32>;
@group(0) @binding(8) var<storage, read> ids: array<u32>;

// The predictor's pass runs before dt_update, the corrector's after it; each skips idle steps
// the way the force pass that follows it does.
override BEFORE_DT: bool = true;

// What the rheology pass gathers over particle i's neighbours: the velocity gradient
// (grad[b] is the column du/dx_b), and for sediment the volumes of sediment and of the
// mixture, the kernel-weighted sediment mass of the surface test, the bed's normal, and the
// nearest water particle's distance squared and velocity, relative to i or its own
// (`sd.water_speed`, `SedimentModel::water_speed` of pass.rs), and the count of solids beside
// it at its level.
struct Gathered {
    grad: mat3x3<f32>,
    sediment_volume: f32,
    mixture_volume: f32,
    kernel_mass: f32,
    normal: vec3<f32>,
    nearest_r2: f32,
    nearest_u: vec3<f32>,
    level_solids: u32,  // solid neighbours beside it at its own level (`level_solid`)
}

// Adds neighbour j (sorted order) to the sums of particle i at pos_i moving at vel_i.
fn gather_neighbour(g: ptr<function, Gathered>, pos_i: vec3<f32>, vel_i: vec3<f32>, is_sediment: bool, j: u32) {
    let sd = params.sediment;
    let pos_j = textureLoad(positions, texel(j), 0);
    let dx = pos_i - pos_j.xyz;
    let r2 = dot(dx, dx);
    if (r2 >= 4.0 * params.h * params.h || r2 < 1e-12 * params.h * params.h) {
        return;
    }
    let phase_j = bitcast<u32>(pos_j.w);
    let vr_j = textureLoad(vel_rho, texel(j), 0);
    let m_j = params.phases[phase_j].mass;
    let v_j = m_j / vr_j.w;
    let r = sqrt(r2);
    let gw = dx * kernel_grad_factor(r);
    let du = vr_j.xyz - vel_i;
    (*g).grad += mat3x3<f32>(du * (v_j * gw.x), du * (v_j * gw.y), du * (v_j * gw.z));
    if (!is_sediment) {
        return;
    }
    // The bed's normal points away from the solid under it: sediment and walls.
    if (phase_j == sd.phase || params.phases[phase_j].mobile < 0.5) {
        (*g).normal -= v_j * gw;
        if (sd.rests_beside_solid != 0u && level_solid(dx[params.vertical_axis], r2)) {
            (*g).level_solids += 1u;
        }
    }
    if (phase_j == sd.phase) {
        (*g).sediment_volume += v_j;
        (*g).mixture_volume += v_j;
        (*g).kernel_mass += m_j * kernel_w(r) * v_j;
    } else if (phase_j == sd.water_phase) {
        (*g).mixture_volume += v_j;
        if (r2 < (*g).nearest_r2) {
            (*g).nearest_r2 = r2;
            (*g).nearest_u = select(du, vr_j.xyz, sd.water_speed != 0u);
        }
    }
}

// The deviatoric strain rate of Eq. 12 from the velocity gradient, the trace correction 1/3
// in 2-D too (see rheology.rs).
fn deviatoric_strain(grad: mat3x3<f32>) -> mat3x3<f32> {
    let dim_3d = params.vertical_axis == 2u;
    let trace = grad[0].x + grad[1].y + select(0.0, grad[2].z, dim_3d);
    var eps = 0.5 * (grad + transpose(grad));
    eps[0].x -= trace / 3.0;
    eps[1].y -= trace / 3.0;
    if (dim_3d) {
        eps[2].z -= trace / 3.0;
    } else {
        eps[2] = vec3<f32>(0.0);
        eps[0].z = 0.0;
        eps[1].z = 0.0;
    }
    return eps;
}

// A sediment particle's region and apparent viscosity.
struct Chosen {
    region: u32,
    mu: f32,
    pickup: i32,   // the mass picked up of a held particle so far, signed (pickup.rs)
    flux: f32,     // the bed load it passes on (pass.rs's ParticleRheology::flux)
    to_id: u32,   // the particle it passes it to (ParticleRheology::target)
}

// Where in `regions` the fluxes of the pass at run step `step` lie: after the words, the even
// steps' then the odd steps' (`REGION_SLOTS` of state.rs).
fn flux_slot(step: u32) -> u32 {
    return params.n_particles * (1u + (step & 1u));
}

// Where in `regions` the particles the fluxes of the pass at run step `step` went to lie: after
// the fluxes, the even steps' then the odd steps'.
fn target_slot(step: u32) -> u32 {
    return params.n_particles * (3u + (step & 1u));
}

// The bed-load exchange of sediment particle `id_i` at pos_i with its neighbours (`Exchange`
// of pass.rs), from the last step's pass's fluxes at `slot` and the particles they went to at
// `to_slot`: the loads of those that named it, and, if it `names` one (held at the surface
// under flowing water), the particle at the bed's top nearest the point dp down the flow of
// the nearest water, within dp of it.
struct Exchanged {
    passed: f32,
    to_id: u32,
}

fn bed_load_exchange(
    pos_i: vec3<f32>, id_i: u32, g: Gathered, names: bool, slot: u32, to_slot: u32
) -> Exchanged {
    let dp = params.sediment.dp;
    let along = select(vec3<f32>(0.0), g.nearest_u / length(g.nearest_u), names);
    let at = pos_i + dp * along;
    // Nothing lies nearer the point than 0: a particle under no flow names none.
    var best_d2 = select(0.0, dp * dp, names);
    var ex = Exchanged(0.0, NO_TARGET);
    let cell = cell_coords(pos_i);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            let id_j = ids[j];
            let flux_j = bitcast<f32>(regions[slot + id_j]);
            if (flux_j < 0.0 || id_j == id_i) {
                continue;
            }
            if (regions[to_slot + id_j] == id_i) {
                ex.passed += flux_j;
            }
            let d = textureLoad(positions, texel(j), 0).xyz - at;
            let d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            // The lesser id of two at the same distance: the same choice in any order.
            let tie = d2 == best_d2 && ex.to_id != NO_TARGET && id_j < ex.to_id;
            if (d2 < best_d2 || tie) {
                best_d2 = d2;
                ex.to_id = id_j;
            }
        }
    }
    return ex;
}

// Sediment particle i at pos_i: its region and apparent viscosity from its sums, its density
// and II_D: the Shields chain at the surface, the pick-up draw, Figure 2's region.
fn sediment_rheology(i: u32, pos_i: vec3<f32>, rho_i: f32, g: Gathered, ii_d: f32) -> Chosen {
    let sd = params.sediment;
    let tau_y = drucker_prager_yield(rho_i);
    let has_water = g.nearest_r2 < HUGE;
    let at_surface = has_water && g.kernel_mass < sd.surface_mass;
    // Where bed load is passed on and settles (`at_bed_top` in pass.rs): the surface, or a dry
    // bed's top, its normal within 45 deg of straight up.
    let up = g.normal[params.vertical_axis];
    let faces_up = up > 0.0 && 2.0 * up * up > dot(g.normal, g.normal);
    let bed_top = at_surface || (g.kernel_mass < sd.surface_mass && faces_up);
    var tau_b = 0.0;
    var tau_bcr = HUGE;
    if (at_surface) {
        let u_star = friction_velocity(length(g.nearest_u), sqrt(g.nearest_r2), sd.ks, sd.nu_w);
        let theta = critical_shields(u_star * sd.d50 / sd.nu_w);
        let k = slope_factors(g.normal, g.nearest_u, sd.phi);
        tau_b = sd.rho_w * u_star * u_star;
        tau_bcr = k * theta * sd.submerged_weight * sd.d50;
    }
    let c_v = clamp(g.sediment_volume / g.mixture_volume, 0.0, 1.0);
    // Read before this thread writes it; no other thread writes this id's word.
    let before = regions[ids[i]];
    let held_before = (before & REGION_HELD) != 0u;
    // The stress the particle carries, which only the Drucker-Prager mode reads.
    var sqrt_j2 = 0.0;
    if (sd.shields_only == 0u) {
        sqrt_j2 = 2.0 * min(hbp_viscosity(ii_d, tau_y), sd.mu_max) * sqrt(max(ii_d, 0.0));
    }
    // The pass before the step's size is chosen draws the pick-ups, one draw a step.
    var picked = sd.pickup_per_s == 0.0;
    // Worn net of what settles from upstream: Exner's balance (`van_rijn_exner`), whose units
    // are signed (`word_units` in pickup.rs).
    let exner = sd.exner_step_per_stage > 0.0;
    let units = select(i32(before >> PICKUP_SHIFT), bitcast<i32>(before) >> PICKUP_SHIFT, exner);
    var pickup = select(units, 0, picked);
    let rate = pickup_rate(tau_b, tau_bcr);
    var flux = bed_load_flux(rate, tau_b, tau_bcr);
    var to_id = NO_TARGET;
    if (!picked && BEFORE_DT) {
        let step = state.run_steps + state.steps;
        if (exner) {
            // Every grain is passed the loads named to it, wherever it now lies; one the bed
            // did not hold carries what was worn off it and wears no more (`settle` in pass.rs).
            let last = step + 1u;
            let names = held_before && at_surface && length(g.nearest_u) > 0.0;
            let ex = bed_load_exchange(
                pos_i, ids[i], g, names, flux_slot(last), target_slot(last)
            );
            to_id = ex.to_id;
            // A held grain nothing holds (tau_bcr 0: the roof of a hole, say) leaves whole.
            let free = held_before && tau_bcr <= 0.0;
            let wears = held_before && !free;
            let own = select(vec2<f32>(0.0), vec2<f32>(flux, rate), wears);
            let exchange = exner_exchange(own.x, ex.passed, own.y, pickup, state.dt_taken);
            flux = exchange.x;
            let worn = exner_pickup(pickup, ids[i], step, exchange.y, state.dt_taken);
            let whole = worn >= EXNER_SPENT;
            picked = whole || free;
            pickup = select(worn, EXNER_SPENT, whole);
        } else if (sd.pickup_integrated != 0u) {
            let worn = integrated_pickup(u32(max(pickup, 0)), ids[i], step, rate, state.dt_taken);
            picked = worn >= PICKUP_WHOLE;
            pickup = select(i32(worn), 0, picked);
        } else {
            picked = picked_up(ids[i], step, rate, state.dt_taken);
            pickup = 0;
        }
    }
    let region = sediment_region(RegionInputs(
        sd.shields_only != 0u, held_before, at_surface, tau_b, tau_bcr, sqrt_j2, tau_y, c_v,
        picked, sd.rests_beside_solid != 0u && g.level_solids == 0u
    ));
    // What was worn off a particle stays with it while it is held, and only then; under
    // Exner's balance, where it went downstream as bed load, wherever the particle goes.
    let kept = select(0, pickup, exner || (region == REGION_UNYIELDED && held_before));
    // Held at the bed's top, wet or dry: what the flow carries to a wet front settles there;
    // one the bed lets go in this pass still passes on what it carries.
    let passed = exner && bed_top && (held_before || region == REGION_UNYIELDED);
    let mu = region_viscosity(region, ii_d, tau_y, tau_bcr, c_v);
    let to = select(NO_TARGET, to_id, passed);
    return Chosen(region, mu, kept, select(NO_FLUX, flux, passed), to);
}

@compute @workgroup_size(64)
fn rheology(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // Over the active particles only, as the force pass.
    if (i >= cell_starts[params.n_cells] || chunk_idle(BEFORE_DT)) {
        return;
    }
    let pos_i = textureLoad(positions, texel(i), 0);
    let vr_i = textureLoad(vel_rho, texel(i), 0);
    let phase_i = bitcast<u32>(pos_i.w);
    let ph_i = params.phases[phase_i];
    if (ph_i.mobile < 0.5) {
        textureStore(stress_a, texel(i), vec4<f32>(0.0));
        textureStore(stress_b, texel(i), vec4<f32>(0.0));
        regions[ids[i]] = 0u;
        if (BEFORE_DT && params.sediment.exner_step_per_stage > 0.0) {
            regions[flux_slot(state.run_steps + state.steps) + ids[i]] = bitcast<u32>(NO_FLUX);
        }
        return;
    }
    let sd = params.sediment;
    let is_sediment = phase_i == sd.phase && sd.phase != 0u;
    let rho_i = vr_i.w;
    var g: Gathered;
    g.nearest_r2 = HUGE;
    if (is_sediment) {
        let v_i = ph_i.mass / rho_i;
        g.sediment_volume = v_i;
        g.mixture_volume = v_i;
        g.kernel_mass = ph_i.mass * kernel_w(0.0) * v_i;
    }
    let cell = cell_coords(pos_i.xyz);
    for (var row = 0u; row < STENCIL_ROWS; row++) {
        let range = stencil_row(cell, row);
        for (var j = range.x; j < range.y; j++) {
            gather_neighbour(&g, pos_i.xyz, vr_i.xyz, is_sediment, j);
        }
    }
    let eps = deviatoric_strain(g.grad);
    let ii_d = 0.5 * (dot(eps[0], eps[0]) + dot(eps[1], eps[1]) + dot(eps[2], eps[2]));

    // Water's own viscosity and its eddy viscosity; sediment takes its region's below.
    var mu = ph_i.mu + sps_viscosity(rho_i, ii_d);
    var region = REGION_WATER;
    var pickup = 0;
    var flux = NO_FLUX;
    var to_id = NO_TARGET;
    if (is_sediment) {
        let chosen = sediment_rheology(i, pos_i.xyz, rho_i, g, ii_d);
        region = chosen.region;
        mu = chosen.mu;
        pickup = chosen.pickup;
        flux = chosen.flux;
        to_id = chosen.to_id;
    }
    // Shields-only holds carry no stress; Drucker-Prager holds keep theirs (hold.rs).
    let held = region == REGION_UNYIELDED;
    let t = select(2.0 * mu, 0.0, held && sd.shields_only != 0u) * eps;
    let word = region | select(0u, REGION_HELD, held);
    textureStore(stress_a, texel(i), vec4<f32>(t[0].x, t[1].x, t[2].x, t[1].y));
    // The region and the hold, exact in an f32: the hold stage reads which neighbours this
    // pass held.
    textureStore(stress_b, texel(i), vec4<f32>(t[2].y, t[2].z, mu, f32(word)));
    // By particle id: the integrators, the probes and the host each see the particles in a
    // different order.
    regions[ids[i]] = word | (bitcast<u32>(pickup) << PICKUP_SHIFT);
    // The pass that wears the bed passes its bed load on to the next one's.
    if (BEFORE_DT && sd.exner_step_per_stage > 0.0) {
        let step = state.run_steps + state.steps;
        regions[flux_slot(step) + ids[i]] = bitcast<u32>(flux);
        regions[target_slot(step) + ids[i]] = to_id;
    }
}
