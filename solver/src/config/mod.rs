//! Case files: one YAML document per case (see `launch_configs/`): the serde types here, their
//! checks in `validate.rs`.
//!
//! Every length is in metres, every time in seconds, and the unit is part of the field name
//! (`dp_m`, `end_s`). Unknown fields are rejected so that a misspelt key cannot silently fall
//! back to a default. Parse errors and validation errors both name the offending field.
//!
//! `Case::from_path` and `Case::from_yaml` live in `crate::load`: a case is refused up front
//! when what it asks passes a limit set by its derived sound speed (`crate::derived`), and
//! derivation reads these types, so the loader sits above both.

mod validate;

use serde::Deserialize;

/// Why a case file was refused. `field` is the dotted path of the key (`numerics.dp_m`).
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read case file {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("case file {path}: field `{field}`: {reason}")]
    Parse {
        path: String,
        field: String,
        reason: String,
    },
    #[error("case file {path}: field `{field}`: {reason}")]
    Invalid {
        path: String,
        field: String,
        reason: String,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// A short name used in output file names and logs.
    pub name: String,
    /// 2 (x along the flume, y up) or 3 (x along, y across, z up).
    pub dimension: u32,
    /// The tank: its inner faces are the box `min_m`..`max_m` (one coordinate per dimension).
    pub domain: Domain,
    /// Dynamic boundary particles (DBC, Crespo et al. 2007) on the tank's faces.
    pub walls: Walls,
    /// The fluid and sediment phases; walls take the density of the first phase.
    pub phases: Vec<PhaseConfig>,
    /// Blocks of particles, filled on the dp lattice.
    pub fluid_blocks: Vec<FluidBlock>,
    pub numerics: Numerics,
    /// Gravity in m/s2, one component per dimension (the last one is vertical).
    pub gravity_m_per_s2: Vec<f64>,
    pub time: TimeControl,
    #[serde(default)]
    pub observations: ObservationConfig,
    /// Inlet, outlet and sediment collector of an open flume (2-D); absent for a closed tank.
    #[serde(default)]
    pub open_flume: Option<OpenFlume>,
}

/// An open flume (2-D). Water enters through an inlet at the upstream (x-min) wall, whose
/// velocity follows the discharge, leaves over the downstream (x-max) wall's weir, and sediment
/// reaching the collector is counted as eroded (Eq. 34) and recycled as water. The particle
/// count never changes: particles that leave are parked out of the flow, and the inlet draws
/// on the parked ones, lowest id first.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpenFlume {
    /// Width of the flume across the 2-D plane, m: the discharge Q becomes the inlet velocity
    /// Q / (inlet height x width), and the eroded mass per metre times the width is in kg.
    pub width_m: f64,
    /// Discharge at the start, m3/s (changed at run time with `Simulation::set_boundary_conditions`).
    #[serde(default)]
    pub inflow_m3_per_s: f64,
    pub inlet: InletConfig,
    /// Height of the downstream wall, m: fluid that flows over it and past it leaves the flume.
    pub outlet_weir_m: f64,
    /// Sediment entering this box is eroded: counted, and recycled as water.
    pub collector: CollectorConfig,
    /// A regulated bottom outlet (an orifice behind which a valve sets the velocity), for a
    /// reservoir flushed through its downstream wall; absent for a flume that spills over its weir.
    #[serde(default)]
    pub bottom_outlet: Option<BottomOutlet>,
    /// The sill that ends the sand bed in front of the collector, as a sediment trap's lip.
    #[serde(default)]
    pub sill: Option<SillConfig>,
    /// Water particles parked at the start, for the inlet to draw on before any has left.
    pub reservoir_particles: u32,
}

/// The inlet: an opening in the upstream wall from `y_min_m` to `y_min_m + height_m`, fed by a
/// buffer of `layers` columns of water particles next to the wall that move at the inlet
/// velocity; a new column enters behind them each time they have moved one dp.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InletConfig {
    pub y_min_m: f64,
    pub height_m: f64,
    #[serde(default = "default_inlet_layers")]
    pub layers: u32,
}

fn default_inlet_layers() -> u32 {
    4
}

