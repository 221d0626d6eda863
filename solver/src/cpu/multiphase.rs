//! The water-sediment model's neighbour passes on the CPU backend (`rheology.wgsl`,
//! `hold.wgsl`): `physics::sediment`'s per-pair and per-particle functions over the
//! cell list, particles shared out among threads in blocks and the rheology's pairs taken in
//! lanes, a group of one row of cells at once, as the force pass takes them. A release reads
//! the regions the rheology pass left, before any release, so it does not depend on the order
//! threads run.
//!
//! The awake set: a grain held after the last pass with nothing but resting particles (held
//! grains and walls at rest) in the cells within reach sleeps. Its sums would then hold no
//! water and no velocity difference: it is not at the surface, its strain rate is zero, its
//! concentration one, and it stays held with the viscosity its own density gives. That is
//! what [`Rheology::finish`] gives from the particle's own start, to the bit, without the
//! neighbour loop; its neighbours read only its position, velocity and density, which the
//! pass does not change. A wall, whose rheology is none, is spared the walk as well.
//!
//! Under `van_rijn_exner` two things of a held grain's rheology depend on its neighbours even
//! with none of them moving. A grain named in the last pass that drew takes the load passed to
//! it: it does not sleep. And a grain at the bed's top offers to take load (a flux of 0, not
//! `NO_FLUX`), which the particle that names a target reads in the next pass that draws; its
//! own start cannot tell it, but its last walk did ([`Holds::bed_tops`]): its neighbours have
//! not moved since, for a neighbour that moves is one that stirs. That walk weighed its
//! neighbours' volumes too, so their densities must not have changed either: under Exner's
//! balance a wall or held grain at rest stirs as well where its density is not its rest
//! density, as a wall's or a held bed's is where water in its own reach sets it
//! (`physics::boundary`). A grain whose last walk is not known (none yet, or its word set from
//! outside) does not sleep. Nor does a grain whose last pass found something that stirs in
//! reach: its last walk then weighed water that has since gone, or a density that has since
//! come back to rest, or it slept by a record taken under the water. It walks once dry, and
//! from then on its neighbours are those that walk weighed: none has moved, and each has kept
//! its rest density, or it would have stirred. After a held grain is parked (`ById`), every
//! grain walks again.
//!
//! Under the water a held grain deep in the bed sleeps too, where its last walk bounds its
//! kernel mass over the surface threshold ([`deep`]).
//!
//! The release (Drucker-Prager) sums the stress of the moving sediment around a held grain:
//! a grain with none in the cells within reach is not walked, since empty sums release
//! nothing (`release_held`).

use super::grid::{Flagged, Grid, Group};
use super::simd;
use crate::physics::Params;
use crate::physics::interaction::phase_index;
use crate::physics::lanes::{LANES, Lanes};
use crate::physics::sediment::hold::{Release, Transmitted};
use crate::physics::sediment::pass::{
    Draws, NO_FLUX, NO_TARGET, ParticleRheology, REGION_HELD, Rheology, RheologySide, RheologySums,
    SedimentModel,
};
use crate::physics::sediment::suspension::Region;
use deep::{Deep, NO_RECORD};
use rayon::prelude::*;

mod deep;

/// The held sediment of the last pass and the pick-up draws of this one.
pub struct Holds<'a> {
    /// Each active particle's region word after the last pass (sorted order): whether it was
    /// held, and the mass picked up of it so far.
    pub words: &'a [u32],
    /// The particles' ids (sorted order): their draws'.
    pub ids: &'a [u32],
    /// The bed load each held particle at the surface passed on in the last pass, and the id
    /// it passed it to, by id (`van_rijn_exner`; [`NO_FLUX`] for any other).
    pub fluxes: &'a [(f32, u32)],
    pub draws: Option<Draws>,
    /// Whether held grains far from anything moving, or deep under the water, sleep (see the
    /// module doc); false: every grain runs its sums (the full computation the awake set is
    /// checked against).
    pub awake_set: bool,
    /// Under `van_rijn_exner`, whether each particle lay at the bed's top when it last walked
    /// its neighbours, by id ([`BED_TOP`], [`BED_BELOW`], or [`BED_UNKNOWN`]); empty otherwise.
    pub bed_tops: &'a [u8],
    /// What each held grain's last walk bounds its kernel mass by, by id
    /// ([`RheologyPass::records`]; NaN: none); empty where no grain sleeps under the water.
    pub records: &'a [f32],
    /// Under `van_rijn_exner`, whether the last pass found each particle with nothing that
    /// stirs in reach, by id ([`RheologyPass::dry`]); empty: none.
    pub dry_before: &'a [bool],
}

