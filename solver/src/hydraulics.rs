//! The 1-D reference for an open flume's steady water levels, from textbook hydraulics alone:
//! what the twin's levels are checked against (`flume-twin bench --levels`) and what the
//! synthetic sessions of `flume-twin make-session` are made from. Nothing here is fitted to a
//! run of the SPH model. One choice came after the model was compared with it: the pit's limit
//! by its length (below) replaced the expanded pit the reference was first fixed with, when
//! the model's pool showed the current crossing it (its velocity profile, README's levels
//! section); the rule is Eaton & Johnston's, and the same rule picks the expanded pit for a
//! pit 88 cm long, where the model agreed with that limit.
//!
//! The flume, from downstream up (the ULBRA case's layout):
//! - **The weir** at the downstream end: a rectangular-profile crest of height P above the
//!   collector pit's floor and of length L in the flow direction, with a free overfall. Its rating
//!   gives the pool's level, crest + H, for the unit discharge q
//!   ([`Weir::head_m`](crate::hydraulics::Weir::head_m)): at the model's dp the end wall's particle
//!   layers make a crest as long as the head is high, a short-crested weir, rated as such
//!   ([`crest_coefficient`](crate::hydraulics::crest_coefficient)).
//! - **The collector pit** between the end of the bed and the weir. The flow leaves the bed into it
//!   over an abrupt drop. In a pit longer than the reattachment length behind such a step it
//!   spreads down and slows before the weir, losing the Borda-Carnot head `(V1 - V2)^2 / 2g` of an
//!   abrupt expansion (Chow 1959, Open-Channel Hydraulics): the level over the bed's end is the
//!   pool's plus `V2 (V2 - V1) / g`. In a shorter one (the ULBRA case's 27 cm behind a 5.5 cm step,
//!   5 step heights against 7) the current crosses at the crest's level and reaches the weir with
//!   its velocity head ([`PitFlow`](crate::hydraulics::PitFlow)); the geometry chooses which
//!   ([`REATTACHMENT_STEP_HEIGHTS`](crate::hydraulics::REATTACHMENT_STEP_HEIGHTS)).
//! - **The bed**, horizontal, with the gradually varied flow `dh/dx = (S0 - Sf) / (1 - Fr^2)`
//!   (Chow 1959) integrated upstream from the bed's end, S0 = 0. The friction slope is
//!   Manning's, `Sf = n^2 V^2 / R^(4/3)`, with Strickler's `n = ks^(1/6) / 21.1` (Strickler
//!   1923; ks in m) for the sand's roughness ks.
//!
//! Side walls: a 2-D model has none, so the reference it is checked against takes the bed's
//! friction alone (`R = h`, per metre of width):
//! [`SideWalls::None`](crate::hydraulics::SideWalls::None). The real flume's glass walls add
//! friction; [`SideWalls::Glass`](crate::hydraulics::SideWalls::Glass) gives it by the
//! Horton-Einstein composite roughness (Chow 1959) over the wetted perimeter `b + 2h`, to say how
//! much a 2-D twin must miss by without a wall-shear term of its own.

use crate::config::Case;
use crate::physics::sediment::shields::KARMAN;

/// Standard gravity, m/s2.
pub const GRAVITY_M_PER_S2: f64 = 9.81;

/// Strickler's relation: Manning's n, s/m^(1/3), for an equivalent roughness `ks_m`, m.
pub fn strickler_n(ks_m: f64) -> f64 {
    ks_m.powf(1.0 / 6.0) / 21.1
}

/// Manning's n of glass, s/m^(1/3) (Chow 1959's table of n: glass 0.009-0.013, normal 0.010).
pub const GLASS_MANNING_N: f64 = 0.010;

/// Critical depth `(q^2 / g)^(1/3)` for the unit discharge `q_m2_per_s`, m.
pub fn critical_depth_m(q_m2_per_s: f64) -> f64 {
    (q_m2_per_s * q_m2_per_s / GRAVITY_M_PER_S2).cbrt()
}

