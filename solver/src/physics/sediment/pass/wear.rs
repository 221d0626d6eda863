//! What the flow wears off a sediment particle in a pass: its pick-up, and under Exner's
//! balance what settles on it.

use super::{NO_FLUX, Rheology};
use crate::physics::sediment::pickup::{
    EXNER_SPENT, bed_load_flux, exner_exchange, exner_pickup, integrated_pickup, picked_up,
    pickup_rate,
};

impl Rheology<'_> {
    /// Whether particle `id`, under a bed shear stress `tau_b` against its critical `tau_bcr`,
    /// is picked up in this pass, with the mass picked up of it after the pass (`units` before;
    /// `van_rijn_integrated`, and net of the bed load `upstream` passes on under
    /// `van_rijn_exner`) and the bed load it passes on: picked up always where Shields releases
    /// at once, never in a pass without draws.
    pub(super) fn pick_up(
        &self,
        units: i32,
        id: u32,
        (tau_b, tau_bcr): (f32, f32),
        upstream: f32,
    ) -> (bool, i32, f32) {
        let per_s = self.model.pickup_per_s;
        if per_s == 0.0 {
            return (true, 0, NO_FLUX);
        }
        let rate = pickup_rate(per_s, tau_b, tau_bcr);
        let step = self.model.exner_step_per_stage;
        let flux = if step > 0.0 {
            bed_load_flux(rate, step, tau_b, tau_bcr)
        } else {
            NO_FLUX
        };
        let Some(d) = self.draws else {
            return (false, units, flux);
        };
        if step > 0.0 && tau_bcr <= 0.0 {
            // Nothing holds the grain (`slope_factors`: the roof of a hole, say): it leaves
            // whole, worn no more, and what was passed to it settles on it.
            let (_, units, out) = self.settle(units, id, upstream);
            return (true, units, out);
        }
        let (worn, flux) = if step > 0.0 {
            let (out, net) = exner_exchange(flux, upstream, rate, units, d.dt_s);
            (exner_pickup(units, id, d.step, net, d.dt_s), out)
        } else if self.model.pickup_integrated {
            let units = units.max(0) as u32;
            let worn = integrated_pickup(units, id, d.step, rate, d.dt_s);
            (worn.map(|u| u as i32), flux)
        } else {
            return (picked_up(id, d.step, rate, d.dt_s), 0, NO_FLUX);
        };
        match worn {
            Some(units) => (false, units, flux),
            None if step > 0.0 => (true, EXNER_SPENT, flux),
            None => (true, 0, NO_FLUX),
        }
    }

    /// Under `van_rijn_exner`, a particle the bed did not hold, with `units` worn off it: what
    /// was passed to it, `upstream`, settles on it, up to a whole particle more than its own
    /// mass (beyond that it passes over it, [`exner_exchange`]); it is picked up of no more.
    pub(super) fn settle(&self, units: i32, id: u32, upstream: f32) -> (bool, i32, f32) {
        let Some(d) = self.draws else {
            return (false, units, 0.0);
        };
        let (out, net) = exner_exchange(0.0, upstream, 0.0, units, d.dt_s);
        let settled = exner_pickup(units, id, d.step, net, d.dt_s);
        (false, settled.unwrap_or(EXNER_SPENT), out)
    }
}
