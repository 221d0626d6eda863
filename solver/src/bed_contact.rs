//! How the water of an open flume sits on its bed, column by column, from a readback of the
//! particles: the cushion under the flow and the held bed's push on it. What the sensors cannot
//! check of the levels issue's goals, read by `bench --levels` and by the levels tests.
//!
//! In every 10 cm column from x = 0.3 to 2.1 m:
//! - the bed's top particle: the highest held sand particle, or, for a bed that is a wall block
//!   (clear water), the highest wall particle below
//!   [`BED_BELOW_M`](crate::bed_contact::BED_BELOW_M);
//! - the gap: the 5th percentile of the water particles' heights above it, in dp (about 1 for
//!   water on a boundary's face, half a dp above its outermost particles);
//! - the held sand's push: its Tait pressure over the weight of the water above it
//!   (`rho_w g (surface - y_top)`, the surface half a dp over the highest water particle).
//!
//! The momentum equation (Eq. 10) weighs a neighbour's pressure by `m_j / rho_j^2 = V_j / rho_j`:
//! water feels sand of Tait pressure p as water of pressure `p rho_w / rho_s`, and at equal
//! compression sand's Tait pressure is `rho_s / rho_w` times water's. So the load the bed carries,
//! as the water feels it, is the Tait ratio times `rho_w / rho_s`
//! ([`BedContact::felt_over_load`](crate::bed_contact::BedContact::felt_over_load)). A held bed
//! that stands as a wall (`physics::boundary`) is felt as walls are, at its own pressure: the ratio
//! itself.

use crate::config::Case;
use crate::derived::{Derived, tait_b};
use crate::particles::{ParticleRegion, Particles};

/// The columns' left edges run from here, m.
pub const FIRST_COLUMN_M: f64 = 0.3;
/// Width of a column, m.
pub const COLUMN_M: f64 = 0.1;
/// Columns from [`FIRST_COLUMN_M`] to 2.1 m, the bed before the sill.
pub const COLUMNS: usize = 18;
/// A wall particle of a fixed bed lies below this height, m (the reservoir's wall above the
/// inlet does not count).
pub const BED_BELOW_M: f64 = 0.15;

/// One column of [`bed_contact`].
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// Left edge, m.
    pub x_min_m: f64,
    /// Height of the bed's top particle, m.
    pub bed_top_m: f64,
    /// What the water does over it; `None` where the column is dry.
    pub wet: Option<Wet>,
}

/// The water over one column's bed.
#[derive(Clone, Debug, PartialEq)]
pub struct Wet {
    /// The water particles' 5th-percentile height above the bed's top particle, in dp.
    pub gap_dp: f64,
    /// The free surface, half a dp over the highest water particle, m.
    pub surface_m: f64,
    /// The top held sand particle's Tait pressure over the weight of the water above it;
    /// `None` over a bed of walls.
    pub tait_over_load: Option<f64>,
}

/// The columns of one readback.
#[derive(Clone, Debug, PartialEq)]
pub struct BedContact {
    pub columns: Vec<Column>,
    /// The share of a held sand particle's Tait pressure the water feels: `rho_w / rho_s`, or 1
    /// where the held bed stands as a wall.
    pub felt_factor: f64,
}

impl BedContact {
    /// The largest gap of the wet columns, in dp; `None` when every column is dry.
    pub fn largest_gap_dp(&self) -> Option<f64> {
        self.wet().map(|w| w.gap_dp).reduce(f64::max)
    }

    /// Median of the held sand's Tait pressure over its load; `None` over a bed of walls.
    pub fn median_tait_over_load(&self) -> Option<f64> {
        let mut r: Vec<f64> = self.wet().filter_map(|w| w.tait_over_load).collect();
        r.sort_by(f64::total_cmp);
        r.get(r.len() / 2).copied()
    }

    /// [`BedContact::median_tait_over_load`] as the water feels it (the module doc).
    pub fn felt_over_load(&self) -> Option<f64> {
        self.median_tait_over_load().map(|r| r * self.felt_factor)
    }

    fn wet(&self) -> impl Iterator<Item = &Wet> {
        self.columns.iter().filter_map(|c| c.wet.as_ref())
    }
}