/// The duct behind a bottom outlet: water with x >= `x_min_m` and `y_min_m` < y <= `y_max_m`
/// moves downstream at `velocity_m_s`, so the discharge is velocity x (y_max - y_min) x width
/// whatever the head, as a valve sets it. The duct's floor and roof are wall blocks.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BottomOutlet {
    pub x_min_m: f64,
    pub y_min_m: f64,
    pub y_max_m: f64,
    pub velocity_m_s: f64,
}

/// A wall from the floor, x from `x_min_m` to `x_max_m`, whose top row of particles stands one
/// lattice row under the sediment bed's top row at every dp. The bed's top row is the layer
/// that erodes and slides; the held row under it is the bed the sliding grains move on. A crest
/// level with the top row would be a step one particle high in the sliding layer's path, where
/// a real trap's lip, level with the bed's surface, lets them pass.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SillConfig {
    pub x_min_m: f64,
    pub x_max_m: f64,
}

/// A box, m: x from `x_min_m` to `x_max_m`, below `y_max_m`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollectorConfig {
    pub x_min_m: f64,
    pub x_max_m: f64,
    pub y_max_m: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Domain {
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Walls {
    /// Number of boundary-particle layers, stacked outwards from each wall face.
    #[serde(default = "one")]
    pub layers: u32,
    /// Whether the top of the tank is closed by a wall too.
    #[serde(default)]
    pub closed_top: bool,
    /// Solid blocks inside the tank, filled with wall particles on the dp lattice like fluid
    /// blocks (a fixed apron under an inlet, a step, an obstacle).
    #[serde(default)]
    pub blocks: Vec<WallBlock>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallBlock {
    /// Lattice points with `min_m < x <= max_m` in every coordinate are wall.
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
}

fn one() -> u32 {
    1
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhaseConfig {
    pub name: String,
    /// Rest density of the phase's equation of state, kg/m3.
    pub rho0_kg_per_m3: f64,
    /// Dynamic viscosity, Pa s: the laminar viscosity, the water's mu_w of Eq. 11 or the
    /// sediment's mu_s of Eq. 15.
    #[serde(default = "water_viscosity")]
    pub viscosity_pa_s: f64,
    /// Makes this phase an erodible, saturated sediment bed (Zubeldia et al. 2018); absent for
    /// water. Needs `numerics.viscosity.method: multiphase`.
    #[serde(default)]
    pub sediment: Option<SedimentConfig>,
}

/// Material of a sediment phase; the phase's `rho0_kg_per_m3` is its saturated density rho_s
/// and its `viscosity_pa_s` the mu_s of the HBP law (Eq. 15).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SedimentConfig {
    /// Median grain diameter d50, m (Eqs. 16-17).
    pub d50_m: f64,
    /// Internal friction angle phi, degrees (Eqs. 22-23, 29).
    pub friction_angle_deg: f64,
    /// Cohesion c, Pa (Eq. 29).
    #[serde(default)]
    pub cohesion_pa: f64,
    /// Papanastasiou exponent m of Eq. 15, s (0 with n = 1: Newtonian).
    pub hbp_m_s: f64,
    /// Power-law index n of Eq. 15.
    pub hbp_n: f64,
    /// Equivalent roughness over grain size, ks / d50 (Eq. 21).
    pub ks_over_d50: f64,
    /// Fraction m_f of a full kernel's sediment mass below which a particle with water in its
    /// support is at the bed surface (Eq. 26).
    #[serde(default = "default_surface_mass_fraction")]
    pub surface_mass_fraction: f64,
    /// Which yield criteria apply.
    pub criterion: YieldCriterion,
    /// When a held particle that Shields releases leaves the bed.
    #[serde(default)]
    pub erosion: Erosion,
    /// The speed the log law of Eqs. 19-21 reads from the nearest water particle.
    #[serde(default)]
    pub shields_speed: ShieldsSpeed,
    /// Where a moving grain that Figure 2 would hold may come to rest.
    #[serde(default)]
    pub comes_to_rest: ComesToRest,
    /// Cap on the apparent viscosity, Pa s. Without it, mu_max = 0.125 h rho_s c0: the
    /// viscosity whose explicit diffusion limit `0.125 h^2 rho / mu` equals the acoustic step
    /// `h / c0`, so the sediment never shortens the time step below what the water needs.
    #[serde(default)]
    pub max_viscosity_pa_s: Option<f64>,
    /// The dry bed's pores, which the water fills from above where it first covers the bed
    /// (`simulation::pores`); without them the sand holds no water, as in the paper's model.
    #[serde(default)]
    pub pores: Option<BedPores>,
}

/// Pores of a sand bed laid dry, filled by Green & Ampt's (1911) infiltration
/// (`physics::sediment::infiltration`).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BedPores {
    /// Volume of the pores over the bed's, 0-1: the water a dry bed takes, all of it
    /// (the moisture deficit of a dry bed).
    pub porosity: f64,
    /// Saturated hydraulic conductivity K, m/s.
    pub conductivity_m_per_s: f64,
    /// Suction head at the wetting front psi_f, m.
    pub suction_m: f64,
}

/// Yield criteria of a sediment phase (Zubeldia et al. 2018, Section 2.5).
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum YieldCriterion {
    /// Drucker-Prager below the surface, Shields at the surface (Section 2.5.4, Figure 2).
    DruckerPragerShields,
    /// Shields at the surface only; sediment that is not eroded or suspended is held fixed
    /// (the paper's flushing and flume cases).
    ShieldsOnly,
}

/// When a held sediment particle whose bed shear stress passes Shields' threshold is released.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Erosion {
    /// At once (Eq. 25), as the paper does: a grain's rule.
    #[default]
    Threshold,
    /// At van Rijn's (1984) pick-up rate: a particle is released in a step with the chance that
    /// the flow picks up its mass from its share of the bed (`physics::sediment::pickup`).
    VanRijnPickup,
    /// At van Rijn's (1984) pick-up rate, worn away: a particle is released once the rate,
    /// integrated over the steps it is held, has taken its whole mass
    /// (`physics::sediment::pickup::integrated_pickup`). A front that passes in a second
    /// wears a fraction of a particle off, as it takes a fraction of a millimetre off the real
    /// bed, where a chance each step lifts a whole particle here and there.
    VanRijnIntegrated,
    /// Worn away as `van_rijn_integrated`, net of the bed load that settles on the particle
    /// from those that pass theirs to it (Exner's balance: what each passes on is the load the
    /// flow can carry, its pick-up times van Rijn's 1984 saltation length, but no more than it
    /// was passed plus its pick-up; `physics::sediment::pickup::exner_exchange`). A bed under a
    /// flow the same all along it then neither wears nor roughens; it wears where the flow
    /// quickens and builds up where it slows.
    VanRijnExner,
}

