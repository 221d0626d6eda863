use super::*;

/// 2 m3/h over the ULBRA flume's 86 mm: q = 6.4600e-3 m2/s.
const Q_2: f64 = 5.5556e-4;
const WIDTH: f64 = 0.086;

fn ulbra(n: f64) -> Channel {
    Channel {
        x_inlet_m: 0.0,
        x_bed_end_m: 2.23,
        bed_m: 0.055,
        manning_n: n,
        side_walls: SideWalls::None,
        pit: PitFlow::Expanded,
        weir: Weir {
            x_m: 2.5,
            crest_m: 0.055,
            length_m: 0.03,
            floor_m: 0.0,
        },
    }
}

#[test]
fn critical_depth_and_strickler_by_hand() {
    // (6.46e-3^2 / 9.81)^(1/3) = (4.2540e-6)^(1/3) = 16.203 mm.
    assert!((critical_depth_m(Q_2 / WIDTH) - 0.016_203).abs() < 1e-6);
    // ks = 3 x 0.4 mm: 0.0012^(1/6) / 21.1 = 0.32597 / 21.1 = 0.015449.
    assert!((strickler_n(0.0012) - 0.015_449).abs() < 1e-6);
}

#[test]
fn rehbock_head_by_hand() {
    // q = 2/3 (0.611 + 0.08 H / P) sqrt(2 g) H^1.5 with P = 0.055 m: H = 22.60 mm
    // (by hand: at H = 22.60 mm, Cd = 0.6439 and q = 0.6667 x 0.6439 x 4.4294 x 3.3976e-3
    // = 6.460e-3).
    let h = ulbra(0.0).weir.sharp_head_m(Q_2 / WIDTH);
    assert!((h - 0.022_600).abs() < 2e-6, "{h}");
}

#[test]
fn a_short_crest_needs_more_head_than_a_thin_plate() {
    // L = 3 cm, P = 5.5 cm, H = 25.0 mm: H / L = 0.833, (H / L)^3.06 = 0.572,
    // 1 - 0.2 exp(-0.343) = 0.8581, Cd = (0.6035 + 0.0813 x 0.4545) x 0.8581 = 0.5496, and
    // q = 0.6667 x 0.5496 x 4.4294 x 3.9528e-3 = 6.415e-3, just under 6.46e-3: H is just over
    // 25.0 mm (25.10 mm).
    let weir = ulbra(0.0).weir;
    assert!((crest_coefficient(0.025, 0.055, 0.03) - 0.5496).abs() < 1e-4);
    let h = weir.head_m(Q_2 / WIDTH);
    assert!((h - 0.025_10).abs() < 2e-5, "{h}");
    assert!((weir.discharge_m2_per_s(h) - Q_2 / WIDTH).abs() < 1e-9);
    // A crest five times shorter is a thin plate again: within 0.3 mm of Peter's sharp rating.
    let thin = Weir {
        length_m: 0.006,
        ..weir
    };
    let sharp = invert(
        |h| {
            2.0 / 3.0
                * (0.6035 + 0.0813 * h / 0.055)
                * (2.0 * GRAVITY_M_PER_S2).sqrt()
                * h.powf(1.5)
        },
        Q_2 / WIDTH,
    );
    assert!((thin.head_m(Q_2 / WIDTH) - sharp).abs() < 3e-4);
}