/// A particle's last walk found it at the bed's top ([`Holds::bed_tops`]).
pub const BED_TOP: u8 = 2;
/// A particle's last walk found it off the bed's top.
pub const BED_BELOW: u8 = 1;
/// A particle that has not walked since its word was last set.
pub const BED_UNKNOWN: u8 = 0;

/// What a particle's rheology says of its place on the bed, for [`Holds::bed_tops`]: where
/// it offers to take bed load, it lies at the bed's top.
pub fn bed_top_of(r: &ParticleRheology) -> u8 {
    if r.flux == NO_FLUX {
        BED_BELOW
    } else {
        BED_TOP
    }
}

/// The rheology of the active particles, and how many of them (sleeping grains and walls) were
/// spared the walk over their neighbours.
pub struct RheologyPass {
    pub out: Vec<ParticleRheology>,
    pub asleep: usize,
    /// Seconds in the walk over the neighbours (`StageTime::walk_seconds`).
    pub walk_s: f64,
    /// Where held grains under the water may sleep ([`deep`]), the record each active particle
    /// leaves (sorted order; NaN: none), for [`Holds::records`]; empty elsewhere.
    pub records: Vec<f32>,
    /// Whether each active particle is a held grain with nothing that stirs in reach (sorted
    /// order): a dry grain sleeps only where the pass before found it dry too (see the module
    /// doc).
    pub dry: Vec<bool>,
    /// Under `van_rijn_exner`: the bed tops and, where the pass drew (`wears`), the bed loads
    /// passed on are the pass's to keep too ([`Holds::bed_tops`], [`Holds::fluxes`]).
    pub exner: bool,
    pub wears: bool,
}

/// The rheology of the active particles (sorted order), then, with `release`, the release of
/// held sediment.
#[allow(clippy::too_many_arguments)]
pub fn rheology_pass(
    pool: &rayon::ThreadPool,
    params: &Params,
    model: &SedimentModel,
    grid: &Grid,
    pos: &[[f32; 4]],
    vel: &[[f32; 4]],
    holds: &Holds,
    release: bool,
) -> RheologyPass {
    let pass = Rheology::new(params, model).with_draws(holds.draws);
    let n = holds.words.len();
    let exner = model.exner();
    let (sleepers, passed) = Sleepers::new(pool, (params, model), &pass, grid, (pos, vel), holds);
    let own = Own::new(pool, &pass, &sleepers, holds, (pos, vel));
    let pairs = Pairs {
        params,
        pass: &pass,
        grid,
        pos,
        vel,
        vol: &own.vol,
        sides: &own.sides,
        ids: holds.ids,
        fluxes: &own.fluxes,
        passed: passed.as_deref().unwrap_or_default(),
        words: holds.words,
        asleep: &own.asleep,
        bed_tops: exner.then_some(holds.bed_tops),
        deep: sleepers.deep.as_ref(),
        recordable: &own.recordable,
        records: holds.records,
    };
    // Every slot is written by its block.
    let mut out = vec![ParticleRheology::NONE; n];
    let mut records = vec![NO_RECORD; n];
    let walk = std::time::Instant::now();
    let asleep = pool.install(|| {
        out.par_chunks_mut(BLOCK)
            .zip(records.par_chunks_mut(BLOCK))
            .enumerate()
            .map(|(b, (out, records))| {
                simd::dispatch(
                    #[inline(always)]
                    || pairs.block(b * BLOCK, out, records),
                )
            })
            .sum()
    });
    let walk_s = walk.elapsed().as_secs_f64();
    if release {
        let awake = holds.awake_set;
        release_held(pool, (params, model), grid, (pos, vel), awake, &mut out);
    }
    if sleepers.deep.is_none() {
        records.clear();
    }
    RheologyPass {
        out,
        asleep,
        walk_s,
        records,
        dry: own.dry,
        exner,
        wears: wears(model, holds),
    }
}

