//! Who a particle's neighbours are, for the neighbour loops of the CPU backend: either the rows
//! of cells within reach (`Grid`), or a list of the pairs within the kernel's support, found
//! once from those rows when several passes visit the same positions (the rheology, release
//! and force passes of the water-sediment model). The list visits the same neighbours in the
//! same order as the rows, less those outside the support that every pair formula skips, so
//! a pass gives the same sums, bit for bit, over either.

use super::grid::Grid;
use rayon::prelude::*;

/// Particles per block of the list's construction (as the force pass's blocks).
const BLOCK: usize = 512;

/// The neighbours of each particle, in sorted order.
pub trait Neighbourhood: Sync {
    /// Calls `visit` with the sorted index of each candidate neighbour of particle `i`, at
    /// `x`, in increasing order of index; `i` itself may be among them.
    fn visit(&self, i: usize, x: &[f32; 3], visit: impl FnMut(usize));
}

impl Neighbourhood for Grid {
    #[inline]
    fn visit(&self, _i: usize, x: &[f32; 3], mut visit: impl FnMut(usize)) {
        self.rows(self.coords(x), |range| range.for_each(&mut visit));
    }
}

/// The neighbours closer than the support of each particle, in compressed rows: particle i's
/// are `list[offsets[i]..offsets[i + 1]]`.
pub struct NeighbourList {
    offsets: Vec<u32>,
    list: Vec<u32>,
}

impl NeighbourList {
    /// The pairs of the first `n` particles of `pos` (sorted order, cells from `grid`) closer
    /// than `sqrt(support2)`, the particle itself left out.
    pub fn new(
        pool: &rayon::ThreadPool,
        grid: &Grid,
        pos: &[[f32; 4]],
        n: usize,
        support2: f32,
    ) -> NeighbourList {
        let blocks: Vec<(Vec<u32>, Vec<u32>)> = pool.install(|| {
            (0..n.div_ceil(BLOCK))
                .into_par_iter()
                .map(|block| {
                    let range = block * BLOCK..((block + 1) * BLOCK).min(n);
                    let mut counts = Vec::with_capacity(range.len());
                    let mut list = Vec::new();
                    for i in range {
                        let x = [pos[i][0], pos[i][1], pos[i][2]];
                        let before = list.len();
                        grid.visit(i, &x, |j| {
                            let d = [x[0] - pos[j][0], x[1] - pos[j][1], x[2] - pos[j][2]];
                            if j != i && d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < support2 {
                                list.push(j as u32);
                            }
                        });
                        counts.push((list.len() - before) as u32);
                    }
                    (counts, list)
                })
                .collect()
        });
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0);
        let total = blocks.iter().map(|(_, l)| l.len()).sum();
        let mut list = Vec::with_capacity(total);
        for (counts, block) in blocks {
            for c in counts {
                offsets.push(offsets[offsets.len() - 1] + c);
            }
            list.extend_from_slice(&block);
        }
        NeighbourList { offsets, list }
    }
}

impl Neighbourhood for NeighbourList {
    #[inline]
    fn visit(&self, i: usize, _x: &[f32; 3], mut visit: impl FnMut(usize)) {
        let (lo, hi) = (self.offsets[i] as usize, self.offsets[i + 1] as usize);
        for &j in &self.list[lo..hi] {
            visit(j as usize);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::params::SimParams;

    /// A 2-D grid of cells 0.1 m wide, 20 by 20, reach 1, over `pos` sorted into it.
    fn sorted_grid(pos: &mut Vec<[f32; 4]>) -> Grid {
        let mut params: SimParams = bytemuck::Zeroable::zeroed();
        params.grid_dims = [20, 20, 1, 0];
        params.grid_origin = [0.0, 0.0, 0.0, 10.0];
        params.n_cells = 400;
        let mut grid = Grid::new(&params, 1);
        let ids: Vec<u32> = (0..pos.len() as u32).collect();
        let order = grid.sort(pos, &ids, None);
        *pos = super::super::grid::gather(pos, &order);
        grid
    }

    /// The list holds exactly the pairs closer than the support, each particle's in the
    /// order the rows give them: a list that kept a pair outside the support, lost one
    /// inside, or reordered them would change the passes' sums.
    #[test]
    fn list_is_the_rows_within_the_support() {
        let mut pos: Vec<[f32; 4]> = (0..300)
            .map(|k| {
                let (a, b) = ((k * 37 % 300) as f32, (k * 91 % 300) as f32);
                [0.3 + a * 0.0011, 0.4 + b * 0.0009, 0.0, 0.0]
            })
            .collect();
        let grid = sorted_grid(&mut pos);
        let support2 = 0.1f32 * 0.1;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let list = NeighbourList::new(&pool, &grid, &pos, pos.len(), support2);
        let mut pairs = 0;
        for (i, p) in pos.iter().enumerate() {
            let x = [p[0], p[1], p[2]];
            let mut expected = Vec::new();
            for (j, q) in pos.iter().enumerate() {
                let d2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
                if j != i && d2 < support2 {
                    expected.push(j);
                }
            }
            let mut got = Vec::new();
            list.visit(i, &x, |j| got.push(j));
            assert_eq!(got, expected, "neighbours of particle {i}");
            pairs += got.len();
        }
        assert_eq!(list.list.len(), pairs);
        assert!(pairs > 20 * pos.len(), "too sparse to test: {pairs} pairs");
    }
}