/// The downstream weir.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weir {
    /// The crest's upstream face, m along the flume.
    pub x_m: f64,
    /// The crest's level, m above the floor of the flume's frame.
    pub crest_m: f64,
    /// The crest's length in the flow direction, m.
    pub length_m: f64,
    /// The floor in front of the weir (the collector pit's floor), m.
    pub floor_m: f64,
}

impl Weir {
    /// The weir's height P above the floor in front of it, m.
    pub fn height_m(&self) -> f64 {
        self.crest_m - self.floor_m
    }

    /// The unit discharge over the crest at head `head_m`, m2/s (see [`crest_coefficient`]).
    pub fn discharge_m2_per_s(&self, head_m: f64) -> f64 {
        let cd = crest_coefficient(head_m, self.height_m(), self.length_m);
        2.0 / 3.0 * cd * (2.0 * GRAVITY_M_PER_S2).sqrt() * head_m.powf(1.5)
    }

    /// The head H over the crest that discharges `q_m2_per_s`, m.
    pub fn head_m(&self, q_m2_per_s: f64) -> f64 {
        invert(|h| self.discharge_m2_per_s(h), q_m2_per_s)
    }

    /// The head a thin plate of the same height would need (Rehbock), m.
    pub fn sharp_head_m(&self, q_m2_per_s: f64) -> f64 {
        let p = self.height_m();
        invert(
            |h| {
                2.0 / 3.0
                    * rehbock_coefficient(h, p)
                    * (2.0 * GRAVITY_M_PER_S2).sqrt()
                    * h.powf(1.5)
            },
            q_m2_per_s,
        )
    }
}

/// The head whose discharge `rating` is `q`, by bisection over 0-1 m (q grows with the head).
fn invert(rating: impl Fn(f64) -> f64, q: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if rating(mid) < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The discharge coefficient Cd of `q = 2/3 Cd sqrt(2 g) H^1.5` for a head H over a crest of
/// height P and length L in the flow direction, vertical faces and a free overfall: Peter's
/// (2005, Ueberfaelle und Wehre) sharp-crested `0.6035 + 0.0813 H / P`, reduced for a crest of
/// finite length by `1 - 0.2 exp(-0.6 (H / L)^3.06)`, stated for 0.5 <= H / L <= 1.8 (short
/// crests; above, the factor is within 0.6 % of 1 and the weir is sharp-crested). At the
/// ULBRA weir's heads (H / L = 0.8-1.9 for L = 1-3 cm) it agrees within 0.4 mm of head with
/// Bos (1989, Discharge Measurement Structures) for rectangular-profile weirs and Hulsing (1967,
/// USGS TWRI 3-A5) for broad-crested weirs with a vertical face; a 3 cm crest under 2 m3/h
/// raises the head by about 2.5 mm over a sharp crest's.
pub fn crest_coefficient(head_m: f64, height_m: f64, length_m: f64) -> f64 {
    let sharp = 0.6035 + 0.0813 * head_m / height_m;
    sharp * (1.0 - 0.2 * (-0.6 * (head_m / length_m).powf(3.06)).exp())
}

/// Rehbock's sharp-crested Cd, `0.611 + 0.08 H / P` (Rehbock 1929): the thin plate's rating,
/// for comparison.
pub fn rehbock_coefficient(head_m: f64, height_m: f64) -> f64 {
    0.611 + 0.08 * head_m / height_m
}

/// The side walls' share of the friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SideWalls {
    /// The bed's friction alone, per metre of width (a 2-D model's flume).
    None,
    /// Walls `width_m` apart of Manning's n `manning_n`, composed with the bed's by
    /// Horton-Einstein.
    Glass { width_m: f64, manning_n: f64 },
}

