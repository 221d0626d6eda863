//! The cell list of the CPU backend: the grid of `grid.wgsl` (cells of 2h / R numbered x
//! fastest, so the R-neighbourhood of a cell is a few contiguous rows of the sorted arrays, as
//! DualSPHysics' `ParticleRange`), a counting sort by cell and, inside each cell, by id.
//! Sorting inside cells by id makes the order, and with it every neighbour sum, a function of
//! the state alone: runs are bit-identical whatever came before and on any number of threads.

use crate::contract::SimParams;
use rayon::prelude::*;
use std::ops::Range;

mod groups;

pub use groups::Group;

pub struct Grid {
    dims: [i32; 3],
    origin: [f32; 3],
    inv_cell: f32,
    /// Cells each way the kernel support reaches (cell divisions R).
    reach: i32,
    /// Sorted index of each cell's first particle; `n_cells + 1` entries.
    pub starts: Vec<u32>,
}

impl Grid {
    pub fn new(params: &SimParams, divisions: u32) -> Grid {
        let d = params.grid_dims;
        let o = params.grid_origin;
        Grid {
            dims: [d[0] as i32, d[1] as i32, d[2] as i32],
            origin: [o[0], o[1], o[2]],
            inv_cell: o[3],
            reach: divisions as i32,
            starts: vec![0; params.n_cells as usize + 1],
        }
    }

    /// The cell of a point, as `cell_coords` in grid.wgsl computes it: points outside the
    /// grid are kept in its border cells.
    #[inline]
    pub fn coords(&self, x: &[f32; 3]) -> [i32; 3] {
        let mut c = [0; 3];
        for k in 0..3 {
            // Truncation is the floor wherever the clamp keeps the result (t >= 0), and needs no
            // call into libm, which `floor` is on baseline x86-64. NaN falls to cell 0, where
            // the health check will have it; infinities saturate into the border cells.
            let t = (x[k] - self.origin[k]) * self.inv_cell;
            c[k] = (t as i32).clamp(0, self.dims[k] - 1);
        }
        c
    }

    fn index(&self, c: [i32; 3]) -> usize {
        ((c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]) as usize
    }

    /// Sorts particles by (cell, id): returns, for each sorted slot, the storage index of its
    /// particle, and fills `starts`. Particles of phase `parked` (an open flume's reservoir)
    /// go after all cells, in storage order: no neighbour loop visits them. Particles of one
    /// id in one cell keep their storage order. The caller may know that every particle from
    /// storage index `still` on is parked: those keep their slots, and are not looked at.
    pub fn sort(
        &mut self,
        positions: &[[f32; 4]],
        ids: &[u32],
        parked: Option<u32>,
        still: usize,
    ) -> Vec<u32> {
        let n = positions.len();
        let still = if parked.is_some() { still.min(n) } else { n };
        let outside = self.starts.len() as u32 - 1;
        let cells: Vec<u32> = positions[..still]
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| {
                if Some(p[3].to_bits()) == parked {
                    outside
                } else {
                    self.index(self.coords(&[p[0], p[1], p[2]])) as u32
                }
            })
            .collect();
        self.starts.fill(0);
        for &c in cells.iter().filter(|&&c| c != outside) {
            self.starts[c as usize + 1] += 1;
        }
        for c in 1..self.starts.len() {
            self.starts[c] += self.starts[c - 1];
        }
        let mut cursor = self.starts.clone();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut parked_slot = self.active() as usize;
        for (i, &c) in cells.iter().enumerate() {
            let slot = if c == outside {
                parked_slot += 1;
                parked_slot - 1
            } else {
                cursor[c as usize] += 1;
                cursor[c as usize] as usize - 1
            };
            order[slot] = i as u32;
        }
        let active = self.active() as usize;
        by_id_within_cells(&mut order[..active], |i| (cells[i], ids[i]));
        order
    }

    /// Particles in cells after the last sort (the parked ones are not).
    pub fn active(&self) -> u32 {
        self.starts[self.starts.len() - 1]
    }

    /// Calls `visit` with the sorted-index range of each row of cells within reach of cell
    /// `c`, as `stencil_row` in neighbours.wgsl: (2R + 1) rows in 2-D, (2R + 1)^2 in 3-D.
    #[inline]
    pub fn rows(&self, c: [i32; 3], visit: impl FnMut(Range<usize>)) {
        let r = self.reach;
        // In 2-D the grid is one cell deep: the one plane z = 0.
        let lo = std::array::from_fn(|k| (c[k] - r).max(0));
        let hi = std::array::from_fn(|k| (c[k] + r).min(self.dims[k] - 1));
        self.rows_between(lo, hi, visit);
    }

    /// Calls `visit` with the sorted-index range of each row of cells that holds a part of
    /// the box from `lo` to `hi`, in the order of [`Grid::rows`]: every particle in the box
    /// is in one of them.
    #[inline]
    pub fn rows_in_box(&self, lo: &[f32; 3], hi: &[f32; 3], visit: impl FnMut(Range<usize>)) {
        self.rows_between(self.coords(lo), self.coords(hi), visit);
    }

    /// The rows of the cells from `lo` to `hi` (inside the grid), z, then y, ascending.
    #[inline(always)]
    fn rows_between(&self, lo: [i32; 3], hi: [i32; 3], mut visit: impl FnMut(Range<usize>)) {
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                let base = self.index([0, y, z]);
                let first = self.starts[base + lo[0] as usize] as usize;
                let end = self.starts[base + hi[0] as usize + 1] as usize;
                if end > first {
                    visit(first..end);
                }
            }
        }
    }
}

