//! The sediment budget of an open flume: where the sand the flow has moved is, output by output,
//! and where along the bed it came from. It is what a researcher needs to see why a run eroded
//! what it did: how much sand the flow ever moved, how far it went, and whether it is moving
//! still, suspended, laid down again, past the bed's end or collected.
//!
//! The budget is taken from the particles at each output, by id, so a grain that yielded and
//! settled again between two outputs without moving is not seen. A grain counts as
//! **mobilised** from the first output at which it is yielded, bed load or suspended (regions
//! 2-4 of Figure 2), or has moved more than half a dp from where it started, or has left the
//! sand; it stays mobilised. Each mobilised grain is then in exactly one of:
//! - **collected**: no longer sand, recycled as water after the collector took it (or after
//!   leaving over the weir, or as a grain excluded for its density: `excluded` says how many);
//! - **past the bed**: sand beyond the collector's upstream edge, in the pit or over the crest;
//! - **suspended**: region 4;
//! - **moving**: regions 2 and 3;
//! - **deposited**: held or un-yielded again on the bed.

use crate::config::Case;
use crate::particles::{ParticleRegion, Particles};
use crate::physics::sediment::suspension::Region;

/// Equal stretches of the bed, by where its grains started, that the budget counts apart.
pub const STRETCHES: usize = 5;
/// A grain that has gone this far from its start has travelled far, m (the length over which a
/// grain hopping as bed load would have left its neighbourhood many times over).
pub const FAR_M: f64 = 0.1;

/// The budget at one output, in grains (sand particles).
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetRow {
    pub time_s: f64,
    pub mobilised: u64,
    pub moving: u64,
    pub suspended: u64,
    pub deposited: u64,
    pub past_bed: u64,
    pub collected: u64,
    /// Of the collected, those the flume's books count as excluded for their density.
    pub excluded: u64,
    /// Mobilised grains now further than [`FAR_M`] from where they started (collected ones
    /// count by where they were last seen as sand).
    pub travelled_far: u64,
    /// The furthest any grain has gone downstream of its start, m.
    pub furthest_m: f64,
    /// Mobilised grains by the stretch they started in, upstream first ([`SedimentBudget::stretch_edges_m`]).
    pub mobilised_by_stretch: [u64; STRETCHES],
    /// The mass the flow has worn off grains it still holds, in grains: none of the counts
    /// above sees it, for no grain has left. Under `van_rijn_exner` a held grain loses what
    /// it passes downstream less what it is passed, and what settles on it beyond what was
    /// worn off counts against it, so along the bed's top row the losses add up to the bed
    /// load passed over the row's last held grain into the pit (negative by stretch where the
    /// bed has built up). Under `van_rijn_integrated` it is what was picked up off grains not
    /// yet released.
    pub worn: f64,
    /// [`BudgetRow::worn`] by the stretch the worn grains started in, upstream first.
    pub worn_by_stretch: [f64; STRETCHES],
}

/// One grain's history.
#[derive(Debug, Clone, Copy)]
struct Grain {
    id: usize,
    start: [f64; 2],
    last_x: f64,
    mobilised: bool,
}

/// The sand of a run, grain by grain.
#[derive(Debug, Clone)]
pub struct SedimentBudget {
    grains: Vec<Grain>,
    sand_phase: u32,
    dp: f64,
    /// The collector's upstream edge, m: sand beyond it has left the bed.
    past_bed_x_m: f64,
    /// Whether the sand wears net of what settles (`van_rijn_exner`): its words' units signed.
    exner: bool,
    edges_m: [f64; STRETCHES + 1],
}

impl SedimentBudget {
    /// The budget of an open flume with a sediment, from its particles as generated; None for
    /// a closed tank or clear water.
    pub fn new(case: &Case, initial: &Particles) -> Option<SedimentBudget> {
        let flume = case.open_flume.as_ref()?;
        let (sand, _) = case.sediment_phases()?;
        let exner = case.wears_by_exner();
        let sand_phase = sand as u32 + 1;
        let grains: Vec<Grain> = (0..initial.len())
            .filter(|&i| initial.phase(i) == sand_phase)
            .map(|i| {
                let p = initial.positions[i];
                let start = [f64::from(p[0]), f64::from(p[1])];
                Grain {
                    id: initial.ids[i] as usize,
                    start,
                    last_x: start[0],
                    mobilised: false,
                }
            })
            .collect();
        if grains.is_empty() {
            return None;
        }
        let lo = grains.iter().map(|g| g.start[0]).fold(f64::MAX, f64::min);
        let hi = grains.iter().map(|g| g.start[0]).fold(f64::MIN, f64::max);
        let dp = case.numerics.dp_m;
        // Each stretch holds the grains whose column lies in it: the edges are the columns' faces.
        let (lo, hi) = (lo - 0.5 * dp, hi + 0.5 * dp);
        let edges_m = std::array::from_fn(|k| lo + (hi - lo) * k as f64 / STRETCHES as f64);
        Some(SedimentBudget {
            grains,
            sand_phase,
            dp,
            past_bed_x_m: flume.collector.x_min_m,
            exner,
            edges_m,
        })
    }

