//! Shields erosion criterion at the bed surface (Zubeldia et al. 2018, Eqs. 16-26, after Manenti
//! et al. 2012 and van Rijn 1993):
//! - critical Shields parameter (Eq. 17), `Re* = u* d / nu`:
//!   `theta_cr = 0.010595 ln(Re*) + 0.110476 / Re* + 0.0027197` for Re* < 500, 0.068 otherwise;
//! - critical bed shear stress on a flat bed (Eq. 16): `tau_bcr0 = theta_cr (rho_s - rho_w) g d`;
//! - bed shear stress (Eq. 18): `tau_b = rho_w u*^2`;
//! - velocity profile above the bed (Eqs. 19-20): `u = u*^2 z / nu` for
//!   `z <= delta = 11.6 nu / u*`, `u = (u* / kappa) ln(z / z0)` above, kappa = 0.41;
//! - roughness length (Eq. 21), by `Re_k = ks u* / nu`: `0.11 nu / u*` (smooth, Re_k <= 5),
//!   `0.033 ks` (rough, Re_k >= 70), their sum in between;
//! - slope factors (Eqs. 22-24): `k_beta = sin(phi -/+ beta) / sin(phi)`,
//!   `k_gamma = cos(gamma) sqrt(1 - tan^2(gamma) / tan^2(phi))`,
//!   `tau_bcr = k_beta k_gamma tau_bcr0`;
//! - erosion (Eq. 25) where `tau_b > tau_bcr`, for particles near the surface (Eq. 26).
//!
//! Which Re* enters Eq. 17: the paper computes u* from the nearest water particle and then "tau_b
//! and tau_bcr,0 from (18) and (16)", so in the model Eq. 17 is evaluated at the flow's Re*
//! ([`critical_shields`]). The textbook Shields threshold instead evaluates it at the critical
//! friction velocity itself ([`critical_shields_self_consistent`], which reproduces the
//! validation table). Both give the same answer to "does this particle erode" (at the threshold
//! u* = u*_cr), but differ as the tau_c of bed-load particles in Eq. 15.

/// Von Karman constant kappa of the log law (Eq. 20).
pub const KARMAN: f32 = 0.41;
/// Thickness of the viscous sub-layer in wall units: `delta = 11.6 nu / u*` (Eq. 19).
pub const SUBLAYER_WALL_UNITS: f32 = 11.6;
/// `Re_k = ks u* / nu` at or below which the bed is hydraulically smooth (Eq. 21).
pub const SMOOTH_RE_K: f32 = 5.0;
/// `Re_k` at or above which the bed is hydraulically rough (Eq. 21).
pub const ROUGH_RE_K: f32 = 70.0;
/// Re* from which the critical Shields parameter is the constant [`THETA_CR_ROUGH`] (Eq. 17).
pub const RE_STAR_ROUGH: f32 = 500.0;
/// Critical Shields parameter for Re* >= 500 (Eq. 17).
pub const THETA_CR_ROUGH: f32 = 0.068;
/// Most steps [`friction_velocity`] takes inside a bracket. Newton's method from the bracket's
/// top converges quadratically: 4 steps at most over u <= 5 m/s, 0.1 mm <= z <= 5 cm and ks up
/// to 17.5 mm (the tests allow 6), where a bisection of the same brackets took up to 25. The cap
/// only guards against a bug.
pub const FRICTION_VELOCITY_MAX_ITERATIONS: u32 = 64;
/// Most fixed-point steps [`critical_shields_self_consistent`] takes; it contracts by a factor of
/// about 0.5 or better per step, so 100 steps are far more than f32 needs.
pub const CRITICAL_SHIELDS_MAX_ITERATIONS: u32 = 100;

/// z0 coefficient of the smooth regime (`0.11 nu / u*`) and of the rough one (`0.033 ks`).
pub const Z0_SMOOTH: f32 = 0.11;
pub const Z0_ROUGH: f32 = 0.033;
/// The search stops when the bracket is within this relative width: four f32 ulps, below which
/// rounding of the profile itself decides the comparisons.
pub const BISECTION_REL_TOL: f32 = 4.0 * f32::EPSILON;