/// The columns of `particles` (in id order, as `regions` is) of a flume case with a sediment
/// phase; `None` without one. The bed is the held sand, or the walls where no sand is left
/// (a clear-water bed).
pub fn bed_contact(
    case: &Case,
    derived: &Derived,
    particles: &Particles,
    regions: &[u32],
) -> Option<BedContact> {
    let (sediment, water) = case.sediment_phases()?;
    let (sand, water) = (sediment as u32 + 1, water as u32 + 1);
    let dp = case.numerics.dp_m;
    let n = particles.len();
    let sand_there = (0..n).any(|i| particles.phase(i) == sand);
    let held = |i: usize| {
        regions
            .get(i)
            .is_some_and(|&w| ParticleRegion::from_word(w).held)
    };
    let in_bed = |i: usize| {
        if sand_there {
            particles.phase(i) == sand && held(i)
        } else {
            particles.phase(i) == 0
        }
    };
    let x = |i: usize| f64::from(particles.positions[i][0]);
    let y = |i: usize| f64::from(particles.positions[i][1]);
    let rho_w = derived.phases[water as usize].rho0;
    let rho_s = derived.phases[sand as usize].rho0;
    let b_s = tait_b(derived.c0, rho_s);
    let g = case.gravity_magnitude();
    let columns = (0..COLUMNS)
        .filter_map(|k| {
            let x0 = FIRST_COLUMN_M + COLUMN_M * k as f64;
            let inside = |i: usize| x(i) >= x0 && x(i) < x0 + COLUMN_M;
            let top = (0..n)
                .filter(|&i| inside(i) && in_bed(i) && y(i) < BED_BELOW_M)
                .max_by(|&a, &b| y(a).total_cmp(&y(b)))?;
            let mut heights: Vec<f64> = (0..n)
                .filter(|&i| inside(i) && particles.phase(i) == water)
                .map(y)
                .collect();
            heights.sort_by(f64::total_cmp);
            let wet = heights.last().map(|&highest| {
                let surface_m = highest + 0.5 * dp;
                let rho = f64::from(particles.vel_rho[top][3]);
                let tait = b_s * ((rho / rho_s).powi(7) - 1.0);
                Wet {
                    gap_dp: (heights[(heights.len() as f64 * 0.05) as usize] - y(top)) / dp,
                    surface_m,
                    tait_over_load: sand_there.then(|| tait / (rho_w * g * (surface_m - y(top)))),
                }
            });
            Some(Column {
                x_min_m: x0,
                bed_top_m: y(top),
                wet,
            })
        })
        .collect();
    Some(BedContact {
        columns,
        felt_factor: if case.held_bed_is_wall() {
            1.0
        } else {
            rho_w / rho_s
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::derived::derive;
    use crate::physics::sediment::pass::REGION_HELD;

    /// One column by hand, the flume at dp = 1 cm: held sand topped at y = 0.05 m, water from
    /// 0.06 to 0.08 m (surface 0.085 m) over it, with a free sand particle beside it that must
    /// not count as the bed. The gap is (0.06 - 0.05) / dp = 1; the load is 1000 x 9.81 x 0.035
    /// = 343.35 Pa; a sand density whose Tait pressure is 2.71 times that (B_s = 10^2 x 2710 /
    /// 7 = 38,714 Pa: (1 + 930.5 / 38,714)^(1/7) = 1.003399, 2719.21 kg/m3) is felt as the load.
    #[test]
    fn a_column_by_hand() {
        let case = Case::from_path_with(
            std::path::Path::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../launch_configs/ulbra_flume.yaml"
            )),
            &["numerics.dp_m=0.01".to_string()],
        )
        .expect("the bundled case");
        let derived = derive(&case);
        let (water, sand) = (1u32, 2u32);
        let mut p = Particles::default();
        let mut regions = Vec::new();
        let mut push = |x: f32, y: f32, phase: u32, rho: f32, held: bool| {
            p.positions.push([x, y, 0.0, f32::from_bits(phase)]);
            p.vel_rho.push([0.0, 0.0, 0.0, rho]);
            p.ids.push(p.ids.len() as u32);
            regions.push(if held { REGION_HELD } else { 0 });
        };
        push(0.35, 0.04, sand, 2715.0, true);
        push(0.35, 0.05, sand, 2719.21, true);
        push(0.36, 0.07, sand, 2710.0, false);
        for k in 0..3 {
            push(0.34, 0.06 + 0.01 * k as f32, water, 1000.0, false);
        }
        let contact = bed_contact(&case, &derived, &p, &regions).expect("a sand bed");
        assert_eq!(contact.columns.len(), 1, "only x = 0.3-0.4 m has a bed");
        let c = &contact.columns[0];
        assert!((c.bed_top_m - 0.05).abs() < 1e-6, "{c:?}");
        let wet = c.wet.as_ref().expect("water over it");
        assert!((wet.gap_dp - 1.0).abs() < 1e-4, "{wet:?}");
        assert!((wet.surface_m - 0.085).abs() < 1e-6, "{wet:?}");
        let felt = contact.felt_over_load().expect("held sand");
        assert!((felt - 1.0).abs() < 2e-3, "{felt}");
        assert!((contact.median_tait_over_load().expect("held") - 2.71).abs() < 6e-3);
    }
}
