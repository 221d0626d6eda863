//! What the rheology passes leave each particle for the next, kept by id: the sorted order
//! changes from step to step, the ids do not.

use super::multiphase::{BED_UNKNOWN, RheologyPass, bed_top_of};
use crate::physics::sediment::pass::{NO_FLUX, NO_TARGET};

/// The rheology's memory of each particle, by id.
#[derive(Clone, Default)]
pub(super) struct ById {
    /// Region words (region | REGION_HELD), as the last rheology pass left them.
    pub regions: Vec<u32>,
    /// The bed load each held particle at the surface passed on in the last pass that drew
    /// (`van_rijn_exner`), and the id it passed it to; `NO_FLUX` for any other.
    pub fluxes: Vec<(f32, u32)>,
    /// Under `van_rijn_exner`, where each particle's last walk found it on the bed
    /// (`multiphase::Holds::bed_tops`).
    pub bed_tops: Vec<u8>,
    /// What each held grain's last walk bounds its kernel mass by (NaN: none;
    /// `multiphase::Holds::records`).
    pub records: Vec<f32>,
    /// Under `van_rijn_exner`, whether the last pass found each particle with nothing that
    /// stirs in reach (`multiphase::Holds::dry_before`).
    pub dry: Vec<bool>,
}

impl ById {
    /// Nothing known yet of `n` particles.
    pub fn new(n: usize) -> ById {
        ById {
            regions: vec![0; n],
            fluxes: vec![(NO_FLUX, NO_TARGET); n],
            bed_tops: vec![BED_UNKNOWN; n],
            records: vec![f32::NAN; n],
            dry: vec![false; n],
        }
    }

    /// Keeps what `pass` left the particles `ids` (sorted order), the first `active` of them
    /// in the flow: the regions, and the bed tops, records and bed loads where the pass has
    /// them. One loop over the ids, not one for each array: the ids are random, and this runs
    /// beside the force pass's side filling (`step.rs`).
    pub fn keep(&mut self, pass: &RheologyPass, ids: &[u32], active: usize) {
        let records = !pass.records.is_empty();
        for (k, (r, &id)) in pass.out.iter().zip(ids).enumerate() {
            let id = id as usize;
            self.regions[id] = r.word();
            // The bed load of the pass that wore the bed, which the next one settles
            // downstream.
            if pass.exner {
                self.bed_tops[id] = bed_top_of(r);
                self.dry[id] = pass.dry[k];
            }
            // A held grain under the water sleeps by its last walk's record
            // (`multiphase::deep`).
            if records {
                self.records[id] = pass.records[k];
            }
            if pass.wears {
                self.fluxes[id] = (r.flux, r.target);
            }
        }
        // Parked particles are out of the flow: no region, no walk, no load.
        for &id in &ids[active..] {
            let id = id as usize;
            self.regions[id] = 0;
            if pass.exner {
                self.bed_tops[id] = BED_UNKNOWN;
                self.dry[id] = false;
            }
            if records {
                self.records[id] = f32::NAN;
            }
            if pass.wears {
                self.fluxes[id] = (NO_FLUX, NO_TARGET);
            }
        }
    }

    /// Region words set from outside (`Engine::write_regions`): no walk's, so every grain
    /// walks before it may sleep.
    pub fn set_regions(&mut self, words: &[u32]) {
        self.regions.copy_from_slice(words);
        self.bed_tops.fill(BED_UNKNOWN);
        self.forget_records();
    }

    /// After a held grain was parked, no record bounds a kernel mass it was in
    /// (`multiphase::deep`), and no dry grain's last walk is known to have weighed the
    /// neighbours it has now.
    pub fn forget_records(&mut self) {
        self.records.fill(f32::NAN);
        self.dry.fill(false);
    }
}