/// Critical Shields parameter of Eq. 17 (van Rijn 1993), dimensionless.
///
/// The formula jumps at Re* = 500 (0.06878 just below, 0.068 from 500 on); the paper states it so
/// and so does this function. For Re* <= 0 the result is +infinity, the limit of
/// `0.110476 / Re*` as Re* -> 0+: no flow moves a grain. NaN stays NaN.
pub fn critical_shields(re_star: f32) -> f32 {
    if re_star.is_nan() {
        re_star
    } else if re_star >= RE_STAR_ROUGH {
        THETA_CR_ROUGH
    } else if re_star > 0.0 {
        0.010595 * re_star.ln() + 0.110476 / re_star + 0.0027197
    } else {
        f32::INFINITY
    }
}

/// Critical bed shear stress on a flat bed, Eq. 16: `theta_cr (rho_s - rho_w) g d`, Pa
/// (densities in kg/m3, g in m/s2, d in m).
pub fn critical_bed_shear_stress(theta_cr: f32, rho_s: f32, rho_w: f32, g: f32, d: f32) -> f32 {
    theta_cr * (rho_s - rho_w) * g * d
}

/// Bed shear stress `tau_b = rho_w u*^2` (Eq. 18), Pa.
pub fn bed_shear_stress(rho_w: f32, u_star: f32) -> f32 {
    rho_w * u_star * u_star
}

/// Hydraulic regime of the bed in Eq. 21.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Roughness {
    /// `ks u* / nu <= 5`.
    Smooth,
    /// `5 < ks u* / nu < 70`.
    Transitional,
    /// `ks u* / nu >= 70`.
    Rough,
}

/// Regime of Eq. 21 for friction velocity `u_star` (m/s), roughness `ks` (m) and kinematic
/// viscosity `nu` (m2/s).
pub fn roughness_regime(u_star: f32, ks: f32, nu: f32) -> Roughness {
    let re_k = ks * u_star / nu;
    if re_k <= SMOOTH_RE_K {
        Roughness::Smooth
    } else if re_k >= ROUGH_RE_K {
        Roughness::Rough
    } else {
        Roughness::Transitional
    }
}

fn z0_in(regime: Roughness, u_star: f32, ks: f32, nu: f32) -> f32 {
    match regime {
        Roughness::Smooth => Z0_SMOOTH * nu / u_star,
        Roughness::Transitional => Z0_SMOOTH * nu / u_star + Z0_ROUGH * ks,
        Roughness::Rough => Z0_ROUGH * ks,
    }
}

/// Roughness length z0 of Eq. 21, m. Infinite at u* = 0 (smooth regime, `0.11 nu / 0`).
pub fn roughness_length(u_star: f32, ks: f32, nu: f32) -> f32 {
    z0_in(roughness_regime(u_star, ks, nu), u_star, ks, nu)
}

/// Thickness of the viscous sub-layer `delta = 11.6 nu / u*` (Eq. 19), m.
pub fn sublayer_thickness(u_star: f32, nu: f32) -> f32 {
    SUBLAYER_WALL_UNITS * nu / u_star
}

/// Which law of Eq. 20 applies, with the z0 regime of Eq. 21 for the log law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layer {
    Viscous,
    Log(Roughness),
}

fn profile_in(layer: Layer, z: f32, u_star: f32, ks: f32, nu: f32) -> f32 {
    match layer {
        Layer::Viscous => u_star * u_star * z / nu,
        Layer::Log(regime) => u_star / KARMAN * (z / z0_in(regime, u_star, ks, nu)).ln(),
    }
}

/// Velocity u(z) of Eqs. 19-21 at height `z` (m) above the bed for friction velocity `u_star`
/// (m/s), roughness `ks` (m) and kinematic viscosity `nu` (m2/s), m/s. Zero for u* <= 0.
///
/// Inside the rough regime's roughness height (z < 0.033 ks) the log law is negative; it is
/// returned as is, being what Eq. 20 says.
pub fn velocity_profile(z: f32, u_star: f32, ks: f32, nu: f32) -> f32 {
    if u_star.is_nan() || u_star <= 0.0 {
        return 0.0;
    }
    let layer = if z <= sublayer_thickness(u_star, nu) {
        Layer::Viscous
    } else {
        Layer::Log(roughness_regime(u_star, ks, nu))
    };
    profile_in(layer, z, u_star, ks, nu)
}

