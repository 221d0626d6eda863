// Formulas of the sediment model (Zubeldia et al. 2018), one function per equation; the
// reference of each is the function of the same name in solver/src/physics/sediment/.

const KARMAN: f32 = 0.41;
const SUBLAYER_WALL_UNITS: f32 = 11.6;
const SMOOTH_RE_K: f32 = 5.0;
const ROUGH_RE_K: f32 = 70.0;
const Z0_SMOOTH: f32 = 0.11;
const Z0_ROUGH: f32 = 0.033;
const FRICTION_VELOCITY_MAX_ITERATIONS: u32 = 64u;
const BISECTION_REL_TOL: f32 = 4.0 * 1.1920929e-7;
const SUSPENSION_CONCENTRATION: f32 = 0.3;
const PAPANASTASIOU_SERIES_LIMIT: f32 = 0.1;
const HUGE: f32 = 3.0e38;

const REGION_UNYIELDED: u32 = 1u;
const REGION_YIELDED: u32 = 2u;
const REGION_BED_LOAD: u32 = 3u;
const REGION_SUSPENDED: u32 = 4u;
const REGION_WATER: u32 = 5u;
// Set in a particle's region word when it is held fixed this step.
const REGION_HELD: u32 = 256u;
// Above the hold: the mass picked up of a held particle so far, in PICKUP_WHOLE-ths of it; under
// Exner's balance in EXNER_WHOLE-ths, a two's complement read by shifting the word as an i32
// (`PICKUP_SHIFT`, `PICKUP_WHOLE`, `EXNER_WHOLE` of pickup.rs).
const PICKUP_SHIFT: u32 = 9u;
const PICKUP_WHOLE: u32 = 8388608u;
const EXNER_WHOLE: u32 = 4194304u;
// The units a particle worn whole keeps under Exner's balance (`EXNER_SPENT` of pickup.rs).
const EXNER_SPENT: i32 = 4194303;
// The bed load of a particle that is not held at the bed's surface (`NO_FLUX` of pass.rs).
const NO_FLUX: f32 = -1.0;
// The particle a held particle passes its bed load to when none is (`NO_TARGET` of pass.rs).
const NO_TARGET: u32 = 4294967295u;

// Eq. 17 (van Rijn 1993); "infinite" (HUGE) at Re* <= 0.
fn critical_shields(re_star: f32) -> f32 {
    if (re_star >= 500.0) {
        return 0.068;
    }
    if (re_star > 0.0) {
        return 0.010595 * log(re_star) + 0.110476 / re_star + 0.0027197;
    }
    return HUGE;
}

// Eq. 21 for one regime: 0 smooth, 1 transitional, 2 rough.
fn z0_in(regime: u32, u_star: f32, ks: f32, nu: f32) -> f32 {
    switch (regime) {
        case 0u: { return Z0_SMOOTH * nu / u_star; }
        case 1u: { return Z0_SMOOTH * nu / u_star + Z0_ROUGH * ks; }
        default: { return Z0_ROUGH * ks; }
    }
}

// Eq. 20, the log law with the z0 of `regime`.
fn log_profile(regime: u32, z: f32, u_star: f32, ks: f32, nu: f32) -> f32 {
    return u_star / KARMAN * log(z / z0_in(regime, u_star, ks, nu));
}

// Friction velocity u* such that the profile of Eqs. 19-21 passes through speed u at height z
// above the bed: the viscous sub-layer first, then the log law regime by regime, narrowing
// the bracket of the regime whose u* range holds the solution (see `friction_velocity` in
// shields.rs, whose bracket and stopping rules this follows step for step).
fn friction_velocity(u: f32, z: f32, ks: f32, nu: f32) -> f32 {
    if (!(u > 0.0) || !(z > 0.0) || u > HUGE) {
        return 0.0;
    }
    let sublayer_top = SUBLAYER_WALL_UNITS * nu / z;
    let guess = sqrt(u * nu / z);
    if (guess <= sublayer_top) {
        return guess;
    }
    let smooth_top = SMOOTH_RE_K * nu / ks;
    let rough_bottom = ROUGH_RE_K * nu / ks;
    for (var regime = 0u; regime < 3u; regime++) {
        var lo = sublayer_top;
        var hi = smooth_top;
        if (regime == 1u) {
            lo = max(sublayer_top, smooth_top);
            hi = rough_bottom;
        } else if (regime == 2u) {
            lo = max(sublayer_top, rough_bottom);
            hi = HUGE;
        }
        if (lo >= hi) {
            continue;
        }
        if (log_profile(regime, z, lo, ks, nu) >= u) {
            return lo;
        }
        if (regime == 2u) {
            let log_ratio = log(z / (Z0_ROUGH * ks));
            if (!(log_ratio > 0.0)) {
                break;
            }
            return max(KARMAN * u / log_ratio, lo);
        }
        if (regime == 0u) {
            hi = min(hi, u * KARMAN / log(50.0));
        }
        let excess = log_profile(regime, z, hi, ks, nu) - u;
        if (excess < 0.0) {
            continue;
        }
        return narrow_bracket(regime, u, z, ks, nu, lo, hi, excess);
    }
    return sublayer_top;
}

