//! The host's half of the open flume: the discharge, the inlet buffer's new columns, and the
//! count of parked particles and of eroded sediment. The GPU half (the inlet's imposed
//! velocity, parking at the outlet and the collector) is in `shaders/common/store_rule.wgsl`.
//!
//! The particle count never changes. A particle that leaves (over the weir, or as sediment
//! into the collector) is parked: it becomes water at its own spot above the flume, where it
//! takes no part in the flow. Each time the inlet buffer has moved one dp, the host fills a new
//! column behind it with parked particles, lowest id first, so that runs stay deterministic.

use crate::config::{Case, OpenFlume};
use crate::particles::{Particles, parked_phase};

/// The discharge driving the inlet, m3/s; set at any time with
/// `Simulation::set_boundary_conditions`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryConditions {
    pub inflow_m3_per_s: f64,
}

/// The open flume's state on the host.
#[derive(Debug, Clone)]
pub struct FlumeState {
    pub config: OpenFlume,
    pub inflow_m3_per_s: f64,
    /// Distance the inlet buffer has moved since its newest column entered, m.
    pub inlet_shift_m: f64,
    /// Sediment particles collected (or gone over the weir) since the start.
    pub eroded_particles: u64,
    /// Particles parked now.
    pub parked_particles: u64,
    /// Inlet particles that could not be placed for want of parked ones, since the start.
    pub starved_particles: u64,
    /// Inlet spots left empty because a particle was there, since the start.
    pub blocked_particles: u64,
    /// Particles the inlet has placed since the start.
    pub injected_particles: u64,
    /// Particles excluded for a density out of range (and parked) since the start
    /// (`crate::health`), and how many of them were sediment (recycled as water).
    pub excluded_particles: u64,
    pub excluded_sediment: u64,
    /// Water particles the bed's pores took (and parked) since the start
    /// (`simulation::PoreColumns`).
    pub soaked_particles: u64,
}

/// Share of the inflow's particles left unplaced, 0-1: `blocked` spots against `placed` ones.
pub fn blocked_share(blocked: u64, placed: u64) -> f64 {
    let due = blocked + placed;
    if due == 0 {
        0.0
    } else {
        blocked as f64 / due as f64
    }
}

/// What the inlet needs this time: new columns, each at its x, m.
pub struct Injection {
    pub columns_x_m: Vec<f64>,
}

impl FlumeState {
    pub fn new(case: &Case, particles: &Particles) -> Option<FlumeState> {
        let config = case.open_flume.clone()?;
        let parked = parked_phase(case);
        let parked_particles = (0..particles.len())
            .filter(|&i| particles.phase(i) == parked)
            .count() as u64;
        Some(FlumeState {
            inflow_m3_per_s: config.inflow_m3_per_s,
            config,
            inlet_shift_m: 0.0,
            eroded_particles: 0,
            parked_particles,
            starved_particles: 0,
            blocked_particles: 0,
            injected_particles: 0,
            excluded_particles: 0,
            excluded_sediment: 0,
            soaked_particles: 0,
        })
    }

    /// Inlet velocity at `dp` ([`inlet_velocity`]), m/s.
    pub fn inlet_velocity(&self, dp: f64) -> f64 {
        inlet_velocity(&self.config, self.inflow_m3_per_s, dp)
    }

    /// Longest span one submission may cover, s: the buffer must not move by more than its
    /// depth less one column between two visits of the host.
    pub fn max_span_s(&self, dp: f64) -> f64 {
        let u = self.inlet_velocity(dp);
        if u > 0.0 {
            f64::from(self.config.inlet.layers - 1) * dp / u
        } else {
            f64::INFINITY
        }
    }

    /// Advances the buffer by `span_s` of inflow and says which columns are due, newest last;
    /// `x_min` is the upstream wall, m.
    pub fn advance(&mut self, span_s: f64, dp: f64, x_min: f64) -> Injection {
        self.inlet_shift_m += self.inlet_velocity(dp) * span_s;
        let mut columns_x_m = Vec::new();
        // The newest column sits at x_min + dp + shift; the one behind it goes dp upstream.
        while self.inlet_shift_m >= dp {
            columns_x_m.push(x_min + self.inlet_shift_m);
            self.inlet_shift_m -= dp;
        }
        Injection { columns_x_m }
    }

    /// Heights of one inlet column's particles, m ([`opening_rows`]).
    pub fn column_heights(&self, dp: f64) -> Vec<f64> {
        opening_rows(&self.config, dp)
    }

    /// Eroded mass per metre of flume width, kg/m (Eq. 34: N dp^2 rho_s, the 2-D sediment
    /// particle mass times the particles collected).
    pub fn eroded_kg_per_m(&self, sediment_particle_mass: f64) -> f64 {
        self.eroded_particles as f64 * sediment_particle_mass
    }
}

/// Heights of the particles of one inlet column, m: the lattice points of the opening
/// (`y_min < y <= y_min + height`).
pub fn opening_rows(f: &OpenFlume, dp: f64) -> Vec<f64> {
    let lo = f.inlet.y_min_m;
    let hi = lo + f.inlet.height_m;
    let first = (lo / dp + 1e-6).floor() as i64 + 1;
    let last = (hi / dp + 1e-6).floor() as i64;
    (first..=last).map(|j| j as f64 * dp).collect()
}

/// Inlet velocity of discharge `q` (m3/s) at `dp`: Q over the opening as its rows fill it,
/// rows x dp high (one row at least), times the width, m/s. The nominal height would place
/// Q rows dp / height: 5 % too much at dp = 7 mm, whose three rows fill 21 mm of a 20 mm
/// opening.
pub fn inlet_velocity(f: &OpenFlume, q: f64, dp: f64) -> f64 {
    let rows = opening_rows(f, dp).len().max(1);
    q / (rows as f64 * dp * f.width_m)
}