/// The reattachment length of a turbulent flow over a backward-facing step, in step heights:
/// 7 +/- 1 (Eaton & Johnston 1981, AIAA J. 19:1093, their review of the experiments). A pit
/// shorter than this from the step to the weir is crossed by the current before it has spread
/// down ([`PitFlow::Carried`]); a longer one stills it ([`PitFlow::Expanded`]).
pub const REATTACHMENT_STEP_HEIGHTS: f64 = 7.0;

/// How the flow off the bed's end meets the pool before the weir: the two limits between which
/// a collector pit's flow lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PitFlow {
    /// The jet spreads over the pit's whole depth and slows before the weir: the momentum
    /// balance of an abrupt expansion, with its Borda-Carnot loss (Chow 1959). It needs a pit
    /// longer than the reattachment length of the flow over its step, 5-8 step heights for a
    /// turbulent flow (Eaton & Johnston 1981).
    Expanded,
    /// The current crosses the pit at the crest's level without losing head: the level over
    /// the bed's end carries the pool's energy (its level plus the pool's velocity head), and
    /// no less than critical depth (a free overfall's control) when that energy is below
    /// the bed's least specific energy, 1.5 h_c.
    Carried,
}

/// The flume as the 1-D reference sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The inlet wall, m along the flume.
    pub x_inlet_m: f64,
    /// Where the bed and its sill end over the collector pit, m.
    pub x_bed_end_m: f64,
    /// The bed's surface, m above the floor of the flume's frame.
    pub bed_m: f64,
    /// The bed's Manning n, s/m^(1/3).
    pub manning_n: f64,
    pub side_walls: SideWalls,
    pub pit: PitFlow,
    pub weir: Weir,
}

/// Step of the surface-profile integration, m.
pub const DX_M: f64 = 0.001;

/// A steady water surface: the depth over the bed every [`DX_M`] from the inlet wall to the
/// bed's end, and the pool's level before the weir.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    pub x_inlet_m: f64,
    pub bed_m: f64,
    /// Depth over the bed, m, at `x_inlet_m + k DX_M`.
    pub depths_m: Vec<f64>,
    /// The pool's level between the bed's end and the weir, m.
    pub pool_level_m: f64,
    pub x_bed_end_m: f64,
}

impl Profile {
    /// The water level at `x`, m above the frame's floor: linear between the profile's points,
    /// the pool's level past the bed's end.
    pub fn level_m(&self, x_m: f64) -> f64 {
        if x_m > self.x_bed_end_m {
            return self.pool_level_m;
        }
        let s = ((x_m - self.x_inlet_m) / DX_M).max(0.0);
        let k = (s.floor() as usize).min(self.depths_m.len() - 1);
        let next = (k + 1).min(self.depths_m.len() - 1);
        let f = (s - k as f64).clamp(0.0, 1.0);
        self.bed_m + self.depths_m[k] * (1.0 - f) + self.depths_m[next] * f
    }

    /// Water stored over the bed and in the pool, m3 per metre of width (the pool's from its
    /// floor up: a dry flume's pit fills first).
    pub fn volume_m2(&self, weir: &Weir) -> f64 {
        let bed: f64 = self.depths_m.iter().sum::<f64>() * DX_M;
        bed + (self.pool_level_m - weir.floor_m) * (weir.x_m - self.x_bed_end_m).max(0.0)
    }
}

impl Channel {
    /// The flume of a case's file: its blocks' faces and the weir's crest as written.
    pub fn from_case(case: &Case) -> Result<Channel, String> {
        Channel::build(case, None)
    }

    /// The flume as the generator builds it at the case's dp: each particle stands for the dp
    /// around it, so a surface lies half a dp past its outermost particles (a bed whose top
    /// particles sit at 0.050 m has its surface at 0.055 m), and a block's faces move to the
    /// lattice (the sand's top is 0.0525 m at dp = 7 mm for a nominal 0.055 m). The end wall's
    /// `layers` columns make a crest `layers` dp long.
    pub fn as_generated(case: &Case) -> Result<Channel, String> {
        Channel::build(case, Some(case.numerics.dp_m))
    }