// d u / d u* of the log law of `regime` (smooth or transitional), `profile_slope` in shields.rs.
fn profile_slope(regime: u32, z: f32, u_star: f32, ks: f32, nu: f32) -> f32 {
    let z0 = z0_in(regime, u_star, ks, nu);
    return (log(z / z0) + Z0_SMOOTH * nu / (u_star * z0)) / KARMAN;
}

// Newton's method from the bracket's top, a step that leaves the bracket bisecting it and one
// shorter than half the tolerance taken at that length (`narrow_bracket` in shields.rs).
fn narrow_bracket(
    regime: u32, u: f32, z: f32, ks: f32, nu: f32, lo_in: f32, hi_in: f32, excess_in: f32
) -> f32 {
    var lo = lo_in;
    var hi = hi_in;
    var x = hi;
    var excess = excess_in;
    var iterations = 0u;
    while (hi - lo > BISECTION_REL_TOL * hi && iterations < FRICTION_VELOCITY_MAX_ITERATIONS) {
        let shortest = 0.5 * BISECTION_REL_TOL * x;
        var newton = excess / profile_slope(regime, z, x, ks, nu);
        if (abs(newton) < shortest) {
            newton = select(-shortest, shortest, excess >= 0.0);
        }
        var next = x - newton;
        if (!(next > lo && next < hi)) {
            next = 0.5 * (lo + hi);
            if (next <= lo || next >= hi) {
                break;
            }
        }
        iterations++;
        x = next;
        excess = log_profile(regime, z, x, ks, nu) - u;
        if (excess >= 0.0) {
            hi = x;
        } else {
            lo = x;
        }
    }
    return hi;
}

// Eq. 22: k_beta, flow down the slope or up it.
fn k_beta(beta: f32, phi: f32, down: bool) -> f32 {
    let b = abs(beta);
    let s = select(sin(phi + b), sin(phi - b), down);
    return max(s / sin(phi), 0.0);
}

// Eq. 23: k_gamma.
fn k_gamma(gamma: f32, phi: f32) -> f32 {
    let g = abs(gamma);
    if (g >= phi) {
        return 0.0;
    }
    let r = tan(g) / tan(phi);
    return cos(g) * sqrt(max(1.0 - r * r, 0.0));
}

// k_beta k_gamma from the bed's outward normal n and the flow u over it (`slope_factors` in
// shields.rs): the slope is the normal's tilt along and across the flow's horizontal direction.
fn slope_factors(n: vec3<f32>, u: vec3<f32>, phi: f32) -> f32 {
    let v = params.vertical_axis;
    var uh = u;
    uh[v] = 0.0;
    let speed_h = length(uh);
    let n_len = length(n);
    if (speed_h == 0.0 || n_len == 0.0) {
        return 1.0;
    }
    // A bed that faces down holds no grain (`slope_factors` in shields.rs).
    if (n[v] < 0.0) {
        return 0.0;
    }
    var nh = n;
    nh[v] = 0.0;
    let n_s = dot(nh, uh) / speed_h;
    var n_t = 0.0;
    if (v == 2u) {
        n_t = (n.x * u.y - n.y * u.x) / speed_h;
    }
    let beta = atan2(abs(n_s), n[v]);
    let gamma = atan2(abs(n_t), n[v]);
    return k_beta(beta, phi, n_s > 0.0) * k_gamma(gamma, phi);
}