/// The slots (indices into the GPU state, which is in cell order) of parked particles, by
/// ascending id, from the state's phases and ids.
pub fn parked_slots(positions: &[[f32; 4]], ids: &[u32], parked_phase: u32) -> Vec<usize> {
    let mut slots: Vec<usize> = (0..positions.len())
        .filter(|&k| positions[k][3].to_bits() == parked_phase)
        .collect();
    slots.sort_by_key(|&k| ids[k]);
    slots
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{CollectorConfig, InletConfig};
    use crate::derived::max_inflow_m3_per_s;

    /// 0.3 c0 through a 2 cm x 8.6 cm opening with c0 = 10 m/s: 3 m/s x 1.72e-3 m2.
    #[test]
    fn the_inlet_carries_at_most_a_third_of_c0_through_its_opening() {
        let f = state(0.0).config;
        assert!((max_inflow_m3_per_s(&f, 10.0) - 5.16e-3).abs() < 1e-12);
    }

    fn state(q: f64) -> FlumeState {
        FlumeState {
            config: OpenFlume {
                width_m: 0.086,
                inflow_m3_per_s: q,
                inlet: InletConfig {
                    y_min_m: 0.055,
                    height_m: 0.02,
                    layers: 4,
                },
                outlet_weir_m: 0.1,
                collector: CollectorConfig {
                    x_min_m: 2.1,
                    x_max_m: 2.5,
                    y_max_m: 0.05,
                },
                bottom_outlet: None,
                sill: None,
                reservoir_particles: 100,
            },
            inflow_m3_per_s: q,
            inlet_shift_m: 0.0,
            eroded_particles: 0,
            parked_particles: 100,
            starved_particles: 0,
            blocked_particles: 0,
            injected_particles: 0,
            excluded_particles: 0,
            excluded_sediment: 0,
            soaked_particles: 0,
        }
    }

    #[test]
    fn inlet_velocity_is_discharge_over_the_opening_its_rows_fill() {
        // 2 m3/h = 5.5556e-4 m3/s through 0.02 m x 0.086 m = 1.72e-3 m2: 0.32300 m/s at
        // dp = 4 mm, five rows (0.056 ... 0.072 m) filling the 20 mm opening.
        let s = state(2.0 / 3600.0);
        let u = s.inlet_velocity(0.004);
        assert!((u - 0.323_00).abs() < 1e-5, "{u}");
        // At dp = 7 mm three rows (0.056, 0.063, 0.070 m) fill 21 mm: 5.5556e-4 / (0.021 x
        // 0.086) = 0.30762 m/s.
        let u = s.inlet_velocity(0.007);
        assert!((u - 0.307_62).abs() < 1e-5, "{u}");
    }

    #[test]
    fn columns_enter_one_dp_apart() {
        let mut s = state(2.0 / 3600.0);
        let dp = 0.004;
        // 0.02 s at 0.323 m/s is 6.46 mm: one column, at x = 6.46 mm, 2.46 mm left over.
        let inj = s.advance(0.02, dp, 0.0);
        assert_eq!(inj.columns_x_m.len(), 1);
        assert!((inj.columns_x_m[0] - 0.00646).abs() < 1e-5);
        assert!((s.inlet_shift_m - 0.00246).abs() < 1e-5);
        // Another 0.03 s: 2.46 + 9.69 = 12.15 mm: columns at 12.15, 8.15 and 4.15 mm, the
        // last one dp + 0.15 mm from the wall, 0.15 mm left over.
        let inj = s.advance(0.03, dp, 0.0);
        assert_eq!(inj.columns_x_m.len(), 3);
        for (x, want) in inj.columns_x_m.iter().zip([0.012_15, 0.008_15, 0.004_15]) {
            assert!((x - want).abs() < 1e-5, "{x} vs {want}");
        }
        assert!((s.inlet_shift_m - 0.000_15).abs() < 1e-5);
        // The buffer never moves by more than its depth less a column per visit.
        assert!((s.max_span_s(dp) - 3.0 * dp / 0.323).abs() < 1e-4);
        assert_eq!(state(0.0).max_span_s(dp), f64::INFINITY);
    }

    #[test]
    fn an_inlet_column_spans_the_opening() {
        // Opening 0.055..0.075 m at dp = 4 mm: lattice points 0.056, 0.060, ... 0.072.
        let h = state(0.0).column_heights(0.004);
        assert_eq!(h.len(), 5);
        assert!((h[0] - 0.056).abs() < 1e-9 && (h[4] - 0.072).abs() < 1e-9);
    }

    #[test]
    fn parked_slots_come_lowest_id_first() {
        let parked = 3u32;
        let p = |phase: u32| [0.0, 0.0, 0.0, f32::from_bits(phase)];
        let positions = [p(1), p(3), p(3), p(2), p(3)];
        let ids = [4, 9, 2, 0, 5];
        assert_eq!(parked_slots(&positions, &ids, parked), vec![2, 4, 1]);
    }

    #[test]
    fn eroded_mass_follows_eq_34() {
        // 10 particles of dp = 4 mm, rho_s = 2710: 10 * 0.004^2 * 2710 = 0.4336 kg/m.
        let mut s = state(0.0);
        s.eroded_particles = 10;
        let m = s.eroded_kg_per_m(0.004 * 0.004 * 2710.0);
        assert!((m - 0.4336).abs() < 1e-9);
    }
}
