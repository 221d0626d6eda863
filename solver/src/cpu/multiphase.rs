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
//! not moved since, for a neighbour that moves is one that stirs. A grain whose last walk is
//! not known (none yet, or its word set from outside) does not sleep.

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
use rayon::prelude::*;

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
    /// Whether held grains far from anything moving sleep (see the module doc); false: every
    /// grain runs its sums (the full computation the awake set is checked against).
    pub awake_set: bool,
    /// Under `van_rijn_exner`, whether each particle lay at the bed's top when it last walked
    /// its neighbours, by id ([`BED_TOP`], [`BED_BELOW`], or [`BED_UNKNOWN`]); empty otherwise.
    pub bed_tops: &'a [u8],
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
    let held_before = |i: usize| holds.words[i] & REGION_HELD != 0;
    let pass = Rheology::new(params, model).with_draws(holds.draws);
    let n = holds.words.len();
    let exner = model.exner();
    let stirrers = holds
        .awake_set
        .then(|| stirring(params, (pos, vel), holds.words));
    let named = exner.then(|| named(holds.fluxes));
    // Under Exner's balance a grain sleeps only where its last walk is known and no load was
    // named to it (see the module doc).
    let may_sleep = |i: usize| {
        let id = holds.ids[i] as usize;
        !exner || (holds.bed_tops[id] != BED_UNKNOWN && named.as_ref().is_some_and(|n| !n[id]))
    };
    // One parallel region, not two: a region costs a step more than its work at CI size
    // (README, speed).
    let (vol, (sides, asleep)): (Vec<f32>, (Vec<RheologySide>, Vec<bool>)) = pool.install(|| {
        (0..n)
            .into_par_iter()
            .map(|i| {
                let side = pass.side(&pos[i], &vel[i]);
                let sleeps = held_before(i)
                    && stirrers
                        .as_ref()
                        .is_some_and(|s| !grid.any_near(s, &side.x))
                    && may_sleep(i);
                (pass.volume(&pos[i], &vel[i]), (side, sleeps))
            })
            .unzip()
    });
    let pairs = Pairs {
        params,
        pass: &pass,
        grid,
        pos,
        vel,
        vol: &vol,
        sides: &sides,
        ids: holds.ids,
        fluxes: holds.fluxes,
        words: holds.words,
        asleep: &asleep,
        bed_tops: exner.then_some(holds.bed_tops),
        named: named.as_deref(),
    };
    // Every slot is written by its block.
    let none = ParticleRheology {
        stress: [[0.0; 3]; 3],
        mu: 0.0,
        region: 0,
        held: false,
        pickup: 0,
        flux: NO_FLUX,
        target: NO_TARGET,
    };
    let mut out = vec![none; n];
    let asleep = pool.install(|| {
        out.par_chunks_mut(BLOCK)
            .enumerate()
            .map(|(b, out)| {
                simd::dispatch(
                    #[inline(always)]
                    || pairs.block(b * BLOCK, out),
                )
            })
            .sum()
    });
    if release {
        release_held(pool, (params, model), grid, (pos, vel), &mut out);
    }
    RheologyPass { out, asleep }
}

