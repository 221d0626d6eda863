//! The force pass of the CPU backend: each particle sums its neighbours' pair terms
//! (`PairModel::add_pair`, the one statement of the formulas) over the contiguous rows of the
//! cell list, particles shared out among threads in blocks. A block is taken in groups of up
//! to [`LANES`] particles of one row of cells, each neighbour against the whole group at once
//! (`physics::lanes`), a group packed with the particles that walk alone (`Grid::groups`);
//! every lane sums its own neighbours in sorted order, as one particle alone would, so the
//! result does not depend on the grouping or on the number of threads.
//!
//! The awake set: a wall (or held sand standing as one) takes no acceleration, so its only
//! output is its density. Under the generalised condition that comes from its wall sums over
//! the fluid (`physics::boundary`), taken for a group's walls in lanes as the pair sums are
//! (one test of a wall neighbour spares all eight lanes), and its pair sums are not computed.
//! Under DBC its rate sums the mobile particles alone (`PairModel::add_pair`), each pair by the
//! velocity difference: with none in the cells within reach but walls and held sand at rest
//! ([`wakes`]) it is exactly zero, and the wall is not visited. A dry wall under
//! the generalised condition takes rest density without a neighbour loop. Each of these is
//! the value the full sums give, to the bit (`tests/awake_set.rs`); nothing a mobile particle
//! reads is skipped, since every mobile particle runs its own sums.

use super::grid::{Flagged, Grid, Group};
use super::simd;
use crate::physics::boundary::WallSums;
use crate::physics::interaction::{PairModel, PairSum, Side};
use crate::physics::lanes::{LANES, Lanes, Real};
use crate::physics::sediment::stress::{StressDivergence, StressSide};
use crate::physics::timestep::particle_viscous_bound;
use rayon::prelude::*;

/// Particles per block handed to a thread: small enough to balance a flume whose sand costs
/// more than its water (on the CI flume, two threads: blocks of 512 took 3.3 s, of 128 and of
/// 64 2.5 s, the thread that finished first no longer falling asleep before the other).
const BLOCK: usize = 64;

/// What the force pass reads besides the particles' sides.
pub struct Extra<'a> {
    /// The multiphase model's stress divergence, with the stress side and apparent viscosity
    /// of each particle (its explicit viscous bound joins the step).
    pub stress: Option<(&'a StressDivergence<'a>, &'a [StressSide], &'a [f32])>,
    /// Particles whose velocity is imposed (an open flume's inlet buffer and duct): their
    /// acceleration does not bound the step. Empty: none.
    pub imposed: &'a [bool],
    /// The particles whose presence within reach wakes a wall ([`wakes`]); None: every wall
    /// runs its full sums (the full computation the awake set is checked against).
    pub waking: Option<&'a Flagged>,
}

/// What one block of the pass reads.
struct Pass<'a> {
    model: &'a PairModel<'a>,
    grid: &'a Grid,
    sides: &'a [Side],
    extra: &'a Extra<'a>,
}

/// Lane-pairs a force pass evaluates and those of them that add to a sum read: how full the
/// lanes are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaneUse {
    pub evaluated: u64,
    pub useful: u64,
}

/// The [`LaneUse`] of the force pass over `sides` (as [`force_pass`] takes them), without
/// computing it.
pub fn lane_use(
    pool: &rayon::ThreadPool,
    model: &PairModel,
    grid: &Grid,
    sides: &[Side],
    extra: &Extra,
) -> LaneUse {
    let pass = Pass {
        model,
        grid,
        sides,
        extra,
    };
    let blocks = sides.len().div_ceil(BLOCK);
    pool.install(|| {
        (0..blocks)
            .into_par_iter()
            .map(|b| pass.census(b * BLOCK, ((b + 1) * BLOCK).min(sides.len())))
            .reduce(LaneUse::default, |a, b| LaneUse {
                evaluated: a.evaluated + b.evaluated,
                useful: a.useful + b.useful,
            })
    })
}

/// Fills `forces` (`[ax, ay, az, d rho/dt]`) and `dt_limit` (the stable step before the CFL
/// factor) of each particle of `sides`, in sorted order; cells come from `grid`, whose
/// starts were sorted from the same particles or from the state half a step before. Returns
/// how many walls were spared the walk over their neighbours (see the module doc).
pub fn force_pass(
    pool: &rayon::ThreadPool,
    model: &PairModel,
    grid: &Grid,
    sides: &[Side],
    extra: &Extra,
    forces: &mut [[f32; 4]],
    dt_limit: &mut [f32],
) -> usize {
    let pass = Pass {
        model,
        grid,
        sides,
        extra,
    };
    pool.install(|| {
        forces
            .par_chunks_mut(BLOCK)
            .zip(dt_limit.par_chunks_mut(BLOCK))
            .enumerate()
            .map(|(block, (forces, dt_limit))| {
                simd::dispatch(
                    #[inline(always)]
                    || pass.block(block * BLOCK, forces, dt_limit),
                )
            })
            .sum()
    })
}