impl Grid {
    /// Whether any particle that `flagged` counts lies in the cells within reach of `x`'s:
    /// false means none is within the kernel's support of a particle at `x`.
    #[inline]
    pub fn any_near(&self, flagged: &Flagged, x: &[f32; 3]) -> bool {
        let mut any = false;
        self.rows(self.coords(x), |range| {
            any |= flagged.before[range.end] != flagged.before[range.start];
        });
        any
    }
}

/// Puts each cell's particles of `order` (already grouped by cell, in cell order) in id
/// order, `key(i)` being particle i's (cell, id). An insertion sort: the storage order is
/// the last sort's, so a cell holds only the few particles that entered it out of place, and
/// a particle never moves past its own cell's first.
fn by_id_within_cells(order: &mut [u32], key: impl Fn(usize) -> (u32, u32)) {
    for k in 1..order.len() {
        let i = order[k];
        let key_i = key(i as usize);
        let mut j = k;
        while j > 0 && key(order[j - 1] as usize) > key_i {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = i;
    }
}

/// A set of particles of the sorted order, as the running count of its members before each
/// slot: how many lie in a row of cells is one subtraction.
pub struct Flagged {
    before: Vec<u32>,
}

impl Flagged {
    /// The particles `k` of `0..n` for which `member(k)`.
    pub fn new(n: usize, member: impl Fn(usize) -> bool) -> Flagged {
        let mut before = Vec::with_capacity(n + 1);
        let mut count = 0u32;
        before.push(0);
        for k in 0..n {
            count += u32::from(member(k));
            before.push(count);
        }
        Flagged { before }
    }

    /// Whether no particle is flagged.
    pub fn is_empty(&self) -> bool {
        self.before.last().is_none_or(|&n| n == 0)
    }
}

/// `values` in sorted order: slot k holds the value of storage index `order[k]`.
#[cfg(test)]
pub fn gather<T: Copy>(values: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&i| values[i as usize]).collect()
}

