use super::*;
use crate::cpu::fixture::{Fixture, SAND, fixture};
use crate::physics::Viscosity;

fn two_threads() -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool of two threads")
}

/// Each particle's region word, viscosity and stress, as bits.
fn bits(r: &[ParticleRheology]) -> Vec<(u32, u32, Vec<u32>)> {
    r.iter()
        .map(|p| {
            let stress = p.stress.iter().flatten().map(|s| s.to_bits());
            (p.word(), p.mu.to_bits(), stress.collect())
        })
        .collect()
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
            records: &[],
            dry_before: &[],
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
    for awake_set in [false, true] {
        assert!(bits(&pass_with(awake_set)) == bits(&want));
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
            records: &[],
            dry_before: &[],
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

/// The fixture with every wall and held grain at rest at its rest density: only its water
/// stirs.
fn bed_at_rest() -> Fixture {
    use crate::cpu::fixture::WATER;
    let mut fx = fixture(Viscosity::Multiphase {
        alpha: 0.05,
        sps_length2: 0.0,
    });
    for (x, v) in fx.pos.iter().zip(fx.vel.iter_mut()) {
        let phase = x[3].to_bits();
        if phase != WATER {
            *v = [0.0, 0.0, 0.0, fx.params.phases[phase as usize].rho0];
        }
    }
    fx
}

/// Under Exner's balance a dry grain sleeps by the bed-top flag of its last walk only where
/// that walk was taken dry: one that weighed water gone since walks once more. On the
/// fixture's bed at rest (its ends open faces) the water is in reach of the upper rows, then
/// parked (out of the flow, as an open flume's reservoir): the grains of the bed's ends lay at
/// its surface beside the water, and dry they no longer lie at its top. Two passes without the
/// water must then give what the full computation gives.
#[test]
fn under_exner_a_grain_the_water_left_walks_once_dry() {
    use crate::cpu::fixture::WATER;
    let wet = bed_at_rest();
    let model = wet.sediment.clone().worn_by_van_rijn(true);
    let n = wet.pos.len();
    let held = |x: &[f32; 4]| u32::from(x[3].to_bits() == SAND) * REGION_HELD;
    let fluxes = vec![(NO_FLUX, NO_TARGET); n];
    let pool = two_threads();
    let pass = |fx: &Fixture, ids: &[u32], awake_set: bool, known: (&[u8], &[bool])| {
        let active = fx.grid.active() as usize;
        let words: Vec<u32> = fx.pos[..active].iter().map(held).collect();
        let holds = Holds {
            words: &words,
            ids: &ids[..active],
            fluxes: &fluxes,
            draws: None,
            awake_set,
            bed_tops: known.0,
            records: &[],
            dry_before: known.1,
        };
        let (pos, vel) = (&fx.pos, &fx.vel);
        rheology_pass(&pool, &fx.params, &model, &fx.grid, pos, vel, &holds, false)
    };
    // What a pass leaves by id, as `ById::keep` keeps it.
    let keep = |r: &RheologyPass, ids: &[u32]| {
        let (mut tops, mut dry) = (vec![BED_UNKNOWN; n], vec![false; n]);
        for (k, out) in r.out.iter().enumerate() {
            (tops[ids[k] as usize], dry[ids[k] as usize]) = (bed_top_of(out), r.dry[k]);
        }
        (tops, dry)
    };
    let wet_ids: Vec<u32> = (0..n as u32).collect();
    let first = pass(&wet, &wet_ids, true, (&vec![BED_UNKNOWN; n], &[]));
    let (tops, dry) = keep(&first, &wet_ids);
    // The water parked: the same bed, sorted again without it.
    let mut gone = bed_at_rest();
    let ids = gone.grid.sort(&gone.pos, &wet_ids, Some(WATER), n);
    gone.pos = crate::cpu::grid::gather(&gone.pos, &ids);
    gone.vel = crate::cpu::grid::gather(&gone.vel, &ids);
    let outcome = |r: &RheologyPass| -> Vec<(u32, u32, u32)> {
        let out = r.out.iter();
        out.map(|p| (p.word(), p.flux.to_bits(), p.target))
            .collect()
    };
    let full = pass(&gone, &ids, false, (&tops, &dry));
    let second = pass(&gone, &ids, true, (&tops, &dry));
    assert!(outcome(&second) == outcome(&full), "the first pass dry");
    let (tops_after, dry_after) = keep(&second, &ids);
    let third = pass(&gone, &ids, true, (&tops_after, &dry_after));
    assert!(outcome(&third) == outcome(&full), "the second pass dry");
    // Not vacuous: some grain's flag changed with the water gone, and once walked dry the
    // grains slept.
    let full_tops = full.out.iter().map(bed_top_of);
    let moved = full_tops
        .zip(&ids)
        .filter(|&(t, &id)| tops[id as usize] != t);
    assert!(moved.count() > 0, "no grain's bed-top flag changed");
    let slept = (second.asleep, third.asleep);
    assert!(slept.1 > slept.0, "{slept:?}");
}

/// Under the water, held grains deep in the bed sleep by the record their last walk left
/// (`deep`) and still get, to the bit, what they get alone; where the held sand's densities
/// rise past what the records bound, they walk again. On the fixture's bed (four rows of sand
/// on a wall row, water above), the grains of the second row up fill the cells of one row
/// and lie three dp under the water, within its reach.
#[test]
fn held_grains_deep_under_the_water_sleep_by_their_last_walk() {
    let mut fx = fixture(Viscosity::Multiphase {
        alpha: 0.05,
        sps_length2: 0.0,
    });
    fx.params.generalised_walls = true;
    let model = SedimentModel {
        shields_only: true,
        ..fx.sediment.clone().worn_by_van_rijn(false)
    };
    let n = fx.pos.len();
    let sand = |i: usize| fx.pos[i][3].to_bits() == SAND;
    // The held grains at rest, as the store leaves them.
    for i in (0..n).filter(|&i| sand(i)) {
        fx.vel[i] = [0.0, 0.0, 0.0, fx.vel[i][3]];
    }
    let words: Vec<u32> = (0..n)
        .map(|i| if sand(i) { REGION_HELD } else { 0 })
        .collect();
    let ids: Vec<u32> = (0..n as u32).collect();
    let fluxes = vec![(NO_FLUX, NO_TARGET); n];
    let pool = two_threads();
    let run = |fx: &Fixture, records: &[f32]| {
        let holds = Holds {
            words: &words,
            ids: &ids,
            fluxes: &fluxes,
            draws: None,
            awake_set: true,
            bed_tops: &[],
            records,
            dry_before: &[],
        };
        let (pos, vel) = (&fx.pos, &fx.vel);
        rheology_pass(&pool, &fx.params, &model, &fx.grid, pos, vel, &holds, false)
    };
    let alone = |fx: &Fixture| -> Vec<ParticleRheology> {
        let pass = Rheology::new(&fx.params, &model);
        (0..n)
            .map(|i| {
                let s = own_sums(fx, &pass, i);
                let (x, v) = (&fx.pos[i], &fx.vel[i]);
                pass.finish(x, v, &s, (words[i], ids[i]), NONE_PASSED)
            })
            .collect()
    };
    let first = run(&fx, &vec![f32::NAN; n]);
    let second = run(&fx, &first.records);
    let want = bits(&alone(&fx));
    assert!(bits(&first.out) == want && bits(&second.out) == want);
    // Not vacuous: grains with water in reach slept on their records.
    assert!(
        second.asleep > first.asleep,
        "{} {}",
        first.asleep,
        second.asleep
    );
    // Held sand 50 % denser than at the walk that left the records: none of them bounds a
    // kernel mass now (at 20 % the deepest grains' records still do, and they sleep).
    for i in (0..n).filter(|&i| sand(i)) {
        fx.vel[i][3] *= 1.5;
    }
    let denser = run(&fx, &first.records);
    assert_eq!(denser.asleep, first.asleep);
    assert!(bits(&denser.out) == bits(&alone(&fx)));
}

/// The loads named to a grain are summed in sorted order, as its walk over its neighbours
/// adds them: in f32, 4 + 4 + 1e8 is 1e8 + 8, where 1e8 + 4 + 4 rounds to 1e8. Loads of
/// particles not at the bed's top, named to none or past the ids are passed to no one, nor
/// is that of a particle out of the flow (id 3, not among the sorted ids).
#[test]
fn the_loads_named_to_a_grain_are_summed_in_sorted_order() {
    let mut fluxes = [(NO_FLUX, NO_TARGET); 11];
    // Sorted order is not id order: summed by id, the 1e8 of id 0 would come first.
    let ids = [9, 1, 4, 5, 8, 0, 6, 10];
    let named = [
        (4.0, 2),
        (0.5, 3),
        (4.0, 2),
        (7.0, NO_TARGET),
        (NO_FLUX, 3),
        (1e8, 2),
        (9.0, 60),
        (2.0, 7),
    ];
    for (&id, &f) in ids.iter().zip(&named) {
        fluxes[id as usize] = f;
    }
    fluxes[3] = (5.0, 2);
    let by_id = passed(&fluxes, &ids);
    let in_order = 4.0_f32 + 4.0 + 1e8;
    let mut want = vec![0.0; 11];
    (want[2], want[3], want[7]) = (in_order, 0.5, 2.0);
    assert_eq!(by_id, want);
    assert_ne!(in_order, 1e8_f32 + 4.0 + 4.0, "the order must matter");
}