/// Result of [`friction_velocity`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionVelocity {
    /// Friction velocity u*, m/s.
    pub u_star: f32,
    /// Steps taken inside the bracket (0 when a closed form gave the answer).
    pub iterations: u32,
    /// `false` when Eq. 20 cannot produce the given speed at that height or the input is not
    /// physical; see [`friction_velocity`] for what `u_star` then holds.
    pub converged: bool,
}

/// Friction velocity u* for which the profile of Eqs. 19-21 gives speed `u` (m/s) at height `z`
/// (m) above the bed, with roughness `ks` (m, >= 0) and kinematic viscosity `nu` (m2/s).
///
/// The profile u(z; u*) is increasing in u* piece by piece but jumps where the pieces meet: down
/// at the top of the sub-layer (`u* = 11.6 nu / z`: the linear law gives 11.6 u* there, the log
/// law 11.36 u* on a smooth bed and less on a rougher one) and at `Re_k = 5`, up at
/// `Re_k = 70`. So `u(z; u*) = u` can have two roots or none, and a plain fixed point or Newton
/// iteration can cycle between pieces.
/// The function returns the smallest u* whose profile reaches u,
/// `u* = inf { u* > 0 : u(z; u*) >= u }`, found piece by piece in order of increasing u*:
/// 1. the paper's starting hypothesis, smooth flow with the particle inside the sub-layer:
///    `u* = sqrt(u nu / z)`, accepted when `z <= delta`, i.e. `u z / nu <= 11.6^2`;
/// 2. otherwise the log law on the smooth, transitional and rough ranges of u* above the
///    sub-layer, each continuous and increasing where positive: on the smooth and transitional
///    ranges the bracket is narrowed to four f32 ulps by Newton's method from its top, a step
///    that leaves the bracket being a bisection instead (`narrow_bracket`); on the rough one
///    the closed form `u* = kappa u / ln(z / 0.033 ks)`.
///
/// Reading the paper's iteration ("start from smooth flow inside the sub-layer, iterate until u*
/// converges") as a walk from the smallest-u* hypothesis up, the first consistent piece is the one
/// it settles in; where two pieces both hold a root this picks the smaller u*, hence the smaller
/// bed stress. Where u falls in the gap of the upward jump at Re_k = 70, the profile steps over u
/// at `u* = 70 nu / ks`, which is returned (converged).
///
/// No solution exists when the particle sits inside the rough bed's roughness height
/// (`z <= 0.033 ks`, where the log law is not positive) and moves faster than the top of the
/// sub-layer allows (`u > 11.6^2 nu / z`): then `converged` is false and `u_star` is the top of the
/// sub-layer, `11.6 nu / z`, the largest u* the profile can account for. Non-physical input (NaN,
/// u < 0, z <= 0, nu <= 0, ks < 0) gives `u_star = 0`, `converged = false`. u = 0 gives u* = 0.
pub fn friction_velocity(u: f32, z: f32, ks: f32, nu: f32) -> FrictionVelocity {
    if !physical(u, z, ks, nu) {
        return FrictionVelocity {
            u_star: 0.0,
            iterations: 0,
            converged: false,
        };
    }
    let done = |u_star: f32, iterations: u32| FrictionVelocity {
        u_star,
        iterations,
        converged: true,
    };
    if u == 0.0 {
        return done(0.0, 0);
    }

    // 1. Viscous sub-layer: z <= 11.6 nu / u*, i.e. u* <= sublayer_top.
    let sublayer_top = SUBLAYER_WALL_UNITS * nu / z;
    let guess = (u * nu / z).sqrt();
    if guess <= sublayer_top {
        return done(guess, 0);
    }

    // 2. Log law above the sub-layer, on the u* ranges of the three z0 regimes.
    for (regime, lo, hi) in log_ranges(sublayer_top, ks, nu) {
        if lo >= hi {
            continue;
        }
        let layer = Layer::Log(regime);
        let f = |u_star: f32| profile_in(layer, z, u_star, ks, nu);
        // The profile already exceeds u where this range starts: u lies in the upward jump at
        // its lower end (only possible at Re_k = 70).
        if f(lo) >= u {
            return done(lo, 0);
        }
        let hi = match regime {
            Roughness::Rough => {
                // u = (u*/kappa) ln(z / z0) with a constant z0: linear in u*.
                let log_ratio = (z / (Z0_ROUGH * ks)).ln();
                if log_ratio.is_nan() || log_ratio <= 0.0 {
                    break;
                }
                return done((KARMAN * u / log_ratio).max(lo), 0);
            }
            // Above the sub-layer z / z0 = z u* / (0.11 nu) > 11.6 / 0.11 = 105, so the smooth
            // law exceeds u* ln(105) / kappa and the root lies below u kappa / ln(105). Capping
            // at the looser u kappa / ln(50) bounds the bracket when the smooth range is
            // unbounded (ks = 0) or huge (tiny ks), and still surely holds the root.
            Roughness::Smooth => hi.min(u * KARMAN / 50.0_f32.ln()),
            Roughness::Transitional => hi,
        };
        let excess = f(hi) - u;
        if excess < 0.0 {
            continue;
        }
        let slope = |u_star: f32| profile_slope(regime, z, u_star, ks, nu);
        return narrow_bracket(u, (lo, hi), excess, f, slope);
    }
    FrictionVelocity {
        u_star: sublayer_top,
        iterations: 0,
        converged: false,
    }
}