/// Fewest particles a thread takes in the sort's parallel loops (and the gather after it):
/// less is not worth a wake-up. At 4096 the CI flume's 4,000 particles went to one thread,
/// which then read what the other had just stored, line by line from the other core's cache:
/// the cells and the gather took 55 us a step against 40 us at 1024 (README, speed).
pub const PAR_MIN: usize = 1024;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::lanes::LANES;
    use bytemuck::Zeroable;

    /// `cell_coords` of grid.wgsl, by floor: what `coords` must give for any point.
    fn by_floor(grid: &Grid, x: &[f32; 3]) -> [i32; 3] {
        std::array::from_fn(|k| {
            let hi = (grid.dims[k] - 1) as f32;
            ((x[k] - grid.origin[k]) * grid.inv_cell)
                .floor()
                .clamp(0.0, hi) as i32
        })
    }

    /// A 24-bit pseudo-random sequence (Numerical Recipes' LCG, its top bits) from `seed`.
    fn lcg(mut seed: u32) -> impl FnMut() -> u32 {
        move || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            seed >> 8
        }
    }

    /// A 2-D grid of 12 x 9 cells of h = 1.7 dp at dp = 0.01 (two divisions of 2h, as the
    /// CI flume has), and its cell size.
    fn twelve_by_nine() -> (Grid, f32) {
        let mut sim = SimParams::zeroed();
        let cell = 0.017;
        sim.grid_dims = [12, 9, 1, 0];
        sim.grid_origin = [0.0, 0.0, 0.0, 1.0 / cell];
        sim.n_cells = 12 * 9;
        (Grid::new(&sim, 2), cell)
    }

    /// The sort leaves each cell's particles in id order whatever their storage order, and
    /// the parked ones after every cell in storage order (an inlet takes them in that order);
    /// an id given twice loses no particle.
    #[test]
    fn the_sort_orders_each_cell_by_id_and_keeps_the_parked_in_storage_order() {
        let (mut grid, cell) = twelve_by_nine();
        // A particle's fourth component holds its phase's index as bits.
        let (water, parked) = (f32::from_bits(0), 7);
        let parked_bits = f32::from_bits(parked);
        let at = |cx: f32, phase: f32| [(cx + 0.5) * cell, 0.5 * cell, 0.0, phase];
        // Storage order: cells 2, 0, 2, parked, 0, parked, 2; ids not in that order.
        let positions = [
            at(2.0, water),
            at(0.0, water),
            at(2.0, water),
            at(5.0, parked_bits),
            at(0.0, water),
            at(1.0, parked_bits),
            at(2.0, water),
        ];
        let ids = [6, 4, 1, 0, 2, 5, 3];
        let order = grid.sort(&positions, &ids, Some(parked), positions.len());
        // Cell 0: ids 4, 2 (slots 1, 4) -> 2 then 4; cell 2: ids 6, 1, 3 -> 1, 3, 6; then
        // the parked slots 3 and 5 as stored.
        assert_eq!(order, [4, 1, 2, 6, 0, 3, 5]);
        assert_eq!(grid.active(), 5);
        // Id 4 twice, both in cell 0 (slots 1 and 4): both kept, in storage order.
        let ids = [6, 4, 1, 0, 4, 5, 3];
        let order = grid.sort(&positions, &ids, Some(parked), positions.len());
        assert_eq!(order, [1, 4, 2, 6, 0, 3, 5]);
    }

    /// Whatever the storage order (shuffled, or the last sort's with particles moved on), the
    /// sort gives each cell's particles in id order, as a sort of the whole by (cell, id)
    /// does, and the parked ones after them in storage order, whether or not the sort is told
    /// where the parked ones stored last begin: some cells hold a dozen, or,
    /// with 5,000 particles, some fifty (the cells' parallel loop then splits among three
    /// threads).
    #[test]
    fn the_sort_is_by_cell_then_id_from_any_storage_order() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("a pool of three threads");
        for n in [400, 5000] {
            pool.install(|| sorted_as_a_whole(n));
        }
    }

    fn sorted_as_a_whole(n: usize) {
        let (mut grid, cell) = twelve_by_nine();
        let parked = 7;
        let mut next = lcg(5);
        let mut pos: Vec<[f32; 4]> = (0..n)
            .map(|_| {
                let x = (next() % 1000) as f32 * 0.012 * cell;
                let y = (next() % 1000) as f32 * 0.009 * cell * (next() % 2) as f32;
                let phase = if next().is_multiple_of(10) { parked } else { 0 };
                [x, y, 0.0, f32::from_bits(phase)]
            })
            .collect();
        let mut ids: Vec<u32> = (0..n as u32).map(|k| (k * 7919) % 10007).collect();
        // After the first round the parked are stored last: the later sorts are told so.
        let mut still = n;
        for round in 0..3 {
            let order = grid.sort(&pos, &ids, Some(parked), still);
            still = grid.active() as usize;
            let key = |i: u32| {
                let x = &pos[i as usize];
                if x[3].to_bits() == parked {
                    return (usize::MAX, 0);
                }
                let c = grid.index(grid.coords(&[x[0], x[1], x[2]]));
                (c, ids[i as usize])
            };
            let mut expected: Vec<u32> = (0..n as u32).collect();
            expected.sort_by_key(|&i| key(i));
            assert_eq!(order, expected, "{n} particles, round {round}");
            // Stored in the sorted order, then moved by up to a cell.
            pos = gather(&pos, &order);
            ids = gather(&ids, &order);
            for x in &mut pos {
                x[0] = (x[0] + cell * ((next() % 200) as f32 / 100.0 - 1.0)).max(0.0);
            }
        }
    }

    /// Every particle inside a box lies in a row `rows_in_box` visits, for boxes from a tenth
    /// of a cell to three cells wide anywhere on the grid, across cell edges and its border.
    #[test]
    fn a_box_s_rows_hold_every_particle_in_it() {
        let (mut grid, cell) = twelve_by_nine();
        // A lattice of dp = 0.01 shaken by up to 0.4 dp, some of it outside the grid.
        let mut next = lcg(11);
        let mut shake = || next() as f32 / 16_777_216.0 - 0.5;
        let mut pos = Vec::new();
        for iy in 0..16 {
            for ix in 0..22 {
                let x = (ix as f32 - 0.5) * 0.01 + 0.008 * shake();
                let y = (iy as f32 - 0.5) * 0.01 + 0.008 * shake();
                pos.push([x, y, 0.0, 0.0]);
            }
        }
        let ids: Vec<u32> = (0..pos.len() as u32).collect();
        let order = grid.sort(&pos, &ids, None, pos.len());
        let pos = gather(&pos, &order);
        let (mut inside, mut straddling) = (0, 0);
        for _ in 0..400 {
            let at = [0.2 * shake() + 0.1, 0.15 * shake() + 0.07, 0.0];
            let half = cell * (0.05 + 1.45 * (shake() + 0.5));
            let (lo, hi) = (at.map(|a| a - half), at.map(|a| a + half));
            let mut seen = vec![false; pos.len()];
            grid.rows_in_box(&lo, &hi, |range| range.for_each(|j| seen[j] = true));
            for (j, x) in pos.iter().enumerate() {
                if (0..2).all(|k| (lo[k]..=hi[k]).contains(&x[k])) {
                    assert!(seen[j], "{x:?} in the box {lo:?} .. {hi:?}");
                    inside += 1;
                }
            }
            straddling += usize::from(grid.coords(&lo) != grid.coords(&hi));
        }
        assert!(inside > 2000 && straddling > 300, "{inside} {straddling}");
    }

    /// Each member of a group visits, through the group's walk, the particles its own walk
    /// over `rows` visits, in the same order: also where the grid was sorted half a step
    /// before (the symplectic corrector's), so that cells need not rise along the sorted
    /// order, and whichever particles the group leaves out.
    #[test]
    fn each_member_of_a_group_walks_its_own_neighbours_in_order() {
        let (mut grid, cell) = twelve_by_nine();
        let mut pos = Vec::new();
        for iy in 0..14 {
            for ix in 0..19 {
                pos.push([(ix as f32 + 0.5) * 0.01, (iy as f32 + 0.5) * 0.01, 0.0, 0.0]);
            }
        }
        let ids: Vec<u32> = (0..pos.len() as u32).collect();
        let order = grid.sort(&pos, &ids, None, pos.len());
        let mut pos = gather(&pos, &order);
        // Half a step later every third particle has moved back by 0.6 cell.
        for x in pos.iter_mut().step_by(3) {
            x[0] = (x[0] - 0.6 * cell).max(0.0);
        }
        let x_of = |k: usize| [pos[k][0], pos[k][1], pos[k][2]];
        let falling = (1..pos.len()).filter(|&k| {
            let (a, b) = (grid.coords(&x_of(k - 1)), grid.coords(&x_of(k)));
            a[1] == b[1] && b[0] < a[0]
        });
        let falling = falling.count();
        assert!(falling > 10, "{falling}");
        for take_every in [1, 2, 3] {
            let take = |k: usize| k.is_multiple_of(take_every);
            let mut next = 0;
            grid.groups((0, pos.len()), x_of, take, |stretch, group| {
                assert_eq!(stretch.start, next, "the stretches leave none out");
                assert!(!stretch.is_empty());
                next = stretch.end;
                let Some(group) = group else {
                    assert!(!stretch.clone().any(take));
                    return;
                };
                let mut walked = vec![Vec::new(); LANES];
                grid.group_cells(group, |range, near| {
                    for (lane, w) in walked.iter_mut().enumerate() {
                        if near.0[lane] != 0 {
                            w.extend(range.clone());
                        }
                    }
                });
                for (lane, &i) in group.taken().iter().enumerate() {
                    assert!(take(i) && stretch.contains(&i));
                    let mut own = Vec::new();
                    grid.rows(grid.coords(&x_of(i)), |range| own.extend(range));
                    assert_eq!(walked[lane], own, "particle {i}");
                }
            });
            assert_eq!(next, pos.len());
        }
    }

    #[test]
    fn cells_of_points_inside_outside_and_not_finite_are_those_of_the_shader() {
        let mut sim = SimParams::zeroed();
        sim.grid_dims = [7, 5, 3, 0];
        sim.grid_origin = [-0.1, 0.2, 0.0, 1.0 / 0.05];
        sim.n_cells = 7 * 5 * 3;
        let grid = Grid::new(&sim, 1);
        // Cell edges, points just below the origin (truncation would give 0 there too, but
        // -1.5 cells and beyond must clamp), far outside, and not finite.
        let values = [
            -0.1,
            -0.1 - 1e-7,
            -0.125,
            -0.2,
            -1e30,
            0.0,
            0.049_999,
            0.05,
            0.2,
            0.25,
            0.2999,
            0.3,
            0.5,
            1e30,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let mut edge_cases = 0;
        for &a in &values {
            for &b in &values {
                let x = [a, b, a - b];
                let got = grid.coords(&x);
                assert_eq!(got, by_floor(&grid, &x), "{x:?}");
                edge_cases += usize::from(got.contains(&0) || got[0] == 6 || got[1] == 4);
            }
        }
        assert!(edge_cases > 100, "{edge_cases}");
        assert_eq!(grid.coords(&[0.026, 0.31, 0.07]), [2, 2, 1]);
    }
}