/// The horizontal wide channel has a closed-form backwater curve (Chow 1959, Sec. 10-1, the
/// direct integration of dx = (1 - Fr^2) / Sf dh with Sf = n^2 q^2 / h^(10/3)):
/// x(h) = 3 h^(13/3) / (13 n^2 q^2) - 3 h^(4/3) / (4 g n^2) + const.
#[test]
fn the_backwater_curve_matches_its_closed_form() {
    let n = strickler_n(0.0012);
    let c = ulbra(n);
    let q = Q_2 / WIDTH;
    let p = c.steady(Q_2, WIDTH);
    let x = |h: f64| {
        3.0 * h.powf(13.0 / 3.0) / (13.0 * n * n * q * q)
            - 3.0 * h.powf(4.0 / 3.0) / (4.0 * GRAVITY_M_PER_S2 * n * n)
    };
    let h_end = *p.depths_m.last().expect("a profile");
    // The depth at the inlet is the one whose closed-form distance from the end is the reach.
    let reach = c.x_bed_end_m - c.x_inlet_m;
    let (mut lo, mut hi) = (h_end, 0.1);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if x(mid) - x(h_end) < reach {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let h0 = p.depths_m[0];
    assert!((h0 - lo).abs() < 2e-5, "RK4 {h0} against closed form {lo}");
    // The friction lifts the inlet's level by millimetres, not centimetres.
    assert!(h0 - h_end > 0.003 && h0 - h_end < 0.015, "{h0} {h_end}");
}

#[test]
fn without_friction_the_level_is_the_bed_ends_at_every_x() {
    let p = ulbra(0.0).steady(Q_2, WIDTH);
    let end = p.level_m(2.2);
    assert!((p.level_m(0.5) - end).abs() < 1e-9);
    assert_eq!(p.level_m(2.4), p.pool_level_m);
}

#[test]
fn the_drop_into_the_pit_loses_the_borda_carnot_head() {
    let c = ulbra(0.0);
    let q = Q_2 / WIDTH;
    let p = c.steady(Q_2, WIDTH);
    // Pool 0.055 + 0.0251 = 0.0801 m over a floor at 0: V2 = 6.46e-3 / 0.0801 = 0.081 m/s.
    assert!((p.pool_level_m - 0.080_10).abs() < 2e-5);
    let h1 = p.depths_m[p.depths_m.len() - 1];
    let (v1, v2) = (q / h1, q / p.pool_level_m);
    // Energy: level + V1^2/2g = pool + V2^2/2g + (V1 - V2)^2/2g, to the iteration's precision.
    let lhs = c.bed_m + h1 + v1 * v1 / (2.0 * GRAVITY_M_PER_S2);
    let rhs = p.pool_level_m + (v2 * v2 + (v1 - v2).powi(2)) / (2.0 * GRAVITY_M_PER_S2);
    assert!((lhs - rhs).abs() < 1e-9, "{lhs} {rhs}");
    // About 1.8 mm below the pool at 2 m3/h (V1 = 0.31 m/s).
    let drop = p.pool_level_m - p.level_m(2.23);
    assert!(drop > 0.0015 && drop < 0.0022, "{drop}");
}

#[test]
fn a_current_carried_over_the_pit_keeps_the_pools_energy() {
    let c = Channel {
        pit: PitFlow::Carried,
        ..ulbra(0.0)
    };
    let q = Q_2 / WIDTH;
    let p = c.steady(Q_2, WIDTH);
    let h1 = p.depths_m[p.depths_m.len() - 1];
    // By hand: the pool's energy over the bed is 0.02510 + 0.0807^2 / 2g = 25.43 mm, over
    // 1.5 h_c = 24.30 mm, so the flow stays subcritical: h1 + q^2 / (2 g h1^2) = 25.43 mm at
    // h1 = 20.24 mm (V1 = 0.319 m/s), 3.1 mm under the expanded pit's 23.3 mm.
    assert!((h1 - 0.020_24).abs() < 2e-5, "{h1}");
    let v2 = q / p.pool_level_m;
    let lhs = c.bed_m + h1 + (q / h1).powi(2) / (2.0 * GRAVITY_M_PER_S2);
    let rhs = p.pool_level_m + v2 * v2 / (2.0 * GRAVITY_M_PER_S2);
    assert!((lhs - rhs).abs() < 1e-9, "{lhs} {rhs}");
    let expanded = ulbra(0.0).steady(Q_2, WIDTH).level_m(2.23);
    assert!((expanded - p.level_m(2.23) - 0.0031).abs() < 2e-4);
    // A crest 1 cm under the bed leaves less energy than the bed's least: critical depth there.
    let low = Channel {
        weir: Weir {
            crest_m: 0.045,
            ..c.weir
        },
        ..c
    };
    let h_end = low
        .steady(Q_2, WIDTH)
        .depths_m
        .last()
        .copied()
        .unwrap_or(0.0);
    assert!(
        (h_end / critical_depth_m(q) - 1.001).abs() < 1e-9,
        "{h_end}"
    );
}

#[test]
fn glass_side_walls_add_friction() {
    let n = strickler_n(0.0012);
    let mut c = ulbra(n);
    let bed_only = c.steady(Q_2, WIDTH).level_m(0.5);
    c.side_walls = SideWalls::Glass {
        width_m: WIDTH,
        manning_n: GLASS_MANNING_N,
    };
    let walls = c.steady(Q_2, WIDTH).level_m(0.5);
    assert!(walls > bed_only + 0.001, "{walls} {bed_only}");
    // Walls as rough as the bed: the composite n is the bed's and only R changes.
    c.side_walls = SideWalls::Glass {
        width_m: WIDTH,
        manning_n: n,
    };
    let r_only = c.steady(Q_2, WIDTH).level_m(0.5);
    assert!(r_only > walls);
}

#[test]
fn the_generated_geometry_sits_on_the_lattice() {
    let mut case = crate::Case::from_path(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../launch_configs/ulbra_flume.yaml"
    )))
    .expect("the bundled case");
    let nominal = Channel::from_case(&case).expect("a flume");
    assert_eq!(nominal.bed_m, 0.055);
    assert_eq!(nominal.x_bed_end_m, 2.23, "the sill ends the bed");
    assert_eq!(nominal.weir.crest_m, 0.055);
    // The end wall's first column is the domain's end rounded to the lattice: 2.50, 2.499
    // (357 x 7 mm) and 2.50 m.
    let cases = [
        (0.01, 0.055, 2.235, 2.495),
        (0.007, 0.0525, 2.2295, 2.4955),
        (0.004, 0.054, 2.230, 2.498),
    ];
    for (dp, bed, end, weir) in cases {
        case.numerics.dp_m = dp;
        let c = Channel::as_generated(&case).expect("a flume");
        assert!((c.bed_m - bed).abs() < 1e-9, "dp {dp}: bed {}", c.bed_m);
        assert!(
            (c.weir.crest_m - bed).abs() < 1e-9,
            "dp {dp}: crest {}",
            c.weir.crest_m
        );
        assert!(
            (c.x_bed_end_m - end).abs() < 1e-9,
            "dp {dp}: end {}",
            c.x_bed_end_m
        );
        assert!(
            (c.weir.x_m - weir).abs() < 1e-9,
            "dp {dp}: weir {}",
            c.weir.x_m
        );
        assert!((c.weir.floor_m - dp / 2.0).abs() < 1e-9);
        assert!((c.weir.length_m - 3.0 * dp).abs() < 1e-12);
    }
}