// (1 - exp(-x)) / x, continuous through x = 0.
fn papanastasiou_factor(x: f32) -> f32 {
    if (x < PAPANASTASIOU_SERIES_LIMIT) {
        return 1.0 - x * (1.0 / 2.0 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)));
    }
    return (1.0 - exp(-x)) / x;
}

// Eq. 15, the HBP apparent viscosity, Pa s.
fn hbp_viscosity(ii_d: f32, tau_c: f32) -> f32 {
    let sd = params.sediment;
    let d = max(ii_d, 0.0);
    let s = sqrt(d);
    let yield_term = tau_c * sd.hbp_m * papanastasiou_factor(sd.hbp_m * s);
    var power_term = 2.0 * sd.mu_s;
    if (sd.hbp_n != 1.0) {
        power_term *= pow(4.0 * d, 0.5 * (sd.hbp_n - 1.0));
    }
    return yield_term + power_term;
}

// Eqs. 29-31, the Drucker-Prager yield stress of a sediment particle of density rho, Pa, from
// its skeleton pressure p (1 - rho_w / rho_s) (`skeleton_pressure` in drucker_prager.rs).
fn drucker_prager_yield(rho: f32) -> f32 {
    let sd = params.sediment;
    let p_skel = tait_pressure(rho, sd.phase) * (1.0 - sd.rho_w / sd.rho_s);
    return sd.dp_alpha * max(p_skel, 0.0) + sd.dp_kappa;
}

// The Smagorinsky sub-particle-scale viscosity rho (C_s dp)^2 2 sqrt(II_D), Pa s
// (`sps_viscosity` in rheology.rs).
fn sps_viscosity(rho: f32, ii_d: f32) -> f32 {
    return rho * params.sps_length2 * 2.0 * sqrt(max(ii_d, 0.0));
}

// Eq. 33, Vand's suspension viscosity, Pa s.
fn vand_viscosity(c_v: f32) -> f32 {
    return params.sediment.mu_w * exp(2.5 * c_v / (1.0 - 39.0 / 64.0 * c_v));
}

// What the rheology pass chooses a sediment particle's region from (`RegionInputs` in pass.rs).
struct RegionInputs {
    shields_only: bool,
    held_before: bool,
    at_surface: bool,
    tau_b: f32,
    tau_bcr: f32,
    sqrt_j2: f32,
    tau_y: f32,
    c_v: f32,
    picked_up: bool,  // its mass picked up this step; always where Shields releases at once
    lone: bool,       // no solid beside it at its own level
}

// Whether a solid neighbour `up` above a sediment particle and `r2` from it squared lies
// beside it at its level: within half a spacing of its height and one and a half of it
// (`level_solid` in suspension.rs).
fn level_solid(up: f32, r2: f32) -> bool {
    let dp = params.sediment.dp;
    return up * up < 0.25 * dp * dp && r2 < 2.25 * dp * dp;
}

// The PCG hash (Jarzynski & Olano 2020), `pcg` in pickup.rs.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The uniform 32-bit draw of particle `id` at run step `step` (`pickup_draw` in pickup.rs).
fn pickup_draw(id: u32, step: u32) -> u32 {
    return pcg(id ^ pcg(step));
}

// van Rijn's pick-up rate of one particle, 1/s (`pickup_rate` in pickup.rs).
fn pickup_rate(tau_b: f32, tau_bcr: f32) -> f32 {
    let stage = max(tau_b / tau_bcr - 1.0, 0.0);
    return params.sediment.pickup_per_s * stage * sqrt(stage);
}

// Whether particle `id` is picked up at run step `step`, a step of `dt` at `rate` per second
// (`picked_up` in pickup.rs).
fn picked_up(id: u32, step: u32, rate: f32, dt: f32) -> bool {
    let chance = clamp(rate * dt, 0.0, 0.99999994);
    return pickup_draw(id, step) < u32(chance * 4294967296.0);
}

// The mass picked up of a held particle after a step of `dt` at `rate` per second, from `units`
// before: PICKUP_WHOLE or more once none of it is left (`integrated_pickup` in pickup.rs; the
// step's share rounded down or up by the particle's draw).
fn integrated_pickup(units: u32, id: u32, step: u32, rate: f32, dt: f32) -> u32 {
    let share = clamp(rate * dt, 0.0, 1.0) * f32(PICKUP_WHOLE);
    let fraction = f32(pickup_draw(id, step) >> 8u) * (1.0 / 16777216.0);
    return units + u32(share + fraction);
}