/// What the walk reads of each active particle besides its position and velocity, and how it
/// sleeps (sorted order).
struct Own {
    vol: Vec<f32>,
    /// The last pass's bed load and where it went (`Holds::fluxes`).
    fluxes: Vec<(f32, u32)>,
    sides: Vec<RheologySide>,
    asleep: Vec<bool>,
    /// Whether its walk leaves a record ([`deep`]).
    recordable: Vec<bool>,
    /// [`RheologyPass::dry`].
    dry: Vec<bool>,
}

impl Own {
    /// One parallel region, not two: a region costs a step more than its work at CI size
    /// (README, speed). Each block writes its slots of the six in place: an `unzip` into
    /// vectors gathers each thread's pieces and joins them on one thread.
    fn new(
        pool: &rayon::ThreadPool,
        pass: &Rheology,
        sleepers: &Sleepers,
        holds: &Holds,
        (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
    ) -> Own {
        let n = holds.words.len();
        let mut own = Own {
            vol: vec![0.0; n],
            fluxes: vec![(NO_FLUX, NO_TARGET); n],
            sides: vec![RheologySide::default(); n],
            asleep: vec![false; n],
            recordable: vec![false; n],
            dry: vec![false; n],
        };
        let Own {
            vol,
            fluxes,
            sides,
            asleep,
            recordable,
            dry,
        } = &mut own;
        pool.install(|| {
            let mine = vol.par_chunks_mut(BLOCK).zip(fluxes.par_chunks_mut(BLOCK));
            let sleep = asleep
                .par_chunks_mut(BLOCK)
                .zip(recordable.par_chunks_mut(BLOCK))
                .zip(dry.par_chunks_mut(BLOCK));
            let blocks = mine.zip(sides.par_chunks_mut(BLOCK)).zip(sleep).enumerate();
            blocks.for_each(
                |(b, (((vol, fluxes), sides), ((asleep, recordable), dry)))| {
                    for (k, i) in (b * BLOCK..).take(vol.len()).enumerate() {
                        sides[k] = pass.side(&pos[i], &vel[i]);
                        (asleep[k], recordable[k], dry[k]) = sleepers.state(i, &sides[k].x);
                        // In sorted order: the loads are summed and weighed in that order.
                        let flux = holds.fluxes.get(holds.ids[i] as usize);
                        fluxes[k] = *flux.unwrap_or(&(NO_FLUX, NO_TARGET));
                        vol[k] = pass.volume(&pos[i], &vel[i]);
                    }
                },
            );
        });
        own
    }
}

/// Whether a pass wears the bed under Exner's balance: it draws the pick-ups, so the loads it
/// passes on are settled downstream by the next pass ([`passed`]).
fn wears(model: &SedimentModel, holds: &Holds) -> bool {
    model.exner() && holds.draws.is_some()
}

/// What decides which held grains sleep in a pass (see the module doc).
struct Sleepers<'a> {
    grid: &'a Grid,
    holds: &'a Holds<'a>,
    /// With the awake set, the particles whose presence in reach wakes a dry grain.
    stirrers: Option<Flagged>,
    /// Under `van_rijn_exner`, by id, whether the last pass named the particle to take load.
    named: Option<Vec<bool>>,
    exner: bool,
    /// Where held grains under the water may sleep ([`deep`]).
    deep: Option<Deep>,
}