/// Whether the inputs of [`friction_velocity`] describe a flow: finite, u and ks not
/// negative, z and nu positive.
fn physical(u: f32, z: f32, ks: f32, nu: f32) -> bool {
    u.is_finite()
        && u >= 0.0
        && z.is_finite()
        && z > 0.0
        && nu.is_finite()
        && nu > 0.0
        && ks.is_finite()
        && ks >= 0.0
}

/// The u* ranges (m/s) of the three z0 regimes above the sub-layer's top `sublayer_top`. With
/// ks = 0 the bed is smooth at every u*: the transitional and rough ranges start at infinity.
fn log_ranges(sublayer_top: f32, ks: f32, nu: f32) -> [(Roughness, f32, f32); 3] {
    let (smooth_top, rough_bottom) = if ks > 0.0 {
        (SMOOTH_RE_K * nu / ks, ROUGH_RE_K * nu / ks)
    } else {
        (f32::INFINITY, f32::INFINITY)
    };
    [
        (Roughness::Smooth, sublayer_top, smooth_top),
        (
            Roughness::Transitional,
            sublayer_top.max(smooth_top),
            rough_bottom,
        ),
        (
            Roughness::Rough,
            sublayer_top.max(rough_bottom),
            f32::INFINITY,
        ),
    ]
}

/// `d u / d u*` of the log law of `regime` at height `z` (the smooth and transitional ranges):
/// with `L = ln(z / z0)`, `u = u* L / kappa` and `z0 = a / u* + b` (a = 0.11 nu, b = 0 or
/// 0.033 ks), `du/du* = (L + a / (u* z0)) / kappa`.
fn profile_slope(regime: Roughness, z: f32, u_star: f32, ks: f32, nu: f32) -> f32 {
    let z0 = z0_in(regime, u_star, ks, nu);
    ((z / z0).ln() + Z0_SMOOTH * nu / (u_star * z0)) / KARMAN
}

/// The smallest u* of the bracket `(lo, hi)` at which the increasing profile `f` (with slope
/// `slope`) reaches `u`, to [`BISECTION_REL_TOL`]: `f(lo) < u <= f(hi)` on entry and after every
/// step, `excess` being `f(hi) - u` on entry. Newton's method starts from the top; the profile is convex there, so its steps come
/// down onto the root from above. Once a step would be shorter than half the tolerance it is
/// taken at that length, which crosses the root and closes the bracket. A step that would
/// leave the bracket (where the profile is not convex) bisects it instead.
fn narrow_bracket(
    u: f32,
    (mut lo, mut hi): (f32, f32),
    mut excess: f32,
    f: impl Fn(f32) -> f32,
    slope: impl Fn(f32) -> f32,
) -> FrictionVelocity {
    let mut x = hi;
    let mut iterations = 0;
    while hi - lo > BISECTION_REL_TOL * hi {
        if iterations == FRICTION_VELOCITY_MAX_ITERATIONS {
            return FrictionVelocity {
                u_star: hi,
                iterations,
                converged: false,
            };
        }
        let shortest = 0.5 * BISECTION_REL_TOL * x;
        let newton = excess / slope(x);
        let mut next = x - if newton.abs() < shortest {
            shortest.copysign(excess)
        } else {
            newton
        };
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
            if next <= lo || next >= hi {
                break;
            }
        }
        iterations += 1;
        (x, excess) = (next, f(next) - u);
        if excess >= 0.0 {
            hi = x;
        } else {
            lo = x;
        }
    }
    FrictionVelocity {
        u_star: hi,
        iterations,
        converged: true,
    }
}