/// Releases the held sediment whose neighbours transmit enough stress (`hold.wgsl`), from the
/// regions `out` the rheology pass left, before any release.
fn release_held(
    pool: &rayon::ThreadPool,
    (params, model): (&Params, &SedimentModel),
    grid: &Grid,
    (pos, vel): (&[[f32; 4]], &[[f32; 4]]),
    out: &mut [ParticleRheology],
) {
    let stage = Release::new(params, model);
    let released: Vec<bool> = pool.install(|| {
        (0..out.len())
            .into_par_iter()
            .map(|i| {
                if !stage.applies(&pos[i], &out[i]) {
                    return false;
                }
                let mut sums = Transmitted::default();
                grid.rows(grid.coords(&[pos[i][0], pos[i][1], pos[i][2]]), |range| {
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
/// rest. A held grain with none of them in the cells within reach sleeps (see the module doc).
fn stirring(params: &Params, (pos, vel): (&[[f32; 4]], &[[f32; 4]]), words: &[u32]) -> Flagged {
    let rests = |k: usize| {
        let still = vel[k][..3].iter().all(|&v| v == 0.0);
        let held = words[k] & REGION_HELD != 0;
        still && (held || !params.phases[phase_index(&pos[k])].mobile)
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
    /// The last pass's bed load and where it went, by id (`Holds::fluxes`).
    fluxes: &'a [(f32, u32)],
    /// The region words of the last pass.
    words: &'a [u32],
    /// The grains that may sleep in this pass.
    asleep: &'a [bool],
    /// Under `van_rijn_exner`, [`Holds::bed_tops`]: a sleeper at the bed's top offers to take
    /// load.
    bed_tops: Option<&'a [u8]>,
    /// Under `van_rijn_exner`, whether the last pass that drew named each particle, by id.
    named: Option<&'a [bool]>,
}

impl Pairs<'_> {
    /// The rheology of the particles from `first` into `out`, in groups of one row of cells
    /// as the force pass takes them: each lane sums its own neighbours in sorted order.
    /// Returns how many were spared the walk over their neighbours.
    #[inline(always)]
    fn block(&self, first: usize, out: &mut [ParticleRheology]) -> usize {
        let mut asleep = 0;
        let (pass, grid, pos, vel) = (self.pass, self.grid, self.pos, self.vel);
        let end = first + out.len();
        let mut start = first;
        while start < end {
            let group = grid.group(start, end, |k| self.sides[k].x);
            // A group with an awake grain or a moving particle is walked whole: a sleeper's
            // sums give it what its start does, and a wall's rheology is none whatever its
            // neighbours.
            let spared =
                |i: usize| self.asleep[i] || !self.params.phases[phase_index(&pos[i])].mobile;
            if group.range.clone().all(spared) {
                asleep += group.range.len();
                for i in group.range.clone() {
                    let s = pass.start(&pos[i], &vel[i]);
                    let before = (self.words[i], self.ids[i]);
                    let r = &mut out[i - first];
                    *r = pass.finish(&pos[i], &vel[i], &s, before, NONE_PASSED);
                    // At rest under no water a grain at the top passes on nothing, and
                    // offers to take what a wet front brings.
                    let top = |t: &[u8]| t[self.ids[i] as usize] == BED_TOP;
                    if self.asleep[i] && self.bed_tops.is_some_and(top) {
                        r.flux = 0.0;
                    }
                }
            } else {
                let sums = self.group(&group);
                for (lane, i) in group.range.clone().enumerate() {
                    let s = sums.lane(lane);
                    let exchange = self.exchange(i, &s);
                    let before = (self.words[i], self.ids[i]);
                    out[i - first] = pass.finish(&pos[i], &vel[i], &s, before, exchange);
                }
            }
            start = group.range.end;
        }
        asleep
    }

    /// The bed load passed to particle `i` in the last pass and the particle it passes its own
    /// to, from its sums `s` (none without deposition): the cells within reach hold both, since
    /// each lies within 2 dp of `i`.
    fn exchange(&self, i: usize, s: &RheologySums) -> (f32, u32) {
        let x = &self.pos[i];
        let id = self.ids[i];
        let Some(mut ex) = self.pass.exchange_of((x, id), s, self.words[i]) else {
            return NONE_PASSED;
        };
        // Most of the bed neither names nor was named: nothing to weigh.
        if !ex.names() && !self.named.is_none_or(|n| n[id as usize]) {
            return NONE_PASSED;
        }
        self.grid
            .rows(self.grid.coords(&[x[0], x[1], x[2]]), |range| {
                for j in range {
                    let id_j = self.ids[j];
                    ex.add(&self.pos[j], id_j, self.fluxes[id_j as usize]);
                }
            });
        ex.outcome()
    }

    /// The sums of `group`, from each particle's own start.
    #[inline(always)]
    fn group(&self, group: &Group) -> RheologySums<Lanes> {
        let (pass, grid, pos, vel) = (self.pass, self.grid, self.pos, self.vel);
        let range = group.range.clone();
        let starts: [RheologySums; LANES] = std::array::from_fn(|k| {
            let i = (range.start + k).min(range.end - 1);
            pass.start(&pos[i], &vel[i])
        });
        let mut sums = RheologySums::lanes(&starts);
        let side = RheologySide::lanes(&self.sides[range]);
        grid.group_cells(
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
mod tests {
    use super::*;
    use crate::cpu::fixture::{Fixture, SAND, fixture};
    use crate::physics::Viscosity;

    fn two_threads() -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool of two threads")
    }

    /// Particle `i`'s sums as it walks its neighbours alone over `Grid::rows`, each pair by
    /// the f32 formulas.
    fn own_sums(fx: &Fixture, pass: &Rheology, i: usize) -> RheologySums {
        let (x, v) = (&fx.pos[i], &fx.vel[i]);
        let mut s = pass.start(x, v);
        if fx.params.phases[phase_index(x)].mobile {
            let side = pass.side(x, v);
            fx.grid.rows(fx.grid.coords(&side.x), |range| {
                for j in range {
                    let vol = pass.volume(&fx.pos[j], &fx.vel[j]);
                    let j = (&fx.pos[j], &fx.vel[j]);
                    pass.add_pair_of_volume(&side, j, vol, true, &mut s);
                }
            });
        }
        s
    }

    #[test]
    fn each_lane_gets_the_rheology_of_its_particle_alone() {
        let fx = fixture(Viscosity::Multiphase {
            alpha: 0.05,
            sps_length2: 0.0,
        });
        let pool = two_threads();
        let n = fx.pos.len();
        let held: Vec<u32> = (0..n)
            .map(|i| if i % 3 == 0 { REGION_HELD } else { 0 })
            .collect();
        let ids: Vec<u32> = (0..n as u32).collect();
        let fluxes = vec![(NO_FLUX, NO_TARGET); n];
        let (params, grid) = (&fx.params, &fx.grid);
        let pass_with = |awake_set| {
            let holds = Holds {
                words: &held,
                ids: &ids,
                fluxes: &fluxes,
                draws: None,
                awake_set,
                bed_tops: &[],
            };
            let (pos, vel) = (&fx.pos, &fx.vel);
            rheology_pass(&pool, params, &fx.sediment, grid, pos, vel, &holds, false).out
        };
        let pass = Rheology::new(params, &fx.sediment);
        let want: Vec<ParticleRheology> = (0..n)
            .map(|i| {
                let s = own_sums(&fx, &pass, i);
                let (x, v) = (&fx.pos[i], &fx.vel[i]);
                pass.finish(x, v, &s, (held[i], ids[i]), NONE_PASSED)
            })
            .collect();
        let word_bits = |r: &[ParticleRheology]| -> Vec<(u32, u32, Vec<u32>)> {
            r.iter()
                .map(|p| {
                    let stress = p.stress.iter().flatten().map(|s| s.to_bits());
                    (p.word(), p.mu.to_bits(), stress.collect())
                })
                .collect()
        };
        for awake_set in [false, true] {
            assert!(word_bits(&pass_with(awake_set)) == word_bits(&want));
        }
        // Not a vacuous comparison: the bed's top layer sees the water and yields or moves.
        let sand = (0..n).filter(|&i| fx.pos[i][3].to_bits() == SAND);
        let regions: std::collections::BTreeSet<u32> = sand.map(|i| want[i].region).collect();
        assert!(regions.len() > 1, "{regions:?}");
    }

    /// Under `van_rijn_exner`, in a pass that draws, every sediment particle takes the load
    /// the last pass named to it, whether or not it names one itself: on the fixture's held
    /// bed, each grain of the bottom row (under no water, so it names none) is named by the
    /// grain above it, and the top row names targets of its own under the moving water. The
    /// lanes' pass, with the awake set and without, gives each particle's word, flux and target
    /// as it walks its neighbours alone, its exchange over the same cells.
    #[test]
    fn under_exner_a_grain_that_names_none_still_takes_what_was_named_to_it() {
        use crate::physics::sediment::pickup::word_units;
        let fx = fixture(Viscosity::Multiphase {
            alpha: 0.05,
            sps_length2: 0.0,
        });
        let model = fx.sediment.clone().worn_by_van_rijn(true);
        let pool = two_threads();
        let n = fx.pos.len();
        let sand = |i: usize| fx.pos[i][3].to_bits() == SAND;
        let words: Vec<u32> = (0..n)
            .map(|i| if sand(i) { REGION_HELD } else { 0 })
            .collect();
        let ids: Vec<u32> = (0..n as u32).collect();
        // The bottom row lies within 0.2 dp of y = 1.5 dp, the row above within 0.2 dp of 2.5.
        let row = |i: usize, y: f32| sand(i) && (fx.pos[i][1] - y).abs() < 0.0025;
        let mut fluxes = vec![(NO_FLUX, NO_TARGET); n];
        let mut named = Vec::new();
        for d in (0..n).filter(|&d| row(d, 0.015)) {
            let above = (0..n)
                .filter(|&k| row(k, 0.025) && fluxes[k].1 == NO_TARGET)
                .min_by(|&a, &b| {
                    let dx = |k: usize| (fx.pos[k][0] - fx.pos[d][0]).abs();
                    dx(a).total_cmp(&dx(b))
                })
                .expect("a grain above");
            fluxes[above] = (0.5, d as u32);
            named.push(d);
        }
        let draws = Some(Draws {
            step: 3,
            dt_s: 1.0e-4,
        });
        let (params, grid) = (&fx.params, &fx.grid);
        let pass = Rheology::new(params, &model).with_draws(draws);
        let want: Vec<ParticleRheology> = (0..n)
            .map(|i| {
                let s = own_sums(&fx, &pass, i);
                let (x, v) = (&fx.pos[i], &fx.vel[i]);
                let exchange =
                    pass.exchange_of((x, ids[i]), &s, words[i])
                        .map_or(NONE_PASSED, |mut ex| {
                            grid.rows(grid.coords(&[x[0], x[1], x[2]]), |range| {
                                for j in range {
                                    ex.add(&fx.pos[j], ids[j], fluxes[j]);
                                }
                            });
                            ex.outcome()
                        });
                pass.finish(x, v, &s, (words[i], ids[i]), exchange)
            })
            .collect();
        let bed_tops = vec![BED_UNKNOWN; n];
        let outcome = |r: &[ParticleRheology]| -> Vec<(u32, u32, u32)> {
            r.iter()
                .map(|p| (p.word(), p.flux.to_bits(), p.target))
                .collect()
        };
        for awake_set in [false, true] {
            let holds = Holds {
                words: &words,
                ids: &ids,
                fluxes: &fluxes,
                draws,
                awake_set,
                bed_tops: &bed_tops,
            };
            let (pos, vel) = (&fx.pos, &fx.vel);
            let got = rheology_pass(&pool, params, &model, grid, pos, vel, &holds, false).out;
            assert!(outcome(&got) == outcome(&want), "awake set {awake_set}");
        }
        // Not vacuous: the load settled on every named grain of the bottom row, and the top
        // row named targets of its own.
        for &d in &named {
            assert!(
                word_units(want[d].word(), true) < 0,
                "grain {d}: {:?}",
                want[d]
            );
        }
        assert!(
            want.iter().any(|r| r.target != NO_TARGET),
            "none named a target"
        );
    }
}