impl<'a> Sleepers<'a> {
    /// The sleepers of a pass, and, where it wears the bed under Exner's balance, the bed
    /// load passed to each particle by id ([`passed`]; read only there, by
    /// `Rheology::exchange_of`). Four serial loops over the particles, two at a time: each
    /// is a few microseconds on the CI flume, too little to share out.
    fn new(
        pool: &rayon::ThreadPool,
        (params, model): (&Params, &SedimentModel),
        pass: &Rheology,
        grid: &'a Grid,
        (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
        holds: &'a Holds<'a>,
    ) -> (Sleepers<'a>, Option<Vec<f32>>) {
        let exner = model.exner();
        let awake = holds.awake_set;
        let wears = wears(model, holds);
        let ((stirrers, deep), (named, passed)) = pool.install(|| {
            rayon::join(
                || {
                    rayon::join(
                        || awake.then(|| stirring(params, (pos, vel), holds.words, exner)),
                        || {
                            let words = holds.words;
                            let deep = || Deep::new(params, model, pass, (pos, vel), words);
                            awake.then(deep).flatten()
                        },
                    )
                },
                || {
                    rayon::join(
                        || exner.then(|| named(holds.fluxes)),
                        || wears.then(|| passed(holds.fluxes, holds.ids)),
                    )
                },
            )
        });
        let sleepers = Sleepers {
            grid,
            holds,
            stirrers,
            named,
            exner,
            deep,
        };
        (sleepers, passed)
    }

    /// Whether the grain at sorted index `i`, at `x`, sleeps, whether its walk, if it takes
    /// one, leaves a record ([`deep`]), and whether it is dry: a dry held grain sleeps (under
    /// Exner's balance only where the pass before found it dry too), and under the water a
    /// quiet one whose record allows.
    fn state(&self, i: usize, x: &[f32; 3]) -> (bool, bool, bool) {
        // A particle not held stirs itself (`stirring`): it is not dry.
        if self.holds.words[i] & REGION_HELD == 0 {
            return (false, false, false);
        }
        let dry = (self.stirrers.as_ref()).is_some_and(|s| !self.grid.any_near(s, x));
        if dry {
            let walked_dry = !self.exner || self.dry_before(i);
            return (walked_dry && self.may_sleep(i), self.deep.is_some(), true);
        }
        let quiet = self.deep.as_ref().is_some_and(|d| d.quiet(self.grid, x));
        let deep_asleep = quiet && self.deep.as_ref().is_some_and(|d| d.sleeps(self.record(i)));
        (deep_asleep && self.may_sleep(i), quiet, false)
    }

    /// Whether the pass before found the grain at sorted index `i` dry.
    fn dry_before(&self, i: usize) -> bool {
        let id = self.holds.ids[i] as usize;
        self.holds.dry_before.get(id).is_some_and(|&d| d)
    }

    /// Under Exner's balance a grain sleeps only where its last walk is known and no load was
    /// named to it (see the module doc).
    fn may_sleep(&self, i: usize) -> bool {
        let id = self.holds.ids[i] as usize;
        let named = self.named.as_ref().is_some_and(|n| !n[id]);
        !self.exner || (self.holds.bed_tops[id] != BED_UNKNOWN && named)
    }

    /// The record the last walk of the grain at sorted index `i` left.
    fn record(&self, i: usize) -> f32 {
        let id = self.holds.ids[i] as usize;
        self.holds.records.get(id).copied().unwrap_or(NO_RECORD)
    }
}

/// Releases the held sediment whose neighbours transmit enough stress (`hold.wgsl`), from the
/// regions `out` the rheology pass left, before any release. With the awake set a held grain
/// with no moving sediment in the cells within reach is not walked: its sums would stay empty,
/// which releases nothing, the value the walk gives (`tests/awake_set.rs`); with none moving
/// anywhere, none is.
fn release_held(
    pool: &rayon::ThreadPool,
    (params, model): (&Params, &SedimentModel),
    grid: &Grid,
    (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
    awake_set: bool,
    out: &mut [ParticleRheology],
) {
    let stage = Release::new(params, model);
    let moving = awake_set.then(|| Flagged::new(out.len(), |k| stage.transmits(&pos[k], &out[k])));
    if moving.as_ref().is_some_and(Flagged::is_empty) {
        return;
    }
    let released: Vec<bool> = pool.install(|| {
        (0..out.len())
            .into_par_iter()
            .map(|i| {
                if !stage.applies(&pos[i], &out[i]) {
                    return false;
                }
                let x = [pos[i][0], pos[i][1], pos[i][2]];
                if moving.as_ref().is_some_and(|m| !grid.any_near(m, &x)) {
                    return false;
                }
                let mut sums = Transmitted::default();
                grid.rows(grid.coords(&x), |range| {
                    for j in range {
                        stage.add_pair(&pos[i], (&pos[j], &vel[j], &out[j]), &mut sums);
                    }
                });
                stage.released(vel[i][3], &sums)
            })
            .collect()
    });
    for (r, _) in out.iter_mut().zip(released).filter(|(_, go)| *go) {
        r.held = false;
        r.region = Region::Yielded as u32;
        r.pickup = stage.carried(r.pickup);
    }
}

/// The particles that stir a held grain's neighbourhood: any but held grains and walls at
/// rest, and under Exner's balance (`exner`) those too where their density is not their rest
/// density. A held grain with none of them in the cells within reach sleeps (see the module
/// doc).
fn stirring(
    params: &Params,
    (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
    words: &[u32],
    exner: bool,
) -> Flagged {
    let rests = |k: usize| {
        let still = vel[k][..3].iter().all(|&v| v == 0.0);
        let held = words[k] & REGION_HELD != 0;
        let phase = &params.phases[phase_index(&pos[k])];
        let settled = !exner || vel[k][3] == phase.rho0;
        still && settled && (held || !phase.mobile)
    };
    Flagged::new(words.len(), |k| !rests(k))
}

/// By id, whether the last pass that drew named the particle to take another's bed load.
fn named(fluxes: &[(f32, u32)]) -> Vec<bool> {
    let mut named = vec![false; fluxes.len()];
    for &(_, target) in fluxes {
        if let Some(n) = named.get_mut(target as usize) {
            *n = true;
        }
    }
    named
}

/// By id, the bed load passed to each particle in the last pass that drew: the loads of the
/// particles that named it (`fluxes`, by id), summed in the sorted order of `ids`, as a walk
/// over its neighbours ([`Exchange::add`]) sums them.
fn passed(fluxes: &[(f32, u32)], ids: &[u32]) -> Vec<f32> {
    let mut passed = vec![0.0f32; fluxes.len()];
    for &id in ids {
        let Some(&(flux, target)) = fluxes.get(id as usize) else {
            continue;
        };
        if flux < 0.0 || target == id {
            continue;
        }
        if let Some(p) = passed.get_mut(target as usize) {
            *p += flux;
        }
    }
    passed
}

/// What a particle that exchanges no bed load is passed, and where its own goes.
const NONE_PASSED: (f32, u32) = (0.0, NO_TARGET);

/// Particles per block handed to a thread, as in the force pass.
const BLOCK: usize = 64;

/// What the rheology's neighbour loop reads.
struct Pairs<'a> {
    params: &'a Params,
    pass: &'a Rheology<'a>,
    grid: &'a Grid,
    pos: &'a [[f32; 4]],
    vel: &'a [[f32; 4]],
    vol: &'a [f32],
    sides: &'a [RheologySide],
    ids: &'a [u32],
    /// The last pass's bed load and where it went (`Holds::fluxes`), in sorted order.
    fluxes: &'a [(f32, u32)],
    /// Under `van_rijn_exner`, the bed load passed to each particle in the last pass, by id
    /// ([`passed`]); empty otherwise.
    passed: &'a [f32],
    /// The region words of the last pass.
    words: &'a [u32],
    /// The grains that may sleep in this pass.
    asleep: &'a [bool],
    /// Under `van_rijn_exner`, [`Holds::bed_tops`]: a sleeper at the bed's top offers to take
    /// load.
    bed_tops: Option<&'a [u8]>,
    /// Where held grains under the water may sleep: the rule, whether each particle's walk
    /// leaves a record, and the records of the last walks by id ([`deep`]).
    deep: Option<&'a Deep>,
    recordable: &'a [bool],
    records: &'a [f32],
}

impl Pairs<'_> {
    /// The rheology of the particles from `first` into `out`, in groups of one row of cells
    /// as the force pass takes them, the particles it spares left out of them
    /// ([`Grid::groups`]); each lane sums its own neighbours in sorted order.
    /// Returns how many were spared the walk over their neighbours. With [`deep`]'s rule each
    /// particle's record goes to `records`: a sleeper keeps its own.
    #[inline(always)]
    fn block(&self, first: usize, out: &mut [ParticleRheology], records: &mut [f32]) -> usize {
        let mut asleep = 0;
        let pos = self.pos;
        let end = first + out.len();
        // A sleeper's sums give it what its start does, and a wall's rheology is none
        // whatever its neighbours.
        let spared = |i: usize| self.asleep[i] || !self.params.phases[phase_index(&pos[i])].mobile;
        self.grid.groups(
            (first, end),
            |k| self.sides[k].x,
            |k| !spared(k),
            #[inline(always)]
            |stretch, group| {
                for i in stretch.filter(|&i| spared(i)) {
                    asleep += 1;
                    (out[i - first], records[i - first]) = self.unwalked(i);
                }
                if let Some(group) = group {
                    self.walk(group, first, out, records);
                }
            },
        );
        asleep
    }

    /// The rheology of particle `i`, spared the walk, from its own start, and the record it
    /// keeps.
    #[inline(always)]
    fn unwalked(&self, i: usize) -> (ParticleRheology, f32) {
        let (x, v, id) = (&self.pos[i], &self.vel[i], self.ids[i]);
        let s = self.pass.start(x, v);
        let mut r = self.pass.finish(x, v, &s, (self.words[i], id), NONE_PASSED);
        // At rest under no water a grain at the top passes on nothing, and offers to take
        // what a wet front brings.
        let top = |t: &[u8]| t[id as usize] == BED_TOP;
        if self.asleep[i] && self.bed_tops.is_some_and(top) {
            r.flux = 0.0;
        }
        let record = self.records.get(id as usize).copied();
        (r, record.unwrap_or(NO_RECORD))
    }

    /// The rheology of the particles `group` takes into `out` (and their records), from
    /// their sums over their neighbours; `first` is the sorted index of `out`'s first slot.
    #[inline(always)]
    fn walk(&self, group: &Group, first: usize, out: &mut [ParticleRheology], records: &mut [f32]) {
        let sums = self.group(group);
        for (lane, &i) in group.taken().iter().enumerate() {
            let s = sums.lane(lane);
            if let Some(d) = self.deep.filter(|_| self.recordable[i]) {
                records[i - first] = d.record(s.kernel_mass());
            }
            let exchange = self.exchange(i, &s);
            let before = (self.words[i], self.ids[i]);
            out[i - first] = self
                .pass
                .finish(&self.pos[i], &self.vel[i], &s, before, exchange);
        }
    }

    /// The bed load passed to particle `i` in the last pass ([`passed`]) and the particle it
    /// passes its own to, from its sums `s` (none without deposition): the one it names lies
    /// within dp of the point dp down the flow, so only the cells around that point are
    /// weighed.
    fn exchange(&self, i: usize, s: &RheologySums) -> (f32, u32) {
        let x = &self.pos[i];
        let id = self.ids[i];
        let Some(mut ex) = self.pass.exchange_of((x, id), s, self.words[i]) else {
            return NONE_PASSED;
        };
        let passed = self.passed.get(id as usize).copied().unwrap_or(0.0);
        if ex.names() {
            // A box a little wider than the disc: no rounding leaves a point of it out.
            let (at, radius) = ex.reach();
            let (lo, hi) = (at.map(|a| a - 1.01 * radius), at.map(|a| a + 1.01 * radius));
            self.grid.rows_in_box(&lo, &hi, |range| {
                for j in range {
                    ex.weigh(&self.pos[j], self.ids[j], self.fluxes[j].0);
                }
            });
        }
        (passed, ex.outcome().1)
    }

    /// The sums of the particles `group` takes, from each one's own start.
    #[inline(always)]
    fn group(&self, group: &Group) -> RheologySums<Lanes> {
        let (pass, pos, vel) = (self.pass, self.pos, self.vel);
        let m = group.members;
        let starts: [RheologySums; LANES] =
            std::array::from_fn(|k| pass.start(&pos[m[k]], &vel[m[k]]));
        let mut sums = RheologySums::lanes(&starts);
        let sides: [RheologySide; LANES] = std::array::from_fn(|k| self.sides[m[k]]);
        let side = RheologySide::lanes(&sides);
        self.grid.group_cells(
            group,
            #[inline(always)]
            |range, near| {
                for j in range {
                    pass.add_pair_of_volume(
                        &side,
                        (&pos[j], &vel[j]),
                        self.vol[j],
                        near,
                        &mut sums,
                    );
                }
            },
        );
        sums
    }
}

#[cfg(test)]
mod tests;