    fn build(case: &Case, lattice: Option<f64>) -> Result<Channel, String> {
        let Some(flume) = &case.open_flume else {
            return Err(format!(
                "{}: the 1-D reference needs an open flume",
                case.name
            ));
        };
        if case.dim() != 2 {
            return Err(format!(
                "{}: the 1-D reference is for 2-D flumes",
                case.name
            ));
        }
        let dp = case.numerics.dp_m;
        // The generator fills lattice points `min < x <= max`: a block's last point is
        // floor(max / dp), and the surface lies dp/2 beyond it; a wall face's points are the
        // domain's bound rounded to the lattice, the surface dp/2 inside it.
        let top = |v: f64| lattice.map_or(v, |dp| (v / dp + 1e-6).floor() * dp + 0.5 * dp);
        let face_in =
            |v: f64, dir: f64| lattice.map_or(v, |dp| ((v / dp).round() + 0.5 * dir) * dp);
        let (lo, hi) = (&case.domain.min_m, &case.domain.max_m);
        let sediment: Vec<&str> = case
            .phases
            .iter()
            .filter(|p| p.sediment.is_some())
            .map(|p| p.name.as_str())
            .collect();
        let bed_ends: Vec<f64> = case
            .fluid_blocks
            .iter()
            .filter(|b| sediment.contains(&b.phase.as_str()))
            .map(|b| b.max_m[0])
            .collect();
        let Some(bed_nominal) = case.bed_top_m() else {
            return Err(format!(
                "{}: the 1-D reference needs a sediment bed",
                case.name
            ));
        };
        // The bed ends where the sill in front of the pit does, or the last block at its level.
        let x_bed_end = bed_ends
            .iter()
            .copied()
            .chain(flume.sill.iter().map(|s| s.x_max_m))
            .chain(
                case.walls
                    .blocks
                    .iter()
                    .filter(|w| w.max_m[1] >= bed_nominal - 1e-9 && w.max_m[0] < hi[0])
                    .map(|w| w.max_m[0]),
            )
            .fold(lo[0], f64::max);
        let ks_m = case
            .phases
            .iter()
            .find_map(|p| p.sediment.as_ref())
            .map_or(1e-3, |s| s.ks_over_d50 * s.d50_m);
        let weir = Weir {
            x_m: face_in(hi[0], -1.0),
            crest_m: top(flume.outlet_weir_m),
            length_m: f64::from(case.walls.layers) * dp,
            floor_m: face_in(lo[1], 1.0),
        };
        let (x_bed_end_m, bed_m) = (top(x_bed_end), top(bed_nominal));
        let step_m = bed_m - weir.floor_m;
        let pit = if weir.x_m - x_bed_end_m >= REATTACHMENT_STEP_HEIGHTS * step_m {
            PitFlow::Expanded
        } else {
            PitFlow::Carried
        };
        Ok(Channel {
            x_inlet_m: face_in(lo[0], 1.0),
            x_bed_end_m,
            bed_m,
            manning_n: strickler_n(ks_m),
            side_walls: SideWalls::None,
            pit,
            weir,
        })
    }

    /// The depth-averaged eddy viscosity of the steady flow of `q_m3_per_s` through a flume
    /// `width_m` wide, m2/s: `kappa u* h / 6`, the mean over the depth of the parabolic profile
    /// `kappa u* z (1 - z / h)` of a uniform open-channel flow (Rodi 1993, Turbulence Models
    /// and Their Application in Hydraulics; Nezu & Nakagawa 1993), with h the mean depth of the
    /// steady surface over the bed and `u* = sqrt(g h Sf)` its friction velocity there.
    pub fn eddy_viscosity_m2_per_s(&self, q_m3_per_s: f64, width_m: f64) -> f64 {
        let profile = self.steady(q_m3_per_s, width_m);
        let h = profile.depths_m.iter().sum::<f64>() / profile.depths_m.len() as f64;
        let u_star = (GRAVITY_M_PER_S2 * h * self.friction_slope(q_m3_per_s / width_m, h)).sqrt();
        f64::from(KARMAN) * u_star * h / 6.0
    }