/// The u of the log law (Eqs. 19-21) that the Shields test reads from the nearest water
/// particle.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ShieldsSpeed {
    /// Its velocity relative to the grain: what every test and figure before 2026-11-28 was
    /// measured with. A grain carried at the water's speed sees no shear and is held at the next
    /// step, its velocity zeroed, so how far the sand goes depends on the time step
    /// (docs/scour/README.md, "The step moves the sand").
    #[default]
    RelativeToGrain,
    /// Its own velocity, the flow's over a bed at rest, as `MODEL.md` states Eq. 20's u.
    Water,
}

/// Where a moving sediment particle that Figure 2 would hold is held again
/// (`physics::sediment::suspension::sediment_region`).
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ComesToRest {
    /// Wherever it lies, as the paper's model holds it.
    #[default]
    Anywhere,
    /// Only with a solid (sand or wall) beside it at its own level: a grain alone on the bed's
    /// top stays bed load, where held it would be a step of one dp, 45 degrees, in a flow a
    /// few particles deep (the README's sediment section).
    BesideASolid,
}

fn default_surface_mass_fraction() -> f64 {
    0.9
}

fn water_viscosity() -> f64 {
    1.0e-3
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidBlock {
    /// Name of a phase in `phases`.
    pub phase: String,
    /// Lattice points with `min_m < x <= max_m` in every coordinate are filled
    /// (the lattice is the integer multiples of dp, as in DualSPHysics' GenCase).
    pub min_m: Vec<f64>,
    pub max_m: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Numerics {
    /// Initial particle spacing, m.
    pub dp_m: f64,
    /// h = coefh * sqrt(dimension) * dp (DualSPHysics convention).
    #[serde(default = "default_coefh")]
    pub coefh: f64,
    /// Courant number of the variable time step.
    #[serde(default = "default_cfl")]
    pub cfl: f64,
    pub sound_speed: SoundSpeed,
    pub density_diffusion: DensityDiffusion,
    pub viscosity: Viscosity,
    /// Time integration; symplectic when omitted.
    #[serde(default)]
    pub integrator: Integrator,
    /// No tension: fluid densities never fall below rest and negative pressures count as zero
    /// in the momentum equation. A thin sheet of water (the flume's jet before the bed is wet)
    /// has too few neighbours, its density falls below rest, and the tension pulls its
    /// particles into clumps that then collide (the tensile instability); water does not
    /// sustain that tension anyway. Off by default.
    #[serde(default)]
    pub clamp_negative_pressure: bool,
    /// How walls and held sediment push back on the fluid; dynamic (DBC) when omitted.
    #[serde(default)]
    pub boundary: BoundaryMethod,
}

/// The boundary condition of walls and held (un-yielded) sediment.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, rename_all = "snake_case", tag = "method")]
pub enum BoundaryMethod {
    /// Dynamic boundary particles (Crespo et al. 2007): density from the continuity equation.
    #[default]
    Dynamic,
    /// The generalised wall condition of Adami, Hu & Adams (2012): each boundary particle takes
    /// the pressure of the fluid around it plus the hydrostatic term (`physics::boundary`).
    Generalised,
}

/// Time integration scheme (both as in DualSPHysics).
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, rename_all = "snake_case", tag = "method")]
pub enum Integrator {
    /// Symplectic position Verlet: predictor and corrector, two force passes a step.
    #[default]
    Symplectic,
    /// Verlet (Verlet 1967, DualSPHysics' default): one force pass a step, with an Euler step
    /// every `euler_every_steps` steps to keep the leapfrog's two sequences together.
    Verlet { euler_every_steps: u32 },
}

