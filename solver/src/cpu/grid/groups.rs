//! The groups of the vectorised passes: up to [`LANES`] particles of one row of cells, taken
//! together, and the cells within reach of a group's row.

use super::Grid;
use crate::physics::lanes::{LANES, LaneMask};
use std::ops::Range;

/// Up to [`LANES`] particles of one row of cells that the vectorised passes take together:
/// those of a stretch of the sorted order that a pass walks, the ones it spares left out.
pub struct Group {
    /// The sorted indices of the particles taken, in order; lanes past `count` repeat the
    /// last, as the lane sides do.
    pub members: [usize; LANES],
    count: usize,
    /// The row's cell of least x among those taken, and the greatest x.
    cell: [i32; 3],
    x_hi: i32,
    /// The x of each one's cell, lane by lane.
    cells_x: [i32; LANES],
}

impl Group {
    /// The particles taken, lane by lane.
    pub fn taken(&self) -> &[usize] {
        &self.members[..self.count]
    }

    /// Lanes whose own neighbourhood (`reach` cells each way) holds cell x `x` of the row.
    #[inline(always)]
    fn near(&self, x: i32, reach: i32) -> LaneMask {
        LaneMask::from_fn(|k| (x - self.cells_x[k]).abs() <= reach)
    }
}

/// How far along its row of cells a group may reach, cells: a wider group walks more cells
/// for each of its lanes. On the CI twin 4 ran fastest, 2 about as fast, 8 slower (README,
/// speed: "Groups packed with the particles that walk").
const GROUP_SPAN: i32 = 4;

impl Grid {
    /// Calls `walk` with each stretch of the sorted order from `first` to `end` that one
    /// group is taken from (`Grid::group`), in order, and its group: None where `take`
    /// accepts none of the stretch. The particles of a stretch that `take` refuses are the
    /// caller's to handle.
    #[inline(always)]
    pub fn groups(
        &self,
        (first, end): (usize, usize),
        x: impl Fn(usize) -> [f32; 3],
        take: impl Fn(usize) -> bool,
        mut walk: impl FnMut(Range<usize>, Option<&Group>),
    ) {
        let mut start = first;
        while start < end {
            let (stretch, group) = self.group((start, end), &x, &take);
            start = stretch.end;
            walk(stretch, group.as_ref());
        }
    }

    /// The group from sorted particle `first` (up to `end`): the particles `take` accepts,
    /// [`LANES`] at most, of `first`'s row of cells (same y and z) and within [`GROUP_SPAN`]
    /// cells of each other along it, `x(k)` being where particle k is (the cells of a grid
    /// sorted half a step before need not rise along the sorted order).
    /// A group shares its neighbour rows, so the vectorised passes take it at once; the
    /// particles between its members that `take` refuses are left to the caller. Returns the
    /// stretch of the sorted order it was taken from (never empty) and the group, None where
    /// it takes nobody.
    #[inline(always)]
    fn group(
        &self,
        (first, end): (usize, usize),
        x: impl Fn(usize) -> [f32; 3],
        take: impl Fn(usize) -> bool,
    ) -> (Range<usize>, Option<Group>) {
        let row = self.coords(&x(first));
        let mut members = [first; LANES];
        let mut cells_x = [row[0]; LANES];
        let (mut count, mut lo, mut hi) = (0, i32::MAX, i32::MIN);
        let mut stop = first;
        while stop < end {
            let c = self.coords(&x(stop));
            if c[1] != row[1] || c[2] != row[2] {
                break;
            }
            if take(stop) {
                let (l, h) = (lo.min(c[0]), hi.max(c[0]));
                if count == LANES || h - l > GROUP_SPAN {
                    break;
                }
                (lo, hi) = (l, h);
                members[count] = stop;
                cells_x[count] = c[0];
                count += 1;
            }
            stop += 1;
        }
        // `first` lies in its own row: the stretch holds it.
        let stretch = first..stop;
        if count == 0 {
            return (stretch, None);
        }
        let last = (members[count - 1], cells_x[count - 1]);
        members[count..].fill(last.0);
        cells_x[count..].fill(last.1);
        let group = Group {
            members,
            count,
            cell: [lo, row[1], row[2]],
            x_hi: hi,
            cells_x,
        };
        (stretch, Some(group))
    }

    /// Calls `visit` with the sorted-index range and the x of each cell within reach of any
    /// of the cells `c` to `[x_last, c[1], c[2]]` (a group's row), rows in the order of
    /// [`Grid::rows`] and cells along each row: a particle of the group visits its own
    /// neighbours in the order `rows` gives them, among cells of the others.
    #[inline(always)]
    pub fn row_span(&self, c: [i32; 3], x_last: i32, mut visit: impl FnMut(Range<usize>, i32)) {
        let r = self.reach;
        let (z_lo, z_hi) = ((c[2] - r).max(0), (c[2] + r).min(self.dims[2] - 1));
        let x0 = (c[0] - r).max(0);
        let x1 = (x_last + r).min(self.dims[0] - 1);
        for z in z_lo..=z_hi {
            for y in (c[1] - r).max(0)..=(c[1] + r).min(self.dims[1] - 1) {
                let base = self.index([0, y, z]);
                for x in x0..=x1 {
                    let lo = self.starts[base + x as usize] as usize;
                    let hi = self.starts[base + x as usize + 1] as usize;
                    if hi > lo {
                        visit(lo..hi, x);
                    }
                }
            }
        }
    }

    /// Calls `visit` with the sorted-index range of each cell [`Grid::row_span`] gives for
    /// `group`, and the lanes of the group within reach of it: the walk of both lane passes.
    /// Like the `visit` a caller hands it, `#[inline(always)]` (`super::simd`).
    #[inline(always)]
    pub fn group_cells(&self, group: &Group, mut visit: impl FnMut(Range<usize>, LaneMask)) {
        let reach = self.reach;
        self.row_span(
            group.cell,
            group.x_hi,
            #[inline(always)]
            |range, x| visit(range, group.near(x, reach)),
        );
    }
}
