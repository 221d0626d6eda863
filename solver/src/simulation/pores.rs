//! The pores of a sand bed laid dry (`SedimentConfig::pores`). The model's sand particles are
//! solid sand and hold no water; a real bed pluviated dry stores its porosity's share of its
//! volume, and takes it from the first water that covers it, at Green & Ampt's rate
//! (`physics::sediment::infiltration`). Each column of the bed one dp wide keeps the depth of
//! water it has taken up, and the water particle lowest over it is parked (out of the flow,
//! available to the inlet, as the outlet parks its water) each time that depth passes another
//! particle's volume. The host does it between submissions, so both backends run it alike.

use super::Simulation;
use crate::config::Case;
use crate::contract::FlumeGpu;
use crate::error::SolverError;
use crate::particles::Particles;
use crate::physics::sediment::infiltration::GreenAmpt;

/// Water within this many dp above the centre of a column's top sand particle wets the
/// column: over held sand it stands 0.6-1 dp off (`bed_contact`), and half a dp more takes in
/// a sheet one particle thick riding a little higher.
const CONTACT_DP: f64 = 1.5;
/// Once wet, a column goes on taking water while its lowest water stands within this many dp:
/// each particle parked leaves a gap a dp deep until the water over it settles, and the
/// ponding is still there.
const PONDED_DP: f64 = 3.0;

/// The bed's columns and the water their pores have taken.
#[derive(Clone, Debug)]
pub struct PoreColumns {
    law: GreenAmpt,
    dp: f64,
    /// Left edge of the first column, m.
    x_edge: f64,
    sand_phase: u32,
    columns: Vec<PoreColumn>,
}

#[derive(Clone, Debug, Default)]
struct PoreColumn {
    /// Depth of water taken up (Green-Ampt's F), m.
    taken_m: f64,
    /// What the column's sand holds when full: its porosity times its depth, m.
    capacity_m: f64,
    /// Water particles parked for it.
    parked: u32,
}

impl PoreColumn {
    /// Full, and every particle of its water parked.
    fn done(&self, dp: f64) -> bool {
        self.taken_m >= self.capacity_m && self.parked >= particles_in(self.capacity_m, dp)
    }
}

/// What `PoreColumns::soak` finds of one column in the state.
#[derive(Clone, Debug, Default)]
struct Seen {
    top_sand: Option<f32>,
    /// (height, id, storage slot) of the water over the column.
    water: Vec<(f32, u32, usize)>,
}

impl PoreColumns {
    /// The columns of `particles`' sand downstream of the inlet's buffer (`flume`), or None
    /// where the case's sediment has no pores. Under the buffer the inlet's own water, imposed
    /// and counted as it enters, covers the sand: the discharge is what crosses its face.
    pub fn new(case: &Case, particles: &Particles, flume: &FlumeGpu) -> Option<PoreColumns> {
        let (k, _) = case.sediment_phases()?;
        let pores = case.phases[k].sediment.as_ref()?.pores?;
        let dp = case.numerics.dp_m;
        let sand_phase = k as u32 + 1;
        let xs: Vec<f64> = (0..particles.len())
            .filter(|&i| particles.phase(i) == sand_phase)
            .map(|i| f64::from(particles.positions[i][0]))
            .filter(|&x| x >= f64::from(flume.inlet_x_face))
            .collect();
        let x_edge = xs.iter().copied().fold(f64::INFINITY, f64::min) - 0.5 * dp;
        let mut columns: Vec<PoreColumn> = Vec::new();
        for x in xs {
            let c = ((x - x_edge) / dp).floor() as usize;
            if columns.len() <= c {
                columns.resize(c + 1, PoreColumn::default());
            }
            columns[c].capacity_m += pores.porosity * dp;
        }
        Some(PoreColumns {
            law: GreenAmpt {
                conductivity_m_per_s: pores.conductivity_m_per_s,
                suction_m: pores.suction_m,
                // A bed laid dry: every pore is empty.
                moisture_deficit: pores.porosity,
            },
            dp,
            x_edge,
            sand_phase,
            columns,
        })
    }

