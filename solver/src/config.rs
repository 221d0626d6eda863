//! Case files: one YAML document per case (see `launch_configs/`).
//!
//! Every length is in metres, every time in seconds, and the unit is part of the field name
//! (`dp_m`, `end_s`). Unknown fields are rejected so that a misspelt key cannot silently fall
//! back to a default. Parse errors and validation errors both name the offending field.

use serde::Deserialize;
use std::path::Path;

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
    /// Cap on the apparent viscosity, Pa s. Without it, mu_max = 0.125 h rho_s c0: the
    /// viscosity whose explicit diffusion limit `0.125 h^2 rho / mu` equals the acoustic step
    /// `h / c0`, so the sediment never shortens the time step below what the water needs.
    #[serde(default)]
    pub max_viscosity_pa_s: Option<f64>,
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
    pub fn from_path(path: &Path) -> Result<Case, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Case::from_yaml(&text, &path.display().to_string())
    }

    /// Reads `path` with `overrides` applied first, each `key.path=value` (a YAML value; a
    /// number in the path indexes a list, `phases.1.sediment.ks_over_d50=7`): the same case at
    /// another resolution or roughness without a second file. Every override is validated as
    /// the file is.
    pub fn from_path_with(path: &Path, overrides: &[String]) -> Result<Case, ConfigError> {
        if overrides.is_empty() {
            return Case::from_path(path);
        }
        let origin = format!("{} (with {})", path.display(), overrides.join(", "));
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let invalid = |field: &str, reason: String| ConfigError::Invalid {
            path: origin.clone(),
            field: field.to_string(),
            reason,
        };
        let mut doc: serde_norway::Value =
            serde_norway::from_str(&text).map_err(|e| invalid("(top level)", e.to_string()))?;
        for o in overrides {
            let (key, value) = o
                .split_once('=')
                .ok_or_else(|| invalid(o, "an override is key=value".into()))?;
            let value: serde_norway::Value =
                serde_norway::from_str(value).map_err(|e| invalid(key, e.to_string()))?;
            let mut node = &mut doc;
            let parts: Vec<&str> = key.split('.').collect();
            for (i, part) in parts.iter().enumerate() {
                let last = i + 1 == parts.len();
                node = match node {
                    serde_norway::Value::Sequence(items) => {
                        let k: usize = part
                            .parse()
                            .map_err(|_| invalid(key, format!("{part} is not a list index")))?;
                        let len = items.len();
                        items.get_mut(k).ok_or_else(|| {
                            invalid(key, format!("index {k} past the list's {len} items"))
                        })?
                    }
                    serde_norway::Value::Mapping(map) if last => {
                        map.insert(serde_norway::Value::String(part.to_string()), value.clone());
                        break;
                    }
                    serde_norway::Value::Mapping(map) => map
                        .get_mut(*part)
                        .ok_or_else(|| invalid(key, format!("the file has no section {part}")))?,
                    _ => return Err(invalid(key, format!("{part} is not a section or a list"))),
                };
                if last {
                    *node = value.clone();
                }
            }
        }
        let text =
            serde_norway::to_string(&doc).map_err(|e| invalid("(top level)", e.to_string()))?;
        Case::from_yaml(&text, &origin)
    }

    /// Parses and validates a case; `origin` names the source in error messages.
    pub fn from_yaml(text: &str, origin: &str) -> Result<Case, ConfigError> {
        let de = serde_norway::Deserializer::from_str(text);
        let case: Case = serde_path_to_error::deserialize(de).map_err(|e| {
            let field = e.path().to_string();
            ConfigError::Parse {
                path: origin.to_string(),
                field: if field == "." {
                    "(top level)".to_string()
                } else {
                    field
                },
                reason: {
                    // serde prefixes the path, which the message already names.
                    let reason = e.inner().to_string();
                    let prefix = format!("{}: ", e.path());
                    reason.strip_prefix(&prefix).unwrap_or(&reason).to_string()
                },
            }
        })?;
        case.validate()
            .map_err(|(field, reason)| ConfigError::Invalid {
                path: origin.to_string(),
                field,
                reason,
            })?;
        Ok(case)
    }

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

    fn validate_sediment(&self, i: usize, s: &SedimentConfig) -> Result<(), (String, String)> {
        let field = |name: &str| format!("phases[{i}].sediment.{name}");
        let err = |name: &str, reason: &str| Err((field(name), reason.to_string()));
        if self.phases.iter().filter(|p| p.sediment.is_some()).count() > 1 {
            return Err((
                format!("phases[{i}].sediment"),
                "only one sediment phase is supported".into(),
            ));
        }
        let water: Vec<&PhaseConfig> = self
            .phases
            .iter()
            .filter(|p| p.sediment.is_none())
            .collect();
        if water.len() != 1 {
            return Err((
                "phases".into(),
                "a sediment needs exactly one water phase (a phase without `sediment`)".into(),
            ));
        }
        if self.phases[i].rho0_kg_per_m3 <= water[0].rho0_kg_per_m3 {
            return Err((
                format!("phases[{i}].rho0_kg_per_m3"),
                "a sediment must be denser than the water".into(),
            ));
        }
        if !matches!(self.numerics.viscosity, Viscosity::Multiphase { .. }) {
            return Err((
                "numerics.viscosity.method".into(),
                "a sediment phase needs `multiphase`".into(),
            ));
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(s.d50_m) {
            return err("d50_m", "must be positive");
        }
        if !(s.friction_angle_deg.is_finite()
            && s.friction_angle_deg > 0.0
            && s.friction_angle_deg < 90.0)
        {
            return err("friction_angle_deg", "must be between 0 and 90 degrees");
        }
        if !(s.cohesion_pa.is_finite() && s.cohesion_pa >= 0.0) {
            return err("cohesion_pa", "must be >= 0");
        }
        if !(s.hbp_m_s.is_finite() && s.hbp_m_s >= 0.0) {
            return err("hbp_m_s", "must be >= 0");
        }
        if !positive(s.hbp_n) {
            return err("hbp_n", "must be positive");
        }
        if !positive(s.ks_over_d50) {
            return err("ks_over_d50", "must be positive");
        }
        if !(positive(s.surface_mass_fraction) && s.surface_mass_fraction <= 1.0) {
            return err("surface_mass_fraction", "must be in (0, 1]");
        }
        if let Some(mu) = s.max_viscosity_pa_s
            && !positive(mu)
        {
            return err("max_viscosity_pa_s", "must be positive");
        }
        Ok(())
    }

    fn validate_open_flume(&self, f: &OpenFlume) -> Result<(), (String, String)> {
        let err = |name: &str, reason: String| Err((format!("open_flume.{name}"), reason));
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if self.dimension != 2 {
            return err("", "an open flume is 2-D only for now".into());
        }
        if self.phases.len() > 2 {
            return err(
                "",
                "an open flume takes at most two phases (water and a sediment)".into(),
            );
        }
        if !positive(f.width_m) {
            return err("width_m", "must be positive".into());
        }
        if !(f.inflow_m3_per_s.is_finite() && f.inflow_m3_per_s >= 0.0) {
            return err("inflow_m3_per_s", "must be >= 0".into());
        }
        let (lo, hi) = (&self.domain.min_m, &self.domain.max_m);
        let dp = self.numerics.dp_m;
        if !(positive(f.inlet.height_m) && f.inlet.height_m >= dp) {
            return err("inlet.height_m", "must be at least dp".into());
        }
        if !(f.inlet.y_min_m >= lo[1] && f.inlet.y_min_m + f.inlet.height_m <= hi[1]) {
            return err(
                "inlet.y_min_m",
                "the inlet must lie within the domain's height".into(),
            );
        }
        if !(2..=16).contains(&f.inlet.layers) {
            return err(
                "inlet.layers",
                format!("must be 2..=16, got {}", f.inlet.layers),
            );
        }
        if !(f.outlet_weir_m > lo[1] && f.outlet_weir_m <= hi[1]) {
            return err(
                "outlet_weir_m",
                "must lie within the domain's height".into(),
            );
        }
        let c = &f.collector;
        if !(c.x_min_m < c.x_max_m && c.x_min_m >= lo[0] && c.x_max_m <= hi[0] && c.y_max_m > lo[1])
        {
            return err(
                "collector",
                "must be a box inside the flume (x_min < x_max, above the floor)".into(),
            );
        }
        if let Some(o) = &f.bottom_outlet {
            if !(o.x_min_m > lo[0] && o.x_min_m < hi[0]) {
                return err("bottom_outlet.x_min_m", "must lie inside the flume".into());
            }
            if !(o.y_min_m >= lo[1] && o.y_max_m - o.y_min_m >= dp && o.y_max_m <= hi[1]) {
                return err(
                    "bottom_outlet.y_max_m",
                    "the opening must be at least dp high, within the domain's height".into(),
                );
            }
            if !positive(o.velocity_m_s) {
                return err("bottom_outlet.velocity_m_s", "must be positive".into());
            }
            // The rest of the case is valid by now, so its sound speed can be derived.
            let limit = crate::flume::MAX_INLET_MACH * crate::case::derive(self).c0;
            if o.velocity_m_s > limit {
                return err(
                    "bottom_outlet.velocity_m_s",
                    format!(
                        "must be at most {} c0 = {limit:.3} m/s, as the inlet's",
                        crate::flume::MAX_INLET_MACH
                    ),
                );
            }
        }
        // Sediment that starts in the collector would count as eroded at the first step.
        if let Some((k, _)) = self.sediment_phases() {
            let name = &self.phases[k].name;
            for b in self.fluid_blocks.iter().filter(|b| &b.phase == name) {
                if b.max_m[0] >= c.x_min_m && b.min_m[0] < c.x_max_m && b.min_m[1] < c.y_max_m {
                    return err(
                        "collector.x_min_m",
                        format!(
                            "the {name} block ending at x = {} m reaches into the collector",
                            b.max_m[0]
                        ),
                    );
                }
            }
        }
        Ok(())
    }

    fn validate(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        if self.dimension != 2 && self.dimension != 3 {
            return err(
                "dimension",
                format!("must be 2 or 3, got {}", self.dimension),
            );
        }
        let d = self.dim();
        for (field, v) in [
            ("domain.min_m", &self.domain.min_m),
            ("domain.max_m", &self.domain.max_m),
            ("gravity_m_per_s2", &self.gravity_m_per_s2),
        ] {
            check_vector(field, v, d)?;
        }
        for k in 0..d {
            if self.domain.max_m[k] <= self.domain.min_m[k] {
                return err(
                    "domain.max_m",
                    format!("component {k} must exceed domain.min_m's"),
                );
            }
        }
        if self.gravity_m_per_s2[..d - 1].iter().any(|g| *g != 0.0)
            || self.gravity_m_per_s2[d - 1] >= 0.0
        {
            return err(
                "gravity_m_per_s2",
                "must point down the last (vertical) axis, e.g. [0, -9.81]".to_string(),
            );
        }
        if self.walls.layers == 0 || self.walls.layers > 8 {
            return err(
                "walls.layers",
                format!("must be 1..=8, got {}", self.walls.layers),
            );
        }
        for (i, b) in self.walls.blocks.iter().enumerate() {
            check_vector(&format!("walls.blocks[{i}].min_m"), &b.min_m, d)?;
            check_vector(&format!("walls.blocks[{i}].max_m"), &b.max_m, d)?;
        }
        if self.phases.is_empty() {
            return err("phases", "at least one phase is needed".to_string());
        }
        if self.phases.len() > 3 {
            return err("phases", "at most 3 phases are supported".to_string());
        }
        for (i, p) in self.phases.iter().enumerate() {
            if !(p.rho0_kg_per_m3.is_finite() && p.rho0_kg_per_m3 > 0.0) {
                return err(
                    &format!("phases[{i}].rho0_kg_per_m3"),
                    "must be a positive number".into(),
                );
            }
            if !(p.viscosity_pa_s.is_finite() && p.viscosity_pa_s >= 0.0) {
                return err(
                    &format!("phases[{i}].viscosity_pa_s"),
                    "must be >= 0".into(),
                );
            }
            if self.phases[..i].iter().any(|q| q.name == p.name) {
                return err(
                    &format!("phases[{i}].name"),
                    format!("`{}` is defined twice", p.name),
                );
            }
            if let Some(sed) = &p.sediment {
                self.validate_sediment(i, sed)?;
            }
        }
        if self.fluid_blocks.is_empty() {
            return err(
                "fluid_blocks",
                "at least one block of fluid is needed".to_string(),
            );
        }
        for (i, b) in self.fluid_blocks.iter().enumerate() {
            if self.phase_index(&b.phase).is_none() {
                return err(
                    &format!("fluid_blocks[{i}].phase"),
                    format!("no phase named `{}` in `phases`", b.phase),
                );
            }
            check_vector(&format!("fluid_blocks[{i}].min_m"), &b.min_m, d)?;
            check_vector(&format!("fluid_blocks[{i}].max_m"), &b.max_m, d)?;
            for k in 0..d {
                if b.max_m[k] <= b.min_m[k] {
                    return err(
                        &format!("fluid_blocks[{i}].max_m"),
                        format!("component {k} must exceed min_m's"),
                    );
                }
                if b.min_m[k] < self.domain.min_m[k] - 1e-9
                    || b.max_m[k] > self.domain.max_m[k] + 1e-9
                {
                    return err(
                        &format!("fluid_blocks[{i}]"),
                        "must lie inside the domain".to_string(),
                    );
                }
            }
        }
        let n = &self.numerics;
        let extent = (0..d)
            .map(|k| self.domain.max_m[k] - self.domain.min_m[k])
            .fold(f64::MAX, f64::min);
        if !(n.dp_m.is_finite() && n.dp_m > 0.0 && n.dp_m < extent / 4.0) {
            return err(
                "numerics.dp_m",
                format!(
                    "must be positive and below a quarter of the smallest tank size ({extent} m), got {}",
                    n.dp_m
                ),
            );
        }
        if !(n.coefh.is_finite() && (0.5..=3.0).contains(&n.coefh)) {
            return err(
                "numerics.coefh",
                format!("must be in 0.5..=3, got {}", n.coefh),
            );
        }
        if !(n.cfl.is_finite() && n.cfl > 0.0 && n.cfl <= 1.0) {
            return err("numerics.cfl", format!("must be in (0, 1], got {}", n.cfl));
        }
        match (n.sound_speed.c0_m_per_s, n.sound_speed.coefsound) {
            (Some(c), None) if !(c.is_finite() && c > 0.0) => {
                return err(
                    "numerics.sound_speed.c0_m_per_s",
                    format!("must be positive, got {c}"),
                );
            }
            (None, Some(c)) if !(c.is_finite() && c > 0.0) => {
                return err(
                    "numerics.sound_speed.coefsound",
                    format!("must be positive, got {c}"),
                );
            }
            (Some(_), Some(_)) | (None, None) => {
                return err(
                    "numerics.sound_speed",
                    "give exactly one of c0_m_per_s and coefsound".into(),
                );
            }
            _ => {}
        }
        match n.density_diffusion {
            DensityDiffusion::MolteniColagrossi2009 { delta }
            | DensityDiffusion::Fourtakas2019 { delta }
                if !(delta.is_finite() && (0.0..=1.0).contains(&delta)) =>
            {
                return err(
                    "numerics.density_diffusion.delta",
                    format!("must be in 0..=1, got {delta}"),
                );
            }
            _ => {}
        }
        if let Viscosity::Artificial { alpha } | Viscosity::Multiphase { alpha } = n.viscosity
            && !(alpha.is_finite() && (0.0..=10.0).contains(&alpha))
        {
            return err(
                "numerics.viscosity.alpha",
                format!("must be in 0..=10, got {alpha}"),
            );
        }
        if let Integrator::Verlet { euler_every_steps } = n.integrator
            && !(1..=1000).contains(&euler_every_steps)
        {
            return err(
                "numerics.integrator.euler_every_steps",
                format!("must be in 1..=1000, got {euler_every_steps}"),
            );
        }
        let t = &self.time;
        if !(t.end_s.is_finite() && t.end_s > 0.0) {
            return err("time.end_s", "must be positive".into());
        }
        if !(t.output_interval_s.is_finite() && t.output_interval_s > 0.0) {
            return err("time.output_interval_s", "must be positive".into());
        }
        for (i, g) in self.observations.gauges.iter().enumerate() {
            check_vector(
                &format!("observations.gauges[{i}].position_m"),
                &g.position_m,
                d - 1,
            )?;
            for k in 0..d - 1 {
                if !(self.domain.min_m[k]..=self.domain.max_m[k]).contains(&g.position_m[k]) {
                    return err(
                        &format!("observations.gauges[{i}].position_m"),
                        "must lie inside the domain".into(),
                    );
                }
            }
        }
        if let Some(p) = &self.observations.profile {
            let inside = |x: f64| (self.domain.min_m[0]..=self.domain.max_m[0]).contains(&x);
            if !(p.x_min_m.is_finite()
                && p.x_max_m.is_finite()
                && inside(p.x_min_m)
                && inside(p.x_max_m))
                || p.x_max_m < p.x_min_m
            {
                return err(
                    "observations.profile",
                    "x_min_m <= x_max_m, both inside the domain".into(),
                );
            }
            if !(1..=10_000).contains(&p.columns) {
                return err(
                    "observations.profile.columns",
                    format!("must be 1..=10000, got {}", p.columns),
                );
            }
            if d == 3 && !(self.domain.min_m[1]..=self.domain.max_m[1]).contains(&p.y_m) {
                return err(
                    "observations.profile.y_m",
                    "must lie inside the domain".into(),
                );
            }
        }
        for (i, p) in self.observations.pressure_probes.iter().enumerate() {
            check_vector(
                &format!("observations.pressure_probes[{i}].position_m"),
                &p.position_m,
                d,
            )?;
        }
        if let Some(f) = &self.open_flume {
            self.validate_open_flume(f)?;
        }
        Ok(())
    }
}

fn check_vector(field: &str, v: &[f64], len: usize) -> Result<(), (String, String)> {
    if v.len() != len {
        return Err((
            field.to_string(),
            format!("needs {len} components, got {}", v.len()),
        ));
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err((
            field.to_string(),
            "components must be finite numbers".to_string(),
        ));
    }
    Ok(())
}
