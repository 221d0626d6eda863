//! `SimParams`, the uniform every stage reads, and the other blocks, each laid out as its WGSL
//! struct (`shaders_validate` checks the offsets against naga's layout of the WGSL, and every
//! constant stated on both sides by value).

use bytemuck::{Pod, Zeroable};

pub const MAX_PHASES: usize = 4;

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct PhaseParams {
    pub rho0: f32,
    pub mass: f32,
    pub mu: f32,
    /// 1.0 for fluid, 0.0 for DBC wall particles.
    pub mobile: f32,
}

/// `Sediment` of `shaders/common/params.wgsl` (units there).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct SedimentGpu {
    pub phase: u32,
    pub water_phase: u32,
    pub shields_only: u32,
    pub water_speed: u32,
    pub rho_s: f32,
    pub rho_w: f32,
    pub d50: f32,
    pub nu_w: f32,
    pub mu_w: f32,
    pub mu_s: f32,
    pub hbp_m: f32,
    pub hbp_n: f32,
    pub ks: f32,
    pub surface_mass: f32,
    pub dp_alpha: f32,
    pub dp_kappa: f32,
    pub phi: f32,
    pub mu_max: f32,
    pub submerged_weight: f32,
    pub pickup_per_s: f32,
    pub pickup_integrated: u32,
    pub exner_step_per_stage: f32,
    pub dp: f32,
    pub rests_beside_solid: u32,
}

/// `Flume` of `shaders/common/params.wgsl` (units there).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct FlumeGpu {
    pub enabled: u32,
    pub water_phase: u32,
    pub parked_phase: u32,
    pub parking_cols: u32,
    pub inlet_x_face: f32,
    pub inlet_y_min: f32,
    pub inlet_y_max: f32,
    pub inlet_u: f32,
    pub outlet_x: f32,
    pub collector_x_min: f32,
    pub collector_x_max: f32,
    pub collector_y_max: f32,
    pub parking_x0: f32,
    pub parking_y0: f32,
    pub parking_dp: f32,
    pub duct_x_min: f32,
    pub duct_y_min: f32,
    pub duct_y_max: f32,
    pub duct_u: f32,
    pub pad: f32,
}

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct SimParams {
    pub n_particles: u32,
    pub n_cells: u32,
    pub viscosity_mode: u32,
    pub diffusion_mode: u32,
    pub grid_dims: [u32; 4],
    pub grid_origin: [f32; 4],
    pub gravity: [f32; 4],
    pub h: f32,
    pub kernel_ad: f32,
    pub c0: f32,
    pub eta2: f32,
    pub delta_h_c0: f32,
    pub alpha: f32,
    pub cfl: f32,
    pub dt_visc: f32,
    pub dt_min: f32,
    pub rho_ratio_max: f32,
    pub vertical_axis: u32,
    pub n_probes: u32,
    pub euler_every: u32,
    pub clamp_pressure: u32,
    pub boundary_mode: u32,
    /// `(C_s dp)^2` of the multiphase model's sub-particle-scale viscosity, m2 (0: none).
    pub sps_length2: f32,
    pub phases: [PhaseParams; MAX_PHASES],
    pub tait_b: [f32; 4],
    pub sediment: SedimentGpu,
    pub flume: FlumeGpu,
}

pub const VISCOSITY_ARTIFICIAL: u32 = 0;
pub const VISCOSITY_LAMINAR: u32 = 1;
pub const VISCOSITY_MULTIPHASE: u32 = 2;
pub const BOUNDARY_DYNAMIC: u32 = 0;
pub const BOUNDARY_GENERALISED: u32 = 1;
pub const DIFFUSION_NONE: u32 = 0;
pub const DIFFUSION_MOLTENI: u32 = 1;
pub const DIFFUSION_FOURTAKAS: u32 = 2;

/// Entries of `StepState::excluded_log` (`EXCLUDED_LOG_LEN` of step_state.wgsl too).
pub const EXCLUDED_LOG_LEN: usize = 8;

/// `ExcludedParticle` of `shaders/common/step_state.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct ExcludedParticle {
    pub id: u32,
    pub phase: u32,
    pub x: f32,
    pub y: f32,
    pub u: f32,
    pub v: f32,
    pub rho: f32,
    pub pad: u32,
}

/// `StepState` of `shaders/common/step_state.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct StepState {
    pub dt: f32,
    pub t_rel: f32,
    pub t_target: f32,
    pub steps: u32,
    pub dt_min_bits: u32,
    pub status: u32,
    pub last_dt: f32,
    pub step_base: u32,
    pub dt_prev: f32,
    pub dt_taken: f32,
    pub eroded: u32,
    pub parked: u32,
    pub excluded: u32,
    pub excluded_sediment: u32,
    pub run_steps: u32,
    pub pad: u32,
    pub excluded_log: [ExcludedParticle; EXCLUDED_LOG_LEN],
}