/// Longitudinal slope factor of Eq. 22: `sin(phi - beta) / sin(phi)` for flow down the slope,
/// `sin(phi + beta) / sin(phi)` up it; beta and phi in rad, `0 < phi < pi/2`.
///
/// `beta` is the slope's magnitude (its sign is ignored: the direction is `flow_down_slope`).
/// Van Rijn's factor is meant for slopes below the friction angle; a steeper down-slope (beta >=
/// phi) cannot hold a grain at all, so the factor is clamped at 0 rather than turning the critical
/// stress, and through Eq. 15 the viscosity, negative.
pub fn k_beta(beta: f32, phi: f32, flow_down_slope: bool) -> f32 {
    let beta = beta.abs();
    let s = if flow_down_slope {
        (phi - beta).sin()
    } else {
        (phi + beta).sin()
    };
    // f32::max also maps a NaN (phi = 0) to 0.
    (s / phi.sin()).max(0.0)
}

/// Transverse slope factor of Eq. 23: `cos(gamma) sqrt(1 - tan^2(gamma) / tan^2(phi))`; gamma and
/// phi in rad, `0 < phi < pi/2`.
///
/// For `|gamma| >= phi` the square root has no real value: a side slope at or above the friction
/// angle cannot hold a grain, so the factor is 0.
pub fn k_gamma(gamma: f32, phi: f32) -> f32 {
    let gamma = gamma.abs();
    if gamma >= phi {
        return 0.0;
    }
    let r = gamma.tan() / phi.tan();
    gamma.cos() * (1.0 - r * r).max(0.0).sqrt()
}

/// Critical bed shear stress on a sloping bed, Eq. 24: `k_beta k_gamma tau_bcr0`, Pa.
pub fn sloped_critical_stress(tau_bcr0: f32, k_beta: f32, k_gamma: f32) -> f32 {
    k_beta * k_gamma * tau_bcr0
}

/// Surface test of Eq. 26: a sediment particle is near the bed surface when (i) a water particle
/// lies within its kernel support and (ii) its kernel mass sum over sediment neighbours,
/// `sum_j m_j W_ij V_j` (kg), is below `mass_fraction` (m_f, dimensionless) times the reference
/// mass `reference_mass` (kg; the sum deep inside the bed, about the particle mass since
/// `sum_j V_j W_ij` is about 1 there).
pub fn is_surface(
    has_water_neighbour: bool,
    kernel_mass: f32,
    reference_mass: f32,
    mass_fraction: f32,
) -> bool {
    has_water_neighbour && kernel_mass < mass_fraction * reference_mass
}

/// Result of [`critical_shields_self_consistent`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CriticalShields {
    /// Critical Shields parameter theta_cr, dimensionless.
    pub theta_cr: f32,
    /// Critical particle Reynolds number `Re* = u*_cr d / nu`, dimensionless.
    pub re_star: f32,
    /// Critical friction velocity `u*_cr = sqrt(theta_cr (rho_s / rho_w - 1) g d)`, m/s.
    pub u_star_cr: f32,
    /// Critical bed shear stress on a flat bed, Eq. 16, Pa.
    pub tau_bcr0: f32,
    /// Fixed-point steps taken.
    pub iterations: u32,
    /// `false` if the iteration did not settle within [`CRITICAL_SHIELDS_MAX_ITERATIONS`] steps;
    /// the fields then hold the last iterate.
    pub converged: bool,
}