impl Pass<'_> {
    /// The particles from sorted index `first`, [`BLOCK`] at a time ([`Pass::chunk`]);
    /// returns how many walls were spared the walk over their neighbours.
    #[inline(always)]
    fn block(&self, first: usize, forces: &mut [[f32; 4]], dt_limit: &mut [f32]) -> usize {
        let chunks = forces.chunks_mut(BLOCK).zip(dt_limit.chunks_mut(BLOCK));
        let mut asleep = 0;
        for (k, (forces, dt_limit)) in chunks.enumerate() {
            asleep += self.chunk(first + k * BLOCK, forces, dt_limit);
        }
        asleep
    }

    /// The particles of at most [`BLOCK`] from sorted index `first`: the pair sums of those
    /// that walk their neighbours, in groups of one row of cells packed with them alone
    /// ([`Grid::groups`]), then the wall sums of the wet walls packed the same way, then each
    /// particle's forces; returns how many walls were spared the walk over their neighbours.
    #[inline(always)]
    fn chunk(&self, first: usize, forces: &mut [[f32; 4]], dt_limit: &mut [f32]) -> usize {
        let end = first + forces.len();
        let mut wet = [true; BLOCK];
        let mut spared = [false; BLOCK];
        for i in first..end {
            (wet[i - first], spared[i - first]) = self.wall_of(i);
        }
        let mut sums = [PairSum::default(); BLOCK];
        self.groups(
            (first, end),
            |k| !spared[k - first],
            #[inline(always)]
            |group| {
                let (sum, tau) = self.group(group);
                for (lane, &i) in group.taken().iter().enumerate() {
                    let s = &mut sums[i - first];
                    *s = sum.lane(lane);
                    for (a, t) in s.acc.iter_mut().zip(&tau) {
                        *a += t.0[lane];
                    }
                }
            },
        );
        let mut walls = [None; BLOCK];
        if self.model.params().generalised_walls {
            self.groups(
                (first, end),
                |k| wet[k - first] && !self.sides[k].mobile,
                #[inline(always)]
                |group| {
                    let sums = self.wall_sums(group);
                    for (lane, &i) in group.taken().iter().enumerate() {
                        walls[i - first] = Some(sums.lane(lane));
                    }
                },
            );
        }
        for i in first..end {
            let k = i - first;
            (forces[k], dt_limit[k]) = self.finish(i, &sums[k], walls[k].as_ref());
        }
        spared[..end - first].iter().filter(|s| **s).count()
    }

    /// Calls `walk` with each group of the particles from `first` to `end` that `take`
    /// accepts, in sorted order.
    #[inline(always)]
    fn groups(
        &self,
        (first, end): (usize, usize),
        take: impl Fn(usize) -> bool,
        mut walk: impl FnMut(&Group),
    ) {
        let x = |k: usize| self.sides[k].x;
        self.grid.groups(
            (first, end),
            x,
            take,
            #[inline(always)]
            |_, group| {
                if let Some(group) = group {
                    walk(group);
                }
            },
        );
    }

    /// The lane-pairs the walks of the particles from `first` to `end` evaluate, and those
    /// within the kernel's support for a lane whose sums are read and a pair that adds
    /// something (not two walls): what [`Pass::block`]'s pair sums walk, counted.
    fn census(&self, first: usize, end: usize) -> LaneUse {
        let support2 = (2.0 * self.model.params().h).powi(2);
        let mut count = LaneUse::default();
        let walks = |k: usize| !self.wall_of(k).1;
        self.groups((first, end), walks, |group| {
            self.grid.group_cells(group, |cands, _| {
                count.evaluated += (cands.len() * LANES) as u64;
                for j in cands {
                    let (b, x_j) = (&self.sides[j], self.sides[j].x);
                    for &i in group.taken() {
                        let a = &self.sides[i];
                        let r2: f32 = (0..3).map(|k| (a.x[k] - x_j[k]).powi(2)).sum();
                        let adds = a.mobile || b.mobile;
                        count.useful += u64::from(adds && i != j && r2 < support2);
                    }
                }
            });
        });
        count
    }

    /// Whether a mobile particle is in reach of particle `i` (always, for a mobile particle
    /// or without the awake set), and whether it is a wall whose pair sums nothing reads (see
    /// the module doc).
    #[inline(always)]
    fn wall_of(&self, i: usize) -> (bool, bool) {
        let side = &self.sides[i];
        match self.extra.waking {
            Some(waking) if !side.mobile => {
                let wet = self.grid.any_near(waking, &side.x);
                (wet, self.model.params().generalised_walls || !wet)
            }
            _ => (true, false),
        }
    }

    /// The pair sums of `group` and, with the multiphase model, its stress divergence.
    #[inline(always)]
    fn group(&self, group: &Group) -> (PairSum<Lanes>, [Lanes; 3]) {
        let (grid, model, sides) = (self.grid, self.model, self.sides);
        let m = &group.members;
        let side = Side::lanes(&m.map(|i| sides[i]));
        let mut sum = PairSum::<Lanes>::default();
        let mut tau = [Lanes::splat(0.0); 3];
        let stress = self.extra.stress.map(|(div, stress, _)| {
            let mine = StressSide::lanes(&m.map(|i| stress[i]));
            (div, stress, mine)
        });
        // One walk for each model, not one choice per cell: the stress's sums would otherwise
        // stay live through the water-only walk and crowd its registers.
        match &stress {
            None => grid.group_cells(
                group,
                #[inline(always)]
                |range, near| {
                    for j in range {
                        model.add_pair(&side, &sides[j], near, &mut sum);
                    }
                },
            ),
            Some((div, stress, stress_i)) => grid.group_cells(
                group,
                #[inline(always)]
                |range, near| {
                    for j in range {
                        if let Some(g) = model.add_pair(&side, &sides[j], near, &mut sum) {
                            div.add_term(stress_i, &stress[j], &g, &mut tau);
                        }
                    }
                },
            ),
        }
        (sum, tau)
    }

    /// The generalised wall sums (`physics::boundary`) of a group of wet walls, each lane
    /// over its own neighbours in sorted order, as one wall alone would. A dry wall takes
    /// rest density without them.
    #[inline(always)]
    fn wall_sums(&self, group: &Group) -> WallSums<Lanes> {
        let side = Side::lanes(&group.members.map(|i| self.sides[i]));
        let mut sums = WallSums::<Lanes>::default();
        self.grid.group_cells(
            group,
            #[inline(always)]
            |range, near| {
                for j in range {
                    self.model
                        .add_wall_pair(&side, &self.sides[j], near, &mut sums);
                }
            },
        );
        sums
    }

    /// Particle `i`'s forces and step from its sums, and a wall's density from its `wall`
    /// sums under the generalised condition (none or empty: dry).
    fn finish(&self, i: usize, sum: &PairSum, wall: Option<&WallSums>) -> ([f32; 4], f32) {
        let side = &self.sides[i];
        let imposed = self.extra.imposed.get(i).copied().unwrap_or(false);
        let (mut f, mut dt) = self.model.finish(side, sum, !imposed);
        if !side.mobile && self.model.params().generalised_walls {
            // A wall's fourth entry is then its density, not a rate (`physics::boundary`).
            let dry = WallSums::default();
            f[3] = self.model.wall_density(side, wall.unwrap_or(&dry));
        }
        if let Some((_, _, mu)) = self.extra.stress
            && dt.is_finite()
        {
            dt = dt.min(particle_viscous_bound(
                self.model.params().h,
                side.rho,
                mu[i],
            ));
        }
        (f, dt)
    }
}