    /// The stretches' bounds along the flume, m, upstream first.
    pub fn stretch_edges_m(&self) -> [f64; STRETCHES + 1] {
        self.edges_m
    }

    /// Forgets what the flow has moved: the run starts again from the particles as generated
    /// (the twin's reset), so no grain is mobilised until the new run moves it.
    pub fn restart(&mut self) {
        for g in &mut self.grains {
            g.mobilised = false;
            g.last_x = g.start[0];
        }
    }

    /// Takes the budget of `particles` (in id order, as `Simulation::read_particles` gives
    /// them) with their region words (`Simulation::regions`) at `time_s`; `excluded_sediment`
    /// is the flume's count of sand excluded for its density.
    pub fn update(
        &mut self,
        time_s: f64,
        particles: &Particles,
        regions: &[u32],
        excluded_sediment: u64,
    ) -> BudgetRow {
        let mut row = BudgetRow {
            time_s,
            mobilised: 0,
            moving: 0,
            suspended: 0,
            deposited: 0,
            past_bed: 0,
            collected: 0,
            excluded: excluded_sediment,
            travelled_far: 0,
            furthest_m: 0.0,
            mobilised_by_stretch: [0; STRETCHES],
            worn: 0.0,
            worn_by_stretch: [0.0; STRETCHES],
        };
        let mut worn = [0.0; STRETCHES];
        let (sand_phase, dp, past_bed_x) = (self.sand_phase, self.dp, self.past_bed_x_m);
        let edges = self.edges_m;
        for g in &mut self.grains {
            let is_sand = g.id < particles.len() && particles.phase(g.id) == sand_phase;
            let place = if is_sand {
                let p = particles.positions[g.id];
                let (x, y) = (f64::from(p[0]), f64::from(p[1]));
                g.last_x = x;
                let decoded = ParticleRegion::from_word(regions.get(g.id).copied().unwrap_or(0));
                worn[stretch(&edges, g.start[0])] += decoded.worn(self.exner);
                let region = decoded.region;
                let shifted = (x - g.start[0]).hypot(y - g.start[1]) > 0.5 * dp;
                let yielded = matches!(
                    region,
                    Some(Region::Yielded | Region::BedLoad | Region::Suspended)
                );
                g.mobilised |= shifted || yielded;
                if x > past_bed_x {
                    Place::PastBed
                } else if region == Some(Region::Suspended) {
                    Place::Suspended
                } else if yielded {
                    Place::Moving
                } else {
                    Place::Deposited
                }
            } else {
                g.mobilised = true;
                Place::Collected
            };
            if !g.mobilised {
                continue;
            }
            row.mobilised += 1;
            match place {
                Place::Collected => row.collected += 1,
                Place::PastBed => row.past_bed += 1,
                Place::Suspended => row.suspended += 1,
                Place::Moving => row.moving += 1,
                Place::Deposited => row.deposited += 1,
            }
            let travel = g.last_x - g.start[0];
            if travel.abs() > FAR_M {
                row.travelled_far += 1;
            }
            row.furthest_m = row.furthest_m.max(travel);
            row.mobilised_by_stretch[stretch(&edges, g.start[0])] += 1;
        }
        row.worn_by_stretch = worn;
        row.worn = worn.iter().sum();
        row
    }
}

/// The stretch between `edges_m` that a grain which started at `x` m along the flume belongs to.
fn stretch(edges_m: &[f64; STRETCHES + 1], x: f64) -> usize {
    edges_m[1..STRETCHES]
        .iter()
        .take_while(|&&e| x >= e)
        .count()
}

/// Where a mobilised grain is at an output.
enum Place {
    Collected,
    PastBed,
    Suspended,
    Moving,
    Deposited,
}

#[cfg(test)]
mod tests;