/// Shields threshold with Eq. 17 evaluated at its own critical friction velocity: the theta_cr
/// with `theta_cr = f(Re*)`, `Re* = u*_cr d / nu`, `u*_cr = sqrt(theta_cr (rho_s / rho_w - 1) g d)`
/// (d in m, densities in kg/m3, nu in m2/s, g in m/s2).
///
/// Fixed point from theta = 0.068, stopped when a step changes theta by at most two f32 ulps.
/// Writing the step as theta -> f(Re*(theta)) with `Re* ~ sqrt(theta)`, its slope is
/// `(0.010595 - 0.110476 / Re*) / (2 theta)`, of magnitude about 0.5 or less for every Re* < 500
/// (0.5 as Re* -> 0, 0.42 at Re* = 1.2, under 0.1 above Re* = 20), so it converges, alternating
/// below Re* = 10.4, about as fast as halving or faster. Only in a sliver of grain sizes (Re*
/// between about 497 and 500), where theta = 0.068 puts Re* just under 500 and Eq. 17 just below
/// 500 puts it over, can it cycle across the jump; that is reported as not converged.
///
/// `None` for non-physical input: d, nu or g not positive and finite, or `rho_s <= rho_w` (a grain
/// that floats has no Shields threshold).
pub fn critical_shields_self_consistent(
    d: f32,
    rho_s: f32,
    rho_w: f32,
    nu: f32,
    g: f32,
) -> Option<CriticalShields> {
    let positive = |x: f32| x.is_finite() && x > 0.0;
    if !(positive(d) && positive(nu) && positive(g) && positive(rho_w) && rho_s.is_finite()) {
        return None;
    }
    let submerged = (rho_s / rho_w - 1.0) * g * d;
    if submerged.is_nan() || submerged <= 0.0 {
        return None;
    }
    let state = |theta: f32, iterations: u32, converged: bool| {
        let u_star_cr = (theta * submerged).sqrt();
        CriticalShields {
            theta_cr: theta,
            re_star: u_star_cr * d / nu,
            u_star_cr,
            tau_bcr0: critical_bed_shear_stress(theta, rho_s, rho_w, g, d),
            iterations,
            converged,
        }
    };
    let mut theta = THETA_CR_ROUGH;
    for iterations in 1..=CRITICAL_SHIELDS_MAX_ITERATIONS {
        let re_star = (theta * submerged).sqrt() * d / nu;
        let next = critical_shields(re_star);
        let change = (next - theta).abs();
        theta = next;
        if change <= 2.0 * f32::EPSILON * theta {
            return Some(state(theta, iterations, true));
        }
    }
    Some(state(theta, CRITICAL_SHIELDS_MAX_ITERATIONS, false))
}

/// `k_beta k_gamma` of Eqs. 22-24 from the bed's outward normal `n` (any length, pointing out of
/// the bed) and the flow velocity `u` over it, in `dim` dimensions (vertical axis `dim - 1`).
///
/// The slope is the normal's tilt: `tan(beta) = n_s / n_v` along the flow's horizontal direction
/// s, `tan(gamma) = |n_t| / n_v` across it (3-D only). The flow runs down the slope when the
/// normal leans the way the flow goes (`n_s > 0`). With no horizontal flow, or no normal, the
/// bed counts as flat (factor 1). A normal pointing down (the roof of a hole the jet dug) holds
/// no grain, whichever way the water flows: gravity pulls the grain off such a bed, so no
/// friction holds it (Eq. 22 assumes the grain rests on the bed; for up-slope flow it would
/// still give a positive factor up to beta = 180 deg - phi).
pub fn slope_factors(n: [f32; 3], u: [f32; 3], dim: u32, phi: f32) -> f32 {
    let v = (dim - 1) as usize;
    let horizontal = if dim == 2 { 1 } else { 2 };
    let speed_h: f32 = (0..horizontal).map(|k| u[k] * u[k]).sum::<f32>().sqrt();
    let n_len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if speed_h == 0.0 || n_len == 0.0 {
        return 1.0;
    }
    if n[v] < 0.0 {
        return 0.0;
    }
    let mut n_s = 0.0;
    for k in 0..horizontal {
        n_s += n[k] * u[k] / speed_h;
    }
    let n_t = if dim == 3 {
        (n[0] * u[1] - n[1] * u[0]) / speed_h
    } else {
        0.0
    };
    let beta = n_s.abs().atan2(n[v]);
    let gamma = n_t.abs().atan2(n[v]);
    k_beta(beta, phi, n_s > 0.0) * k_gamma(gamma, phi)
}

#[cfg(test)]
mod tests;
