//! CPU reference physics of the weakly compressible SPH solver (Zubeldia et al. 2018, Eqs. 4, 8-10,
//! with DualSPHysics' symplectic and Verlet integrators and DBC walls of Crespo et al. 2007).
//!
//! Everything here is plain f32 arithmetic over slices, written to be read as a spec: it is the
//! oracle the GPU shaders are tested against, so it follows the same formulas (not necessarily the
//! same summation order). The pair formulas are written over
//! [`lanes::Real`](crate::physics::lanes::Real), so that the CPU backend runs the very same code on
//! eight particles at once.
//!
//! Particle layout shared with the GPU:
//! - positions are `[x, y, z, w]` with `w = f32::from_bits(phase index)`;
//! - velocities are `[vx, vy, vz, rho]` (`vel_rho`), density in kg/m3 in `w`.
//!
//! In 2-D the plane is (x, y) with y vertical and z = 0; in 3-D z is vertical. The vertical axis is
//! index `dim - 1`.

pub mod boundary;
pub mod eos;
pub mod integrate;
pub mod interaction;
pub mod kernel;
pub mod lanes;
pub mod probe;
pub mod sediment;
pub mod timestep;

/// One material. Particles point into the phase table through the bits of `pos[i][3]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Phase {
    /// Rest density rho0 of the Tait equation of state, kg/m3.
    pub rho0: f32,
    /// Mass of one particle of this phase, kg (kg per metre of width in 2-D).
    pub mass: f32,
    /// Dynamic viscosity, Pa s; used by [`Viscosity::Laminar`] only.
    pub mu: f32,
    /// `false` for dynamic boundary (DBC) wall particles: they carry a density but never move.
    pub mobile: bool,
    /// A wall under the generalised wall condition: its density is the one the force pass
    /// gives it ([`boundary`]), stored as it is rather than integrated from a rate.
    pub generalised_wall: bool,
}

/// Viscosity model of the momentum equation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viscosity {
    /// Monaghan (1992) artificial viscosity in the DualSPHysics form; `alpha` is dimensionless.
    Artificial { alpha: f32 },
    /// Morris et al. (1997) laminar viscosity with each phase's dynamic viscosity `mu`.
    Laminar,
    /// Viscous stress from each particle's strain rate (Eqs. 10-15), added as the stress
    /// divergence of [`sediment::pass`]; here only Monaghan's artificial viscosity with
    /// coefficient `alpha` (0 for none). Water's viscosity there gains the sub-particle-scale
    /// eddy viscosity `rho sps_length2 |S|`, `sps_length2 = (C_s dp)^2` in m2 (0 for none).
    Multiphase { alpha: f32, sps_length2: f32 },
}

/// Numerical parameters of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// Number of space dimensions, 2 or 3.
    pub dim: u32,
    /// Smoothing length h, m (kernel support 2h).
    pub h: f32,
    /// Numerical speed of sound c0, m/s.
    pub c0: f32,
    /// Gravity acceleration, m/s2, `[x, y, z]` (z = 0 in 2-D, where y is vertical).
    pub gravity: [f32; 3],
    /// Subtract the hydrostatic density difference in the diffusion term (Fourtakas et al.
    /// 2019); without it the term is Molteni & Colagrossi 2009.
    pub hydrostatic_diffusion: bool,
    /// Density diffusion coefficient delta (dimensionless, typically 0.1); 0 turns it off.
    pub delta: f32,
    /// Viscosity model.
    pub viscosity: Viscosity,
    /// Negative pressures count as zero in the momentum equation (not in probes).
    pub clamp_negative_pressure: bool,
    /// Courant number C_CFL (dimensionless, typically 0.2).
    pub cfl: f32,
    /// Walls and held sediment by the generalised wall condition ([`boundary`]) instead of
    /// dynamic boundary particles.
    pub generalised_walls: bool,
    /// Phase table, indexed by the phase bits of the positions.
    pub phases: Vec<Phase>,
}
