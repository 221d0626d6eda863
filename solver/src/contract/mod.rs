//! The contract both engines run on: the uniform blocks (`SimParams`, `StepState` and the
//! sediment's and the flume's, in `blocks`, laid out for WGSL) and their builder from a case:
//! numerics, phases, the sediment model and the open flume. The CPU backend reads the same
//! blocks as the wgpu one, and the sediment model of `physics` that both are tested against
//! comes from the same case here.

mod blocks;

pub use blocks::*;

use crate::config::{
    BoundaryMethod, Case, ComesToRest, DensityDiffusion, Erosion, Integrator, ShieldsSpeed,
    Viscosity, YieldCriterion,
};
use crate::derived::{self, Derived};
use crate::flume::inlet_velocity;
use crate::health::{RHO_RATIO_EXCLUDE, RHO_RATIO_MAX};
use crate::particles::{Parking, parked_phase};
use crate::physics::sediment::SedimentParams;
use crate::physics::sediment::pass::SedimentModel;
use crate::physics::sediment::pickup::{pickup_per_s, saltation_length_per_stage};
use bytemuck::Zeroable;

pub fn sim_params(
    case: &Case,
    derived: &Derived,
    n: u32,
    grid_dims: [u32; 4],
    grid_origin: [f32; 4],
    n_probes: u32,
) -> SimParams {
    let d = case.dim();
    let h = derived.h;
    let mut gravity = [0.0f32; 4];
    for (gk, v) in gravity.iter_mut().zip(&case.gravity_m_per_s2) {
        *gk = *v as f32;
    }
    gravity[3] = (-case.gravity_m_per_s2[d - 1]) as f32;
    let (phases, tait_b, dt_visc) = phase_blocks(case, derived);
    let (viscosity_mode, alpha, sps_length2) = viscosity_block(case, derived);
    let (diffusion_mode, delta) = match case.numerics.density_diffusion {
        DensityDiffusion::None => (DIFFUSION_NONE, 0.0),
        DensityDiffusion::MolteniColagrossi2009 { delta } => (DIFFUSION_MOLTENI, delta),
        DensityDiffusion::Fourtakas2019 { delta } => (DIFFUSION_FOURTAKAS, delta),
    };
    let kernel_ad = crate::physics::kernel::alpha_d(case.dimension, h as f32);
    SimParams {
        n_particles: n,
        n_cells: grid_dims[3],
        viscosity_mode,
        diffusion_mode,
        grid_dims: [grid_dims[0], grid_dims[1], grid_dims[2], 0],
        grid_origin,
        gravity,
        h: h as f32,
        kernel_ad,
        c0: derived.c0 as f32,
        eta2: (0.01 * h * h) as f32,
        delta_h_c0: (delta * h * derived.c0) as f32,
        alpha: alpha as f32,
        cfl: case.numerics.cfl as f32,
        dt_visc: dt_visc as f32,
        // A step a million times below the acoustic one means the state has gone bad.
        dt_min: (1e-6 * h / derived.c0) as f32,
        // An open flume excludes a free particle beyond this (store_rule.wgsl); in a closed
        // tank it is a runaway.
        rho_ratio_max: if case.open_flume.is_some() {
            RHO_RATIO_EXCLUDE
        } else {
            RHO_RATIO_MAX
        },
        vertical_axis: (d - 1) as u32,
        n_probes,
        euler_every: match case.numerics.integrator {
            Integrator::Verlet { euler_every_steps } => euler_every_steps,
            Integrator::Symplectic => 1,
        },
        clamp_pressure: u32::from(case.numerics.clamp_negative_pressure),
        boundary_mode: match case.numerics.boundary {
            BoundaryMethod::Dynamic => BOUNDARY_DYNAMIC,
            BoundaryMethod::Generalised => BOUNDARY_GENERALISED,
        },
        sps_length2,
        phases,
        tait_b,
        sediment: sediment_params(case, derived),
        flume: flume_params(case, derived),
    }
}