impl FlumeGpu {
    /// Whether `x` lies in the inlet's buffer zone, where the inlet sets the velocity
    /// (`flume.wgsl`'s `in_inlet`).
    pub fn in_inlet(&self, x: &[f32; 4]) -> bool {
        x[0] < self.inlet_x_face && x[1] > self.inlet_y_min && x[1] <= self.inlet_y_max
    }

    /// Where particle `id` waits while parked, with the parked phase (`store_rule.wgsl`).
    pub fn parking_spot(&self, id: u32) -> [f32; 4] {
        [
            self.parking_x0 + (id % self.parking_cols) as f32 * self.parking_dp,
            self.parking_y0 + (id / self.parking_cols) as f32 * self.parking_dp,
            0.0,
            f32::from_bits(self.parked_phase),
        ]
    }
}

impl StepState {
    /// The state at the start of a chunk that ends `t_target` seconds later, `run_steps` steps
    /// (wrapping) and `step_base` steps modulo the Verlet Euler period after the start of the
    /// run, the last step having been `dt_taken` long and its CFL step `last_dt`.
    pub fn chunk(
        t_target: f32,
        (last_dt, dt_taken): (f32, f32),
        (run_steps, step_base): (u32, u32),
    ) -> StepState {
        StepState {
            dt: 0.0,
            t_rel: 0.0,
            t_target,
            steps: 0,
            dt_min_bits: f32::MAX.to_bits(),
            status: 0,
            last_dt,
            step_base,
            dt_prev: 0.0,
            dt_taken,
            eroded: 0,
            parked: 0,
            excluded: 0,
            excluded_sediment: 0,
            run_steps,
            pad: 0,
            excluded_log: [ExcludedParticle::zeroed(); EXCLUDED_LOG_LEN],
        }
    }
}

/// `Extremes` of `shaders/stages/observe_reduce.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct Extremes {
    pub front_key: u32,
    pub max_speed_bits: u32,
    pub max_rho_err_bits: u32,
    pub fluid_count: u32,
}

/// Inverse of the shader's `order_key`.
pub fn from_order_key(k: u32) -> f32 {
    if k & 0x8000_0000 != 0 {
        f32::from_bits(k & 0x7fff_ffff)
    } else {
        f32::from_bits(!k)
    }
}

/// `ScanInfo` of `shaders/stages/prefix_sum.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct ScanInfo {
    pub n: u32,
    pub pad: [u32; 3],
}

/// `InletQuery` of `shaders/stages/inlet_scan.wgsl`: the inlet's spots to check and
/// the square of the distance within which a particle occupies one, m2.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct InletQuery {
    pub n_spots: u32,
    pub radius2: f32,
    pub pad: [u32; 2],
}

/// Maps f32 to u32 so that unsigned order is float order (negative values too), as the
/// shader's `order_key` in observe_reduce.wgsl does.
pub fn order_key(x: f32) -> u32 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

impl SimParams {
    /// The pair and particle formulas' parameters (`solver::physics`) for this uniform, of a
    /// case in `dim` dimensions with `n_phases` phases (walls included).
    /// Whether held sediment stands as a wall (`physics::boundary`): the Shields-only mode's
    /// holds under the generalised wall condition, with the multiphase model that holds them
    /// (`held_bed_is_wall` in `params.wgsl`).
    pub fn held_bed_is_wall(&self) -> bool {
        self.boundary_mode == BOUNDARY_GENERALISED
            && self.viscosity_mode == VISCOSITY_MULTIPHASE
            && self.sediment.phase != 0
            && self.sediment.shields_only != 0
    }

    pub fn physics(&self, dim: u32, n_phases: usize) -> crate::physics::Params {
        use crate::physics::{Params, Phase, Viscosity};
        Params {
            dim,
            h: self.h,
            c0: self.c0,
            gravity: [self.gravity[0], self.gravity[1], self.gravity[2]],
            delta: self.delta_h_c0 / (self.h * self.c0),
            hydrostatic_diffusion: self.diffusion_mode == DIFFUSION_FOURTAKAS,
            clamp_negative_pressure: self.clamp_pressure != 0,
            generalised_walls: self.boundary_mode == BOUNDARY_GENERALISED,
            viscosity: match self.viscosity_mode {
                VISCOSITY_ARTIFICIAL => Viscosity::Artificial { alpha: self.alpha },
                VISCOSITY_LAMINAR => Viscosity::Laminar,
                _ => Viscosity::Multiphase {
                    alpha: self.alpha,
                    sps_length2: self.sps_length2,
                },
            },
            cfl: self.cfl,
            phases: self.phases[..n_phases.min(MAX_PHASES)]
                .iter()
                .map(|ph| Phase {
                    rho0: ph.rho0,
                    mass: ph.mass,
                    mu: ph.mu,
                    mobile: ph.mobile > 0.5,
                    generalised_wall: ph.mobile <= 0.5
                        && self.boundary_mode == BOUNDARY_GENERALISED,
                })
                .collect(),
        }
    }
}