    /// The steady surface for the discharge `q_m3_per_s` through a flume `width_m` wide.
    pub fn steady(&self, q_m3_per_s: f64, width_m: f64) -> Profile {
        let q = q_m3_per_s / width_m;
        let pool = self.weir.crest_m + self.weir.head_m(q);
        let h_end = self.bed_end_depth_m(q, pool);
        let n = ((self.x_bed_end_m - self.x_inlet_m) / DX_M).ceil() as usize;
        let mut depths = vec![0.0; n + 1];
        depths[n] = h_end;
        let slope = |h: f64| self.backwater_slope(q, h);
        for k in (0..n).rev() {
            // Fourth-order Runge-Kutta, upstream (x decreasing, depth increasing).
            let h = depths[k + 1];
            let k1 = slope(h);
            let k2 = slope(h + 0.5 * DX_M * k1);
            let k3 = slope(h + 0.5 * DX_M * k2);
            let k4 = slope(h + DX_M * k3);
            depths[k] = h + DX_M / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        Profile {
            x_inlet_m: self.x_inlet_m,
            bed_m: self.bed_m,
            depths_m: depths,
            pool_level_m: pool,
            x_bed_end_m: self.x_bed_end_m,
        }
    }

    /// The depth over the bed's end under the pool's level `pool` for the unit discharge `q`
    /// ([`PitFlow`]), m. A pool below critical depth over the bed's end would mean a
    /// supercritical reach: the bed's end is then a control at critical depth.
    fn bed_end_depth_m(&self, q: f64, pool: f64) -> f64 {
        let g = GRAVITY_M_PER_S2;
        let v2 = q / (pool - self.weir.floor_m);
        let hc = critical_depth_m(q);
        let h1 = match self.pit {
            PitFlow::Expanded => {
                // The pool's level less the Borda-Carnot adjustment V2 (V2 - V1) / g, solved
                // for the depth h1 whose V1 = q / h1 enters it (a few fixed-point rounds
                // converge: the adjustment is a small fraction of the depth).
                let mut h1 = pool - self.bed_m;
                for _ in 0..50 {
                    let v1 = q / h1;
                    h1 = pool + v2 * (v2 - v1) / g - self.bed_m;
                }
                h1
            }
            PitFlow::Carried => {
                // The subcritical depth of specific energy E, by bisection over (h_c, E]:
                // h + q^2 / 2 g h^2 grows with h there.
                let energy = pool + v2 * v2 / (2.0 * g) - self.bed_m;
                let (mut lo, mut hi) = (hc, energy.max(hc));
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if mid + q * q / (2.0 * g * mid * mid) < energy {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            }
        };
        h1.max(hc * 1.001)
    }

    /// `-dh/dx = Sf / (1 - Fr^2)` at depth `h`: how fast the depth grows upstream.
    fn backwater_slope(&self, q: f64, h: f64) -> f64 {
        let v = q / h;
        let fr2 = (v * v / (GRAVITY_M_PER_S2 * h)).min(0.99);
        self.friction_slope(q, h) / (1.0 - fr2)
    }

    /// Manning's friction slope `Sf` at depth `h` for the unit discharge `q`.
    fn friction_slope(&self, q: f64, h: f64) -> f64 {
        let v = q / h;
        match self.side_walls {
            SideWalls::None => self.manning_n.powi(2) * v * v / h.powf(4.0 / 3.0),
            SideWalls::Glass {
                width_m: b,
                manning_n,
            } => {
                let perimeter = b + 2.0 * h;
                let n = ((b * self.manning_n.powf(1.5) + 2.0 * h * manning_n.powf(1.5))
                    / perimeter)
                    .powf(2.0 / 3.0);
                let r = b * h / perimeter;
                n * n * v * v / r.powf(4.0 / 3.0)
            }
        }
    }
}

/// The overrides (`Case::from_path_with`) that make `case`'s flume a clear-water one: its
/// sediment blocks become wall blocks of the same shape, a sill becomes a wall block level with
/// them (no sliding sheet to pass over it), and the collector pit starts full of water (a case
/// needs some fluid, and the pit fills before any water leaves over the weir).
pub fn fixed_bed_overrides(case: &Case) -> Result<Vec<String>, String> {
    let channel = Channel::from_case(case)?;
    let pit = pit_water(case, &channel)?;
    let is_bed = |phase: &str| {
        case.phases
            .iter()
            .any(|p| p.name == phase && p.sediment.is_some())
    };
    let block = |min: &[f64], max: &[f64]| format!("{{min_m: {min:?}, max_m: {max:?}}}");
    let sill = case
        .open_flume
        .as_ref()
        .and_then(|f| f.sill.as_ref())
        .zip(case.bed_top_m())
        .map(|(s, top)| ([s.x_min_m, case.domain.min_m[1]], [s.x_max_m, top]));
    let walls: Vec<String> = case
        .walls
        .blocks
        .iter()
        .map(|w| block(&w.min_m, &w.max_m))
        .chain(sill.iter().map(|(min, max)| block(min, max)))
        .chain(
            case.fluid_blocks
                .iter()
                .filter(|b| is_bed(&b.phase))
                .map(|b| block(&b.min_m, &b.max_m)),
        )
        .collect();
    let fluids: Vec<String> = case
        .fluid_blocks
        .iter()
        .filter(|b| !is_bed(&b.phase))
        .map(|b| fluid_block(&b.phase, &b.min_m, &b.max_m))
        .chain([pit])
        .collect();
    let mut overrides = vec![
        format!("walls.blocks=[{}]", walls.join(", ")),
        format!("fluid_blocks=[{}]", fluids.join(", ")),
    ];
    if sill.is_some() {
        overrides.push("open_flume.sill=null".into());
    }
    Ok(overrides)
}

/// The override (`Case::from_path_with`) that starts `case`'s collector pit full of still
/// water to the crest, its sand bed as it is: the level benchmark's start. The pit's current
/// is not unique: filled by the first water falling into it, the pit's flow at dp = 5 mm and
/// finer plunges to its floor and stayed so in every run to its end (50 s, 40 s at 4 mm);
/// started full, it crosses the pit at the crest's level (README, "The pit's current at each
/// dp"). A flume that has run before holds a full pit.
pub fn filled_pit_override(case: &Case) -> Result<String, String> {
    let pit = pit_water(case, &Channel::from_case(case)?)?;
    let fluids: Vec<String> = case
        .fluid_blocks
        .iter()
        .map(|b| fluid_block(&b.phase, &b.min_m, &b.max_m))
        .chain([pit])
        .collect();
    Ok(format!("fluid_blocks=[{}]", fluids.join(", ")))
}

/// A fluid block of `case`'s water filling the collector pit from the bed's end to the weir's
/// face, from the floor to the crest.
fn pit_water(case: &Case, channel: &Channel) -> Result<String, String> {
    let water = (case.phases.iter())
        .find(|p| p.sediment.is_none())
        .ok_or_else(|| {
            format!(
                "{}: the collector pit's water needs a water phase",
                case.name
            )
        })?;
    let min = [channel.x_bed_end_m, channel.weir.floor_m];
    let max = [channel.weir.x_m, channel.weir.crest_m];
    Ok(fluid_block(&water.name, &min, &max))
}

/// A `fluid_blocks` entry, as an override writes it.
fn fluid_block(phase: &str, min: &[f64], max: &[f64]) -> String {
    format!("{{phase: {phase}, min_m: {min:?}, max_m: {max:?}}}")
}

#[cfg(test)]
mod tests;