/// Each phase's block, its Tait coefficient, and the viscous step bound of a laminar
/// viscosity (s; f32::MAX where none binds).
fn phase_blocks(case: &Case, derived: &Derived) -> ([PhaseParams; MAX_PHASES], [f32; 4], f64) {
    let h = derived.h;
    let mut phases = [PhaseParams {
        rho0: 1000.0,
        mass: 0.0,
        mu: 0.0,
        mobile: 0.0,
    }; MAX_PHASES];
    let mut tait_b = [1.0f32; 4];
    let mut dt_visc = f64::from(f32::MAX);
    for (k, p) in derived.phases.iter().enumerate() {
        phases[k] = PhaseParams {
            rho0: p.rho0 as f32,
            mass: p.mass as f32,
            mu: p.viscosity_pa_s as f32,
            mobile: if p.mobile { 1.0 } else { 0.0 },
        };
        tait_b[k] = derived::tait_b(derived.c0, p.rho0) as f32;
        if p.mobile
            && p.viscosity_pa_s > 0.0
            && matches!(case.numerics.viscosity, Viscosity::Laminar)
        {
            dt_visc = dt_visc.min(0.125 * h * h * p.rho0 / p.viscosity_pa_s);
        }
    }
    (phases, tait_b, dt_visc)
}

/// The viscosity's mode, its artificial alpha (an eddy viscosity given as one), and the
/// Smagorinsky length squared (m2; 0 without).
fn viscosity_block(case: &Case, derived: &Derived) -> (u32, f64, f32) {
    let (h, c0) = (derived.h, derived.c0);
    match case.numerics.viscosity {
        Viscosity::Artificial { alpha } => (VISCOSITY_ARTIFICIAL, alpha, 0.0),
        Viscosity::Laminar => (VISCOSITY_LAMINAR, 0.0, 0.0),
        Viscosity::Multiphase {
            alpha,
            eddy_m2_per_s,
            smagorinsky_cs,
        } => (
            VISCOSITY_MULTIPHASE,
            alpha + derived::monaghan_alpha(eddy_m2_per_s, h, c0, case.dim()),
            (smagorinsky_cs * case.numerics.dp_m).powi(2) as f32,
        ),
    }
}

/// The open-flume block of the uniform; all zero (disabled) for a closed tank. The inlet
/// velocity starts from the case's discharge.
fn flume_params(case: &Case, derived: &Derived) -> FlumeGpu {
    let Some(f) = &case.open_flume else {
        return FlumeGpu::zeroed();
    };
    let dp = case.numerics.dp_m;
    let parking = Parking::new(case, derived.h);
    let (lo, hi) = (&case.domain.min_m, &case.domain.max_m);
    // An empty box (y_max = y_min) when there is no bottom outlet.
    let duct = f.bottom_outlet.as_ref().map_or([0.0; 4], |o| {
        [o.x_min_m, o.y_min_m, o.y_max_m, o.velocity_m_s]
    });
    FlumeGpu {
        enabled: 1,
        water_phase: 1 + case.sediment_phases().map_or(0, |(_, w)| w) as u32,
        parked_phase: parked_phase(case),
        parking_cols: parking.cols,
        inlet_x_face: (lo[0] + (f64::from(f.inlet.layers) + 0.5) * dp) as f32,
        // Half a dp of margin each way: the buffer's rows are lattice points inside the
        // opening, and a row must not drop out of the zone by rounding.
        inlet_y_min: f.inlet.y_min_m as f32,
        inlet_y_max: (f.inlet.y_min_m + f.inlet.height_m + 0.5 * dp) as f32,
        inlet_u: inlet_velocity(f, f.inflow_m3_per_s, dp) as f32,
        outlet_x: (hi[0] + f64::from(case.walls.layers) * dp) as f32,
        collector_x_min: f.collector.x_min_m as f32,
        collector_x_max: f.collector.x_max_m as f32,
        collector_y_max: f.collector.y_max_m as f32,
        parking_x0: parking.x0 as f32,
        parking_y0: parking.y0 as f32,
        parking_dp: dp as f32,
        duct_x_min: duct[0] as f32,
        duct_y_min: duct[1] as f32,
        duct_y_max: duct[2] as f32,
        duct_u: duct[3] as f32,
        pad: 0.0,
    }
}