    /// Whether every column holds all it can.
    pub fn full(&self) -> bool {
        self.columns.iter().all(|c| c.done(self.dp))
    }

    /// Per column, left to right: the depth of water taken up (m) and the water particles
    /// parked for it.
    pub fn columns(&self) -> Vec<(f64, u32)> {
        self.columns.iter().map(|c| (c.taken_m, c.parked)).collect()
    }

    /// Advances every column the water covers by `span_s` and returns the storage slots and
    /// ids of the water particles to park, lowest over its column first. `positions` and
    /// `ids` are the state in storage order; water in `flume`'s inlet buffer is the inlet's,
    /// and parked particles are no one's.
    pub fn soak(
        &mut self,
        positions: &[[f32; 4]],
        ids: &[u32],
        flume: &FlumeGpu,
        span_s: f64,
    ) -> Vec<(usize, u32)> {
        let mut seen = vec![Seen::default(); self.columns.len()];
        for (slot, (p, &id)) in positions.iter().zip(ids).enumerate() {
            let Some(c) = self.column_of(p[0]) else {
                continue;
            };
            let phase = p[3].to_bits();
            let s = &mut seen[c];
            if phase == self.sand_phase {
                s.top_sand = Some(s.top_sand.map_or(p[1], |t| t.max(p[1])));
            } else if phase == flume.water_phase && !flume.in_inlet(p) {
                s.water.push((p[1], id, slot));
            }
        }
        let mut out = Vec::new();
        for (col, s) in self.columns.iter_mut().zip(&mut seen) {
            let (Some(top), Some(lowest)) =
                (s.top_sand, s.water.iter().map(|w| w.0).reduce(f32::min))
            else {
                continue;
            };
            let full = particles_in(col.capacity_m, self.dp);
            let reach = if col.taken_m > 0.0 {
                PONDED_DP
            } else {
                CONTACT_DP
            };
            if col.done(self.dp) || f64::from(lowest - top) > reach * self.dp {
                continue;
            }
            let surface = s.water.iter().map(|w| w.0).fold(lowest, f32::max);
            let head = f64::from(surface - top);
            col.taken_m = self
                .law
                .after(col.taken_m, head, span_s)
                .min(col.capacity_m);
            let due = particles_in(col.taken_m, self.dp).min(full);
            s.water
                .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for &(_, id, slot) in s.water.iter().take((due - col.parked.min(due)) as usize) {
                out.push((slot, id));
                col.parked += 1;
            }
        }
        out
    }

    fn column_of(&self, x: f32) -> Option<usize> {
        let c = (f64::from(x) - self.x_edge) / self.dp;
        (c >= 0.0 && (c as usize) < self.columns.len()).then_some(c as usize)
    }
}

/// Water particles (dp^2 each per m of width) a column dp wide holds when it has taken up
/// `depth_m`: the nearest whole number, so that the parked water is never more than half a
/// particle off the depth taken up.
fn particles_in(depth_m: f64, dp: f64) -> u32 {
    (depth_m / dp).round() as u32
}

impl Simulation {
    /// Parks the water the bed's pores have taken over the last `span_s` (`PoreColumns`).
    /// Once every column is full the state is no longer read.
    pub(super) fn soak_pores(&mut self, span_s: f64) -> Result<(), SolverError> {
        let Some(pores) = self.pores.as_mut().filter(|p| !p.full()) else {
            return Ok(());
        };
        let state = self.engine.read_state()?;
        let fl = self.params.flume;
        let soaked = pores.soak(&state.positions, &state.ids, &fl, span_s);
        let rho = self.params.phases[fl.parked_phase as usize].rho0;
        for &(slot, id) in &soaked {
            self.engine
                .place(slot, fl.parking_spot(id), [0.0, 0.0, 0.0, rho]);
        }
        if let Some(f) = &mut self.flume {
            f.parked_particles += soaked.len() as u64;
            f.soaked_particles += soaked.len() as u64;
        }
        Ok(())
    }

    /// The bed's pores, where the case's sediment has them.
    pub fn pores(&self) -> Option<&PoreColumns> {
        self.pores.as_ref()
    }
}
