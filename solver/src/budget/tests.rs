use super::*;
use crate::physics::sediment::pass::REGION_HELD;

/// The short open flume: dp = 5 mm, its collector from x = 0.21 m.
fn collector_case() -> Case {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cases/collector_2d.yaml");
    Case::from_path(std::path::Path::new(path)).expect("the collector case")
}

fn particles(at: &[([f64; 2], u32)]) -> Particles {
    Particles {
        positions: at
            .iter()
            .map(|&([x, y], phase)| [x as f32, y as f32, 0.0, f32::from_bits(phase)])
            .collect(),
        vel_rho: vec![[0.0; 4]; at.len()],
        ids: (0..at.len() as u32).collect(),
    }
}

const SAND: u32 = 2;
const WATER: u32 = 1;
const HELD: u32 = Region::Unyielded as u32 | REGION_HELD;

/// Seven grains, each put by hand where one kind of budget entry should find it, and a water
/// particle the budget must leave out.
#[test]
fn each_grain_is_booked_where_it_is_and_stays_mobilised() {
    let case = collector_case();
    let start = [
        [0.010, 0.010],
        [0.050, 0.010],
        [0.090, 0.010],
        [0.120, 0.010],
        [0.150, 0.010],
        [0.180, 0.020],
        [0.195, 0.020],
    ];
    let mut at: Vec<([f64; 2], u32)> = start.iter().map(|&p| (p, SAND)).collect();
    at.push(([0.1, 0.05], WATER));
    let mut budget = SedimentBudget::new(&case, &particles(&at)).expect("sand in a flume");
    assert_eq!(budget.grains.len(), 7);
    // The stretches span the grains' columns, 0.0075 to 0.1975 m, in five of 0.038 m.
    let edges = budget.stretch_edges_m();
    assert!((edges[0] - 0.0075).abs() < 1e-6 && (edges[5] - 0.1975).abs() < 1e-6);
    let mut regions = vec![HELD; at.len()];
    regions[7] = Region::Water as u32;
    // 0: untouched. 1: bed load, carried 0.11 m. 2: moved 0.3 dp, held: not mobilised.
    regions[1] = Region::BedLoad as u32;
    at[1].0 = [0.160, 0.012];
    at[2].0 = [0.0915, 0.010];
    // 3: carried 0.08 m downstream and laid down again. 4: past the collector's edge.
    at[3].0 = [0.200, 0.012];
    at[4].0 = [0.215, 0.030];
    regions[4] = Region::Yielded as u32;
    // 5: water now (collected and recycled). 6: suspended where it was.
    at[5].1 = WATER;
    regions[6] = Region::Suspended as u32;
    let row = budget.update(1.0, &particles(&at), &regions, 0);
    assert_eq!(
        (
            row.moving,
            row.suspended,
            row.deposited,
            row.past_bed,
            row.collected
        ),
        (1, 1, 1, 1, 1),
        "{row:?}"
    );
    assert_eq!(row.mobilised, 5);
    // Grain 1 went 0.11 m, grain 3 0.08 m, grain 4 0.065 m: one far.
    assert_eq!(row.travelled_far, 1);
    assert!((row.furthest_m - 0.11).abs() < 1e-6, "{}", row.furthest_m);
    // By where they started (edges 0.0075, 0.0455, 0.0835, 0.1215, 0.1595, 0.1975 m): grain 1
    // in the second stretch, 3 in the third, 4 in the fourth, 5 and 6 in the fifth.
    assert_eq!(row.mobilised_by_stretch, [0, 1, 1, 1, 2]);

    // The bed load settles where it went: still mobilised, deposited now.
    regions[1] = HELD;
    let row = budget.update(2.0, &particles(&at), &regions, 0);
    assert_eq!(
        (row.mobilised, row.moving, row.deposited),
        (5, 0, 2),
        "{row:?}"
    );

    // A reset (the twin's): back where they were generated, all held, none mobilised; the
    // grain that went 0.11 m no longer counts as far travelled either.
    budget.restart();
    let start_again: Vec<([f64; 2], u32)> = start
        .iter()
        .map(|&p| (p, SAND))
        .chain([([0.1, 0.05], WATER)])
        .collect();
    let mut held = vec![HELD; start_again.len()];
    held[7] = Region::Water as u32;
    let row = budget.update(0.0, &particles(&start_again), &held, 0);
    assert_eq!((row.mobilised, row.travelled_far), (0, 0), "{row:?}");
}

/// The mass worn off grains still held, whether or not they have moved, and by the stretch
/// the grain started in: a quarter of one untouched grain and three eighths of another, and
/// under Exner's balance less an eighth settled on a third beyond its own mass; the units left
/// in the word of a grain that is not held, and of water, are no grain's wear.
#[test]
fn worn_is_the_wear_of_the_held_grains() {
    use crate::physics::sediment::pickup::{EXNER_WHOLE, PICKUP_WHOLE, units_word};
    let at = [
        ([0.010, 0.010], SAND),
        ([0.050, 0.010], SAND),
        ([0.090, 0.010], SAND),
        ([0.120, 0.010], SAND),
        ([0.1, 0.05], WATER),
    ];
    let worn = |case: &Case, whole: u32, last: i32| {
        let mut budget = SedimentBudget::new(case, &particles(&at)).expect("sand in a flume");
        let units = |over: i32, times: i32| units_word(whole as i32 / over * times);
        let regions = [
            HELD | units(4, 1),
            HELD | units(8, 3),
            Region::BedLoad as u32 | units(2, 1),
            HELD | units(8, last),
            Region::Water as u32 | REGION_HELD | units(2, 1),
        ];
        let row = budget.update(1.0, &particles(&at), &regions, 0);
        assert_eq!(row.mobilised, 1, "only the bed-load grain moved");
        row
    };
    // The four grains span 0.0075-0.1225 m: the first two lie in the first two stretches, the
    // last in the last.
    let alone = worn(&collector_case(), PICKUP_WHOLE, 0);
    assert!((alone.worn - 0.625).abs() < 1e-12, "{}", alone.worn);
    assert_eq!(alone.worn_by_stretch, [0.25, 0.375, 0.0, 0.0, 0.0]);
    let set = ["phases.1.sediment.erosion=van_rijn_exner".to_string()];
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cases/collector_2d.yaml");
    let exner = Case::from_path_with(std::path::Path::new(path), &set).expect("the case");
    // Under Exner's balance the moving grain (at 0.09 m, the fourth stretch) carries its
    // wear, which went downstream as bed load: half a grain.
    let net = worn(&exner, EXNER_WHOLE, -1);
    assert!((net.worn - 1.0).abs() < 1e-12, "{}", net.worn);
    assert_eq!(net.worn_by_stretch, [0.25, 0.375, 0.0, 0.5, -0.125]);
}