/// The sediment block of the uniform; all zero (phase 0, the walls) when the case has none.
fn sediment_params(case: &Case, derived: &Derived) -> SedimentGpu {
    let Some((k_sed, k_water)) = case.sediment_phases() else {
        return SedimentGpu::zeroed();
    };
    let sed = &case.phases[k_sed];
    let Some(cfg) = &sed.sediment else {
        return SedimentGpu::zeroed();
    };
    let water = &case.phases[k_water];
    let phi = cfg.friction_angle_deg.to_radians();
    let rho_s = sed.rho0_kg_per_m3;
    let rho_w = water.rho0_kg_per_m3;
    let mass = derived.phases[k_sed + 1].mass;
    let mu_max = cfg
        .max_viscosity_pa_s
        .unwrap_or(0.125 * derived.h * rho_s * derived.c0);
    SedimentGpu {
        phase: (k_sed + 1) as u32,
        water_phase: (k_water + 1) as u32,
        shields_only: u32::from(cfg.criterion == YieldCriterion::ShieldsOnly),
        water_speed: u32::from(cfg.shields_speed == ShieldsSpeed::Water),
        rests_beside_solid: u32::from(cfg.comes_to_rest == ComesToRest::BesideASolid),
        rho_s: rho_s as f32,
        rho_w: rho_w as f32,
        d50: cfg.d50_m as f32,
        nu_w: (water.viscosity_pa_s / rho_w) as f32,
        mu_w: water.viscosity_pa_s as f32,
        mu_s: sed.viscosity_pa_s as f32,
        hbp_m: cfg.hbp_m_s as f32,
        hbp_n: cfg.hbp_n as f32,
        ks: (cfg.ks_over_d50 * cfg.d50_m) as f32,
        surface_mass: (cfg.surface_mass_fraction * mass) as f32,
        dp_alpha: crate::physics::sediment::drucker_prager::alpha(phi as f32),
        dp_kappa: crate::physics::sediment::drucker_prager::kappa_c(
            phi as f32,
            cfg.cohesion_pa as f32,
        ),
        phi: phi as f32,
        mu_max: mu_max as f32,
        submerged_weight: ((rho_s - rho_w) * case.gravity_magnitude()) as f32,
        pickup_per_s: match cfg.erosion {
            Erosion::Threshold => 0.0,
            Erosion::VanRijnPickup | Erosion::VanRijnIntegrated | Erosion::VanRijnExner => {
                pickup_per_s(
                    cfg.d50_m,
                    rho_s,
                    rho_w,
                    water.viscosity_pa_s / rho_w,
                    case.gravity_magnitude(),
                    case.numerics.dp_m,
                ) as f32
            }
        },
        pickup_integrated: u32::from(matches!(
            cfg.erosion,
            Erosion::VanRijnIntegrated | Erosion::VanRijnExner
        )),
        exner_step_per_stage: match cfg.erosion {
            Erosion::VanRijnExner => {
                let length = saltation_length_per_stage(
                    cfg.d50_m,
                    rho_s,
                    rho_w,
                    water.viscosity_pa_s / rho_w,
                    case.gravity_magnitude(),
                );
                (length / case.numerics.dp_m) as f32
            }
            _ => 0.0,
        },
        dp: case.numerics.dp_m as f32,
    }
}

/// The sediment model of `physics` for the case's sediment, None when it has none: what the CPU
/// backend runs, from the same fields as the uniform's sediment block.
pub fn sediment_model(case: &Case, derived: &Derived) -> Option<SedimentModel> {
    let (k_sed, k_water) = case.sediment_phases()?;
    let sed = &case.phases[k_sed];
    let cfg = sed.sediment.as_ref()?;
    let water = &case.phases[k_water];
    let block = sediment_params(case, derived);
    Some(SedimentModel {
        material: SedimentParams {
            rho_s: sed.rho0_kg_per_m3 as f32,
            d50_m: cfg.d50_m as f32,
            phi_rad: cfg.friction_angle_deg.to_radians() as f32,
            cohesion_pa: cfg.cohesion_pa as f32,
            hbp_m: cfg.hbp_m_s as f32,
            hbp_n: cfg.hbp_n as f32,
            mu_s_pa_s: sed.viscosity_pa_s as f32,
            ks_over_d50: cfg.ks_over_d50 as f32,
            surface_mass_fraction: cfg.surface_mass_fraction as f32,
            rho_w: water.rho0_kg_per_m3 as f32,
            nu_w: (water.viscosity_pa_s / water.rho0_kg_per_m3) as f32,
            mu_w: water.viscosity_pa_s as f32,
        },
        sediment_phase: k_sed + 1,
        water_phase: k_water + 1,
        shields_only: cfg.criterion == YieldCriterion::ShieldsOnly,
        water_speed: cfg.shields_speed == ShieldsSpeed::Water,
        rests_beside_solid: block.rests_beside_solid != 0,
        mu_max: block.mu_max,
        pickup_per_s: block.pickup_per_s,
        pickup_integrated: block.pickup_integrated != 0,
        exner_step_per_stage: block.exner_step_per_stage,
        dp_m: block.dp,
    })
}