/// Whether a particle wakes the walls within reach: any mobile particle but the held sand
/// fixed where it stands (DBC under the Shields-only mode), and anything that moves. Under
/// the generalised condition a wall's density comes from the fluid around it, still or not;
/// no sand is fixed there.
pub fn wakes(side: &Side) -> bool {
    (side.mobile && !side.fixed) || side.v != [0.0; 3]
}

/// The smallest stable step over particles, s (f32::MAX when none bounds it, as the GPU's
/// reduction starts).
pub fn min_dt(dt_limit: &[f32]) -> f32 {
    dt_limit.iter().copied().fold(f32::MAX, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::fixture::{Fixture, fixture};
    use crate::physics::Viscosity;

    /// The pass particle by particle over `Grid::rows`, each pair by the `f32` formulas: what
    /// every lane must give, to the bit.
    fn one_by_one(pass: &Pass) -> (Vec<[f32; 4]>, Vec<f32>) {
        let (grid, sides) = (pass.grid, pass.sides);
        (0..sides.len())
            .map(|i| {
                let mut sum = PairSum::default();
                let mut tau = [0.0f32; 3];
                let mut wall = WallSums::default();
                grid.rows(grid.coords(&sides[i].x), |range| {
                    for j in range {
                        let g = pass.model.add_pair(&sides[i], &sides[j], true, &mut sum);
                        if let (Some(g), Some((div, stress, _))) = (g, pass.extra.stress) {
                            div.add_term(&stress[i], &stress[j], &g, &mut tau);
                        }
                        pass.model
                            .add_wall_pair(&sides[i], &sides[j], true, &mut wall);
                    }
                });
                for (a, t) in sum.acc.iter_mut().zip(tau) {
                    *a += t;
                }
                pass.finish(i, &sum, Some(&wall))
            })
            .unzip()
    }

    fn bits(forces: &[[f32; 4]], dt: &[f32]) -> Vec<u32> {
        let f = forces.iter().flatten();
        f.chain(dt).map(|v| v.to_bits()).collect()
    }

    /// Made-up stresses, different in every particle and component.
    fn stresses(fx: &Fixture, div: &StressDivergence) -> (Vec<StressSide>, Vec<f32>) {
        (0..fx.pos.len())
            .map(|i| {
                let s = i as f32;
                let t = [[s, 0.5 * s, 0.0], [0.5 * s, -s, 0.0], [0.0; 3]];
                (div.side(&fx.pos[i], fx.vel[i][3], &t), 1e-3 * s)
            })
            .unzip()
    }

    /// The census counts, among the lane-pairs it evaluates, every pair within the support
    /// that has a mobile side, once: the brute-force count over all pairs.
    #[test]
    fn the_lane_census_finds_every_pair_within_the_support() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool of two threads");
        let fx = fixture(Viscosity::Laminar);
        let model = PairModel::new(&fx.params);
        let sides: Vec<Side> = (0..fx.pos.len())
            .map(|i| model.side(&fx.pos[i], &fx.vel[i]))
            .collect();
        let support2 = (2.0 * fx.params.h).powi(2);
        let n = sides.len();
        let brute = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|&(i, j)| i != j && (sides[i].mobile || sides[j].mobile))
            .filter(|&(i, j)| {
                let r2: f32 = (0..3)
                    .map(|k| (sides[i].x[k] - sides[j].x[k]).powi(2))
                    .sum();
                r2 < support2
            })
            .count() as u64;
        let extra = Extra {
            stress: None,
            imposed: &[],
            waking: None,
        };
        let lanes = lane_use(&pool, &model, &fx.grid, &sides, &extra);
        assert_eq!(lanes.useful, brute);
        assert!(lanes.evaluated > 2 * lanes.useful, "{lanes:?}");
    }

    #[test]
    fn each_lane_sums_its_particle_as_the_particle_alone_would() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool of two threads");
        let viscosities = [
            Viscosity::Multiphase {
                alpha: 0.05,
                sps_length2: 0.0,
            },
            Viscosity::Laminar,
        ];
        for (viscosity, generalised) in viscosities.into_iter().zip([false, true]) {
            let mut fx = fixture(viscosity);
            fx.params.generalised_walls = generalised;
            let model = PairModel::new(&fx.params);
            let sides: Vec<Side> = (0..fx.pos.len())
                .map(|i| model.side(&fx.pos[i], &fx.vel[i]))
                .collect();
            let div = StressDivergence::new(&fx.params);
            let (stress, mu) = stresses(&fx, &div);
            let imposed: Vec<bool> = (0..sides.len()).map(|i| i % 7 == 0).collect();
            let with_stress = matches!(viscosity, Viscosity::Multiphase { .. });
            let n = sides.len();
            let waking = Flagged::new(n, |k| wakes(&sides[k]));
            let full = Extra {
                stress: with_stress.then_some((&div, stress.as_slice(), mu.as_slice())),
                imposed: &imposed,
                waking: None,
            };
            let awake = Extra {
                waking: Some(&waking),
                ..full
            };
            let pass = |extra| Pass {
                model: &model,
                grid: &fx.grid,
                sides: &sides,
                extra,
            };
            let (want_f, want_dt) = one_by_one(&pass(&full));
            // Not a vacuous comparison: nearly every particle feels more than gravity.
            let pushed = want_f.iter().filter(|f| f[1] != -9.81).count();
            assert!(pushed > n * 9 / 10, "{pushed} of {n}");

            for extra in [&full, &awake] {
                let (mut f, mut dt) = (vec![[0.0; 4]; n], vec![0.0; n]);
                force_pass(&pool, &model, &fx.grid, &sides, extra, &mut f, &mut dt);
                assert!(bits(&f, &dt) == bits(&want_f, &want_dt), "{viscosity:?}");
                // The baseline copy, without the AVX2 one, and the whole in one call.
                let (mut f, mut dt) = (vec![[0.0; 4]; n], vec![0.0; n]);
                pass(extra).block(0, &mut f, &mut dt);
                assert!(bits(&f, &dt) == bits(&want_f, &want_dt), "{viscosity:?}");
            }
        }
    }
}