fn default_coefh() -> f64 {
    1.2
}
fn default_cfl() -> f64 {
    0.2
}

/// The numerical speed of sound c0 of the Tait equation (Eq. 5): give exactly one of the two.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SoundSpeed {
    /// c0 given directly, m/s.
    pub c0_m_per_s: Option<f64>,
    /// c0 = coefsound * sqrt(|g| * H), H the height of the fluid (DualSPHysics' `coefsound`).
    pub coefsound: Option<f64>,
}

/// Density diffusion (delta-SPH) in the continuity equation.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case", tag = "method")]
pub enum DensityDiffusion {
    None,
    /// Molteni & Colagrossi 2009.
    MolteniColagrossi2009 {
        delta: f64,
    },
    /// Molteni-Colagrossi with the hydrostatic correction of Fourtakas et al. 2019.
    Fourtakas2019 {
        delta: f64,
    },
}

#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case", tag = "method")]
pub enum Viscosity {
    /// Monaghan 1992 artificial viscosity with coefficient alpha.
    Artificial { alpha: f64 },
    /// Laminar viscosity (Morris et al. 1997) with each phase's `viscosity_pa_s`.
    Laminar,
    /// The viscous stress tau = 2 mu eps of Eqs. 10-11 and 14 from each particle's strain rate,
    /// mu the water's viscosity or, for sediment, the apparent viscosity of its region; plus,
    /// with `alpha` > 0, Monaghan's artificial viscosity on every pair: water's own viscosity
    /// does next to nothing at these resolutions, and a violent flow (the flume's jet) needs
    /// some damping of particle noise, as the water-only cases get from `artificial`.
    Multiphase {
        #[serde(default)]
        alpha: f64,
        /// The Smagorinsky constant C_s of the sub-particle-scale eddy viscosity that water adds
        /// to its own (Dalrymple & Rogers 2006, as DualSPHysics' laminar + SPS): mu_t =
        /// rho (C_s dp)^2 |S|, |S| = sqrt(2 S:S). 0 (the default) for none; DualSPHysics
        /// uses 0.12.
        #[serde(default)]
        smagorinsky_cs: f64,
        /// The flow's kinematic eddy viscosity, m2/s, given to Monaghan's term in place of
        /// `alpha`: alpha = 8 nu_t / (h c0), the viscosity the term acts as in 2-D (Monaghan
        /// 2005, Rep. Prog. Phys. 68:1703), so the water is as viscous at every dp. 0 (the
        /// default) for none; `hydraulics::Channel::eddy_viscosity_m2_per_s` gives a flume's.
        #[serde(default)]
        eddy_m2_per_s: f64,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeControl {
    /// Simulated time at which a `simulate` run stops, s.
    pub end_s: f64,
    /// Interval between observations and snapshots, s.
    pub output_interval_s: f64,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObservationConfig {
    /// Free-surface gauges: vertical lines at which the water level is measured.
    #[serde(default)]
    pub gauges: Vec<GaugeConfig>,
    /// Points at which pressure is interpolated (Shepard-corrected kernel sum).
    #[serde(default)]
    pub pressure_probes: Vec<ProbeConfig>,
    /// Columns along x at which the free surface and the top of each phase's layer are
    /// reported (the bed profile when one phase is a sediment bed).
    #[serde(default)]
    pub profile: Option<ProfileConfig>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileConfig {
    /// First and last column, m, and the number of columns (bins) between them.
    pub x_min_m: f64,
    pub x_max_m: f64,
    pub columns: u32,
    /// The cross-flume position of the columns in 3-D, m (ignored in 2-D).
    #[serde(default)]
    pub y_m: f64,
}

impl ProfileConfig {
    /// Horizontal positions of the columns: x evenly from x_min to x_max (and y in 3-D).
    pub fn positions(&self, dim: usize) -> Vec<Vec<f64>> {
        let n = self.columns.max(1);
        (0..n)
            .map(|k| {
                let x = if n == 1 {
                    self.x_min_m
                } else {
                    self.x_min_m + (self.x_max_m - self.x_min_m) * f64::from(k) / f64::from(n - 1)
                };
                if dim == 3 { vec![x, self.y_m] } else { vec![x] }
            })
            .collect()
    }
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaugeConfig {
    pub name: String,
    /// Horizontal position, m: x in 2-D, x and y in 3-D.
    pub position_m: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeConfig {
    pub name: String,
    /// Position, m, one coordinate per dimension.
    pub position_m: Vec<f64>,
}

impl Case {
    pub fn dim(&self) -> usize {
        self.dimension as usize
    }

    /// Smoothing length h, m.
    pub fn smoothing_length_m(&self) -> f64 {
        crate::physics::kernel::smoothing_length(
            self.numerics.coefh,
            self.dimension,
            self.numerics.dp_m,
        )
    }

    /// Magnitude of gravity, m/s2.
    pub fn gravity_magnitude(&self) -> f64 {
        self.gravity_m_per_s2
            .iter()
            .map(|g| g * g)
            .sum::<f64>()
            .sqrt()
    }

    /// Index of a phase by name; phase 0 on the GPU is the wall, so fluid phase k is k + 1.
    pub fn phase_index(&self, name: &str) -> Option<usize> {
        self.phases.iter().position(|p| p.name == name)
    }

    /// The sediment phase and the water phase it lies in, as indices into `phases`.
    pub fn sediment_phases(&self) -> Option<(usize, usize)> {
        let sediment = self.phases.iter().position(|p| p.sediment.is_some())?;
        let water = self.phases.iter().position(|p| p.sediment.is_none())?;
        Some((sediment, water))
    }

    /// Whether the sand wears net of what settles on it (`van_rijn_exner`): its region words'
    /// units are signed, and a grain carries them off the bed.
    pub fn wears_by_exner(&self) -> bool {
        self.sediment_phases().is_some_and(|(k, _)| {
            self.phases[k]
                .sediment
                .as_ref()
                .is_some_and(|s| s.erosion == Erosion::VanRijnExner)
        })
    }

    /// Whether held sediment stands as a wall (`physics::boundary`): the Shields-only mode's
    /// holds under the generalised wall condition.
    pub fn held_bed_is_wall(&self) -> bool {
        self.numerics.boundary == BoundaryMethod::Generalised
            && self.sediment_phases().is_some_and(|(k, _)| {
                self.phases[k]
                    .sediment
                    .as_ref()
                    .is_some_and(|s| s.criterion == YieldCriterion::ShieldsOnly)
            })
    }

    /// Top of the highest sediment block, m, as written in the case.
    pub fn bed_top_m(&self) -> Option<f64> {
        let d = self.dim();
        let (k, _) = self.sediment_phases()?;
        self.fluid_blocks
            .iter()
            .filter(|b| b.phase == self.phases[k].name)
            .map(|b| b.max_m[d - 1])
            .reduce(f64::max)
    }
}