/// Hand check of `kappa u* h / 6` on a bed 1 cm long, whose depth is the one over the bed's end
/// (23.3 mm under the expanded pit at 2 m3/h, above): V = 0.2773 m/s, Manning's
/// Sf = n^2 V^2 / h^(4/3) = 2.747e-3 for n = 0.01542 (ks = 1.2 mm), u* = sqrt(g h Sf) =
/// 0.02506 m/s, nu_t = 0.41 x 0.02506 x 0.0233 / 6 = 3.99e-5 m2/s: 40 times water's.
#[test]
fn the_flows_eddy_viscosity_by_hand() {
    let c = Channel {
        x_inlet_m: 2.22,
        ..ulbra(strickler_n(0.0012))
    };
    let nu_t = c.eddy_viscosity_m2_per_s(Q_2, WIDTH);
    assert!((nu_t / 3.99e-5 - 1.0).abs() < 0.01, "{nu_t}");
}

/// The pit's limit follows its length against 7 step heights (Eaton & Johnston 1981): the
/// bundled flume's 27 cm behind a 5.5 cm step is crossed by the current, a pit 88 cm long is
/// not (the two pits `bench --levels` was run on; see the README's levels section).
#[test]
fn the_pits_length_chooses_its_limit() {
    let mut case = crate::Case::from_path(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../launch_configs/ulbra_flume.yaml"
    )))
    .expect("the bundled case");
    for dp in [0.01, 0.004] {
        case.numerics.dp_m = dp;
        let c = Channel::as_generated(&case).expect("a flume");
        assert_eq!(c.pit, PitFlow::Carried, "dp {dp}");
    }
    assert_eq!(
        Channel::from_case(&case).expect("a flume").pit,
        PitFlow::Carried
    );
    case.domain.max_m[0] = 2.23 + 0.88;
    assert_eq!(
        Channel::from_case(&case).expect("a flume").pit,
        PitFlow::Expanded
    );
}

/// The pit filled at the start (`bench --levels --filled-pit`) at dp = 1 cm: the sand bed is
/// generated as before, particle for particle, and the new water lies in the pit alone, on
/// the lattice points from the bed's end (2.23 m) to the weir's face and from the floor to the
/// crest (0.055 m): x = 2.24-2.49 m (the weir's first column of walls is at 2.50) and y =
/// 0.01-0.05 m (the floor's top row is at 0), 26 x 5 = 130 particles.
#[test]
fn a_filled_pit_adds_still_water_in_the_pit_alone() {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../launch_configs/ulbra_flume.yaml"
    ));
    let dp = ["numerics.dp_m=0.01".to_string()];
    let dry = crate::Case::from_path_with(path, &dp).expect("the bundled case");
    let mut set = dp.to_vec();
    set.push(super::filled_pit_override(&dry).expect("a pit to fill"));
    let filled = crate::Case::from_path_with(path, &set).expect("the case, its pit filled");
    let of_phase = |case: &crate::Case, code: u32| {
        let p = crate::generate(case, &crate::derived::derive(case));
        let at: Vec<[f32; 4]> = (0..p.len())
            .filter(|&i| p.phase(i) == code)
            .map(|i| p.positions[i])
            .collect();
        at
    };
    // Phase codes: 0 walls, 1 water, 2 sand.
    assert_eq!(
        of_phase(&dry, 2),
        of_phase(&filled, 2),
        "the sand bed moved"
    );
    let (before, after) = (of_phase(&dry, 1), of_phase(&filled, 1));
    let new: Vec<&[f32; 4]> = after.iter().filter(|p| !before.contains(p)).collect();
    assert_eq!(new.len(), 130, "{new:?}");
    for p in new {
        let inside = p[0] > 2.235 && p[0] < 2.495 && p[1] > 0.005 && p[1] < 0.055;
        assert!(inside, "water outside the pit at {p:?}");
    }
}