// The bed load a held surface particle passes on downstream, particles per second: its pick-up
// `rate` carried van Rijn's saltation length (`bed_load_flux` in pickup.rs).
fn bed_load_flux(rate: f32, tau_b: f32, tau_bcr: f32) -> f32 {
    let stage = max(tau_b / tau_bcr - 1.0, 0.0);
    return rate * params.sediment.exner_step_per_stage * select(0.0, pow(stage, 0.9), stage > 0.0);
}

// Exner's balance for a held surface particle: what it passes on and what it loses per second,
// `vec2(out, net)` with `net = out - upstream`: its own bed load `flux` but no more than the
// load from `upstream` plus its pick-up at `rate`, its pick-up no more than is left of it, and
// what settles on it no more than builds it up to a whole particle more than its own mass
// (`exner_exchange` in pickup.rs).
fn exner_exchange(flux: f32, upstream: f32, rate: f32, units: i32, dt: f32) -> vec2<f32> {
    let room = (f32(units) + f32(EXNER_WHOLE)) / (f32(EXNER_WHOLE) * dt);
    let left = f32(max(EXNER_SPENT - units, 0)) / (f32(EXNER_WHOLE) * dt);
    let net = clamp(min(flux, upstream + rate) - upstream, -room, left);
    return vec2<f32>(upstream + net, net);
}

// The mass worn off a held particle after a step of `dt` with `net` per second worn (negative:
// settled), from `units` before: EXNER_SPENT or more once none is left, never below a whole
// particle's surplus (`exner_pickup` in pickup.rs; the step's share rounded down or up by the
// particle's draw).
fn exner_pickup(units: i32, id: u32, step: u32, net: f32, dt: f32) -> i32 {
    let share = clamp(net * dt, -1.0, 1.0) * f32(EXNER_WHOLE);
    let fraction = f32(pickup_draw(id, step) >> 8u) * (1.0 / 16777216.0);
    return max(units + i32(floor(share + fraction)), -i32(EXNER_WHOLE));
}

// A sediment particle's region (Figure 2 with the hold; `sediment_region` in pass.rs): in the
// Shields-only mode suspended below the concentration, else bed load or held; in the
// Drucker-Prager mode a particle held before stays un-yielded unless Shields makes it bed load
// (only the hold stage frees it otherwise), any other is bed load, yielded or not, and then
// suspended below the concentration unless un-yielded. A particle held before that has not been
// picked up stays held. Then a grain not held before with no solid beside it at its level
// is bed load where it would be held: it lies on the bed, not in it.
fn sediment_region(r: RegionInputs) -> u32 {
    let region = figure2_region(r);
    if (region == REGION_UNYIELDED && r.lone && !r.held_before) {
        return REGION_BED_LOAD;
    }
    return region;
}

// `sediment_region` before the rule for lone grains.
fn figure2_region(r: RegionInputs) -> u32 {
    if (r.held_before && !r.picked_up) {
        return REGION_UNYIELDED;
    }
    let bed_load = r.at_surface && r.tau_b > r.tau_bcr;
    if (r.shields_only) {
        if (r.c_v < SUSPENSION_CONCENTRATION) {
            return REGION_SUSPENDED;
        }
        return select(REGION_UNYIELDED, REGION_BED_LOAD, bed_load);
    }
    if (r.held_before && !bed_load) {
        return REGION_UNYIELDED;
    }
    var region = select(REGION_UNYIELDED, REGION_YIELDED, r.sqrt_j2 > r.tau_y);
    if (bed_load) {
        region = REGION_BED_LOAD;
    }
    if (region != REGION_UNYIELDED && r.c_v < SUSPENSION_CONCENTRATION) {
        region = REGION_SUSPENDED;
    }
    return region;
}

// The apparent viscosity of a sediment particle in `region`, capped, Pa s (`apparent_viscosity`
// in suspension.rs, then the cap).
fn region_viscosity(region: u32, ii_d: f32, tau_y: f32, tau_bcr: f32, c_v: f32) -> f32 {
    var mu: f32;
    switch (region) {
        case REGION_BED_LOAD: { mu = hbp_viscosity(ii_d, tau_bcr); }
        case REGION_SUSPENDED: { mu = vand_viscosity(c_v); }
        default: { mu = hbp_viscosity(ii_d, tau_y); }
    }
    return min(mu, params.sediment.mu_max);
}
