//! Case files: every shipped case parses, generation matches the documented counts, and a
//! malformed file fails with an error naming the field and the reason. No GPU needed.

use flume_solver::generate::count;
use flume_solver::particles::{Parking, WALL_PHASE, parked_phase};
use flume_solver::{Case, ConfigError};
use flume_solver::{derive, generate};
use std::path::Path;

fn launch_config(name: &str) -> Case {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../launch_configs")
        .join(name);
    Case::from_path(&path).unwrap_or_else(|e| panic!("{e}"))
}

const DAMBREAK: &str = include_str!("../../launch_configs/dambreak_water.yaml");

fn refused(text: &str) -> (String, String) {
    match Case::from_yaml(text, "test.yaml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(ConfigError::Parse { field, reason, .. })
        | Err(ConfigError::Invalid { field, reason, .. }) => (field, reason),
        Err(e) => panic!("unexpected error {e}"),
    }
}

#[test]
fn every_shipped_case_parses() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../launch_configs");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("launch_configs") {
        let path = entry.expect("entry").path();
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        // ROS parameter files (`*.params.yaml`) live beside the cases.
        if name.ends_with(".yaml") && !name.ends_with(".params.yaml") {
            Case::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 2);
}

#[test]
fn dualsphysics_dambreak_copy_has_its_particle_counts() {
    let c = launch_config("dsph_dambreak_val2d.yaml");
    let d = derive(&c);
    let p = generate(&c, &d);
    let walls = (0..p.len()).filter(|&i| p.phase(i) == WALL_PHASE).count();
    assert_eq!(p.len(), 21_001);
    assert_eq!(walls, 1_001);
    assert_eq!(count(&c), 21_001);
    // h = sqrt(2) dp and c0 = 20 sqrt(g 2 m), as DualSPHysics computes them.
    assert!((d.h - 2f64.sqrt() * 0.01).abs() < 1e-12);
    assert!((d.c0 - 20.0 * (9.81f64 * 2.0).sqrt()).abs() < 1e-9);
    // Every particle on the dp lattice, ids in order.
    assert!(p.ids.iter().enumerate().all(|(i, id)| *id as usize == i));
}

#[test]
fn count_matches_generate_for_every_case() {
    for name in ["dambreak_water.yaml", "dsph_dambreak_val2d.yaml"] {
        let c = launch_config(name);
        assert_eq!(
            count(&c) as usize,
            generate(&c, &derive(&c)).len(),
            "{name}"
        );
    }
    for name in ["hydrostatic_2d.yaml", "hydrostatic_3d.yaml"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/cases")
            .join(name);
        let c = Case::from_path(&path).expect("parses");
        assert_eq!(
            count(&c) as usize,
            generate(&c, &derive(&c)).len(),
            "{name}"
        );
    }
}

#[test]
fn initial_density_is_hydrostatic() {
    let c = launch_config("dambreak_water.yaml");
    let d = derive(&c);
    let p = generate(&c, &d);
    let b = d.c0 * d.c0 * 1000.0 / 7.0;
    for i in 0..p.len() {
        let depth = (0.2 - f64::from(p.positions[i][1])).max(0.0);
        let under_column = f64::from(p.positions[i][0]) <= 0.1 + 2.0 * c.numerics.dp_m;
        let expected = if p.phase(i) != WALL_PHASE || under_column {
            1000.0 * (1.0 + 1000.0 * 9.81 * depth / b).powf(1.0 / 7.0)
        } else {
            1000.0
        };
        assert!(
            (f64::from(p.vel_rho[i][3]) - expected).abs() < 1e-3,
            "particle {i}: {:?}",
            p.vel_rho[i]
        );
    }
}

#[test]
fn unknown_field_is_refused_by_name() {
    let text = DAMBREAK.replace("  cfl: 0.2\n", "  cfl: 0.2\n  cfll: 0.3\n");
    let (field, reason) = refused(&text);
    assert_eq!(field, "numerics.cfll");
    assert!(reason.contains("unknown field `cfll`"), "{reason}");
}

#[test]
fn invalid_values_are_refused_with_field_and_reason() {
    let cases = [
        (
            "  dp_m: 0.0025\n",
            "  dp_m: -0.0025\n",
            "numerics.dp_m",
            "positive",
        ),
        ("  cfl: 0.2\n", "  cfl: 1.5\n", "numerics.cfl", "(0, 1]"),
        ("dimension: 2\n", "dimension: 4\n", "dimension", "2 or 3"),
        (
            "  - phase: water\n",
            "  - phase: sand\n",
            "fluid_blocks[0].phase",
            "no phase named `sand`",
        ),
        (
            "  sound_speed: { coefsound: 20.0 }\n",
            "  sound_speed: { coefsound: 20.0, c0_m_per_s: 30.0 }\n",
            "numerics.sound_speed",
            "exactly one",
        ),
        (
            "    - { name: mid_tank, position_m: [0.3] }\n",
            "    - { name: mid_tank, position_m: [0.9] }\n",
            "observations.gauges[1].position_m",
            "inside the domain",
        ),
        (
            "gravity_m_per_s2: [0.0, -9.81]\n",
            "gravity_m_per_s2: [0.0, 9.81]\n",
            "gravity_m_per_s2",
            "down",
        ),
        (
            "    max_m: [0.1, 0.2]\n",
            "    max_m: [0.1, 0.5]\n",
            "fluid_blocks[0]",
            "inside the domain",
        ),
    ];
    for (from, to, field, reason_part) in cases {
        assert!(DAMBREAK.contains(from), "test text out of date: {from}");
        let (f, r) = refused(&DAMBREAK.replace(from, to));
        assert_eq!(f, field, "for {to:?}: {r}");
        assert!(r.contains(reason_part), "for {to:?}: {r}");
    }
}

#[test]
fn wrong_types_and_missing_fields_are_named() {
    let (f, r) = refused(&DAMBREAK.replace("  dp_m: 0.0025\n", "  dp_m: fine\n"));
    assert_eq!(f, "numerics.dp_m");
    assert!(r.contains("invalid type"), "{r}");
    let (f, r) = refused(&DAMBREAK.replace("  dp_m: 0.0025\n", ""));
    assert_eq!(f, "numerics");
    assert!(r.contains("missing field `dp_m`"), "{r}");
    let (f, r) = refused(&DAMBREAK.replace(
        "method: artificial, alpha: 0.02",
        "method: sps, alpha: 0.02",
    ));
    assert!(f.starts_with("numerics.viscosity"), "{f}");
    assert!(r.contains("unknown variant `sps`"), "{r}");
}

const ULBRA: &str = include_str!("../../launch_configs/ulbra_flume.yaml");

#[test]
fn sediment_and_open_flume_values_are_refused_with_field_and_reason() {
    for (from, to, field, reason) in [
        (
            "friction_angle_deg: 32.0",
            "friction_angle_deg: 95.0",
            "phases[1].sediment.friction_angle_deg",
            "between 0 and 90",
        ),
        (
            "d50_m: 0.0004",
            "d50_m: -0.0004",
            "phases[1].sediment.d50_m",
            "positive",
        ),
        (
            "viscosity: { method: multiphase, alpha: 0.02 }",
            "viscosity: { method: artificial, alpha: 0.02 }",
            "numerics.viscosity.method",
            "multiphase",
        ),
        (
            "viscosity: { method: multiphase, alpha: 0.02 }",
            "viscosity: { method: multiphase, alpha: 0.02, smagorinsky_cs: -0.12 }",
            "numerics.viscosity.smagorinsky_cs",
            "0..=1",
        ),
        (
            "viscosity: { method: multiphase, alpha: 0.02 }",
            "viscosity: { method: multiphase, alpha: 0.02, eddy_m2_per_s: 4.0e-5 }",
            "numerics.viscosity.eddy_m2_per_s",
            "not both",
        ),
        (
            "viscosity: { method: multiphase, alpha: 0.02 }",
            "viscosity: { method: multiphase, eddy_m2_per_s: -4.0e-5 }",
            "numerics.viscosity.eddy_m2_per_s",
            "0..=0.01",
        ),
        (
            "rho0_kg_per_m3: 2710.0",
            "rho0_kg_per_m3: 900.0",
            "phases[1].rho0_kg_per_m3",
            "denser than the water",
        ),
        (
            "height_m: 0.02",
            "height_m: 0.001",
            "open_flume.inlet.height_m",
            "at least dp",
        ),
        (
            "outlet_weir_m: 0.055",
            "outlet_weir_m: 0.5",
            "open_flume.outlet_weir_m",
            "within the domain",
        ),
        (
            "x_min_m: 2.22",
            "x_min_m: 2.2",
            "open_flume.collector.x_min_m",
            "reaches into the collector",
        ),
        (
            "inflow_m3_per_s: 5.5556e-4",
            "inflow_m3_per_s: -1.0",
            "open_flume.inflow_m3_per_s",
            ">= 0",
        ),
        (
            "sill: { x_min_m: 2.2, x_max_m: 2.23 }",
            "sill: { x_min_m: 2.2, x_max_m: 2.201 }",
            "open_flume.sill",
            "at least dp thick",
        ),
        (
            "max_m: [2.2, 0.055]",
            "max_m: [2.2, 0.006]",
            "open_flume.sill",
            "no row under its top",
        ),
        (
            "  - phase: sand\n    min_m: [0.0, 0.0]",
            "  - phase: water\n    min_m: [0.0, 0.0]",
            "open_flume.sill",
            "ends a sediment bed",
        ),
        (
            "ks_over_d50: 3.0",
            "ks_over_d50: 3.0\n      pores: { porosity: 1.4, conductivity_m_per_s: 1.5e-3, suction_m: 0.05 }",
            "phases[1].sediment.pores.porosity",
            "between 0 and 1",
        ),
        (
            "ks_over_d50: 3.0",
            "ks_over_d50: 3.0\n      pores: { porosity: 0.4, conductivity_m_per_s: 0.0, suction_m: 0.05 }",
            "phases[1].sediment.pores.conductivity_m_per_s",
            "positive",
        ),
        (
            "ks_over_d50: 3.0",
            "ks_over_d50: 3.0\n      pores: { porosity: 0.4, conductivity_m_per_s: 1.5e-3, suction_m: -0.05 }",
            "phases[1].sediment.pores.suction_m",
            ">= 0",
        ),
    ] {
        assert!(ULBRA.contains(from), "{from}");
        let (f, r) = refused(&ULBRA.replace(from, to));
        assert_eq!(f, field, "{to}: {r}");
        assert!(r.contains(reason), "{to}: {r}");
    }
}

const FALAPPI: &str = include_str!("../../launch_configs/falappi_flushing.yaml");

#[test]
fn bottom_outlet_values_are_refused_with_field_and_reason() {
    for (to, field, reason) in [
        (
            "bottom_outlet: { x_min_m: 2.0, y_min_m: 0.3, y_max_m: 0.36, velocity_m_s: -0.658 }",
            "open_flume.bottom_outlet.velocity_m_s",
            "positive",
        ),
        (
            "bottom_outlet: { x_min_m: 2.0, y_min_m: 0.3, y_max_m: 0.305, velocity_m_s: 0.658 }",
            "open_flume.bottom_outlet.y_max_m",
            "at least dp",
        ),
        (
            "bottom_outlet: { x_min_m: 2.5, y_min_m: 0.3, y_max_m: 0.36, velocity_m_s: 0.658 }",
            "open_flume.bottom_outlet.x_min_m",
            "inside the flume",
        ),
        // 0.3 c0 = 9 m/s, the inlet's bound.
        (
            "bottom_outlet: { x_min_m: 2.0, y_min_m: 0.3, y_max_m: 0.36, velocity_m_s: 9.5 }",
            "open_flume.bottom_outlet.velocity_m_s",
            "at most 0.3 c0",
        ),
    ] {
        let from =
            "bottom_outlet: { x_min_m: 2.0, y_min_m: 0.3, y_max_m: 0.36, velocity_m_s: 0.658 }";
        assert!(FALAPPI.contains(from));
        let (f, r) = refused(&FALAPPI.replace(from, to));
        assert_eq!(f, field, "{to}: {r}");
        assert!(r.contains(reason), "{to}: {r}");
    }
}

#[test]
fn an_open_flume_parks_its_reservoir_above_the_flow() {
    let c = launch_config("ulbra_flume.yaml");
    let d = derive(&c);
    let p = generate(&c, &d);
    let parked = parked_phase(&c);
    let parking = Parking::new(&c, d.h);
    let f = c.open_flume.as_ref().expect("open flume");
    let mut n = 0;
    for i in 0..p.len() {
        if p.phase(i) != parked {
            continue;
        }
        n += 1;
        // Each at its own spot, by id, and more than 2h above anything that is not parked.
        assert_eq!(p.positions[i][..2], parking.spot(p.ids[i]));
        assert!(f64::from(p.positions[i][1]) >= c.domain.max_m[1] + 2.0 * d.h);
    }
    assert_eq!(n, f.reservoir_particles as usize);
    assert!(count(&c) as usize >= p.len(), "count is an upper bound");
}

/// The sill's top row stands one row under the sand's top row whatever the dp, though the
/// nominal 5.5 cm bed's top row is 0.05 m at dp = 1 cm, 0.049 m at 7 mm and 0.052 m at 4 mm.
#[test]
fn the_sill_crest_stands_a_row_under_the_sand_at_every_dp() {
    for dp in [0.01, 0.007, 0.004] {
        let mut c = launch_config("ulbra_flume.yaml");
        c.numerics.dp_m = dp;
        let p = generate(&c, &derive(&c));
        let top = |phase: u32, x: (f32, f32)| {
            (0..p.len())
                .filter(|&i| p.phase(i) == phase && (x.0..x.1).contains(&p.positions[i][0]))
                .map(|i| f64::from(p.positions[i][1]))
                .fold(f64::MIN, f64::max)
        };
        let sand = top(2, (2.0, 2.2));
        let sill = top(WALL_PHASE, (2.2, 2.23));
        let bed = (0.055 / dp + 1e-6).floor() * dp;
        assert!((sand - bed).abs() < 1e-6, "dp {dp}: sand's top row {sand}");
        assert!(
            (sill - (bed - dp)).abs() < 1e-6,
            "dp {dp}: sill's top row {sill}"
        );
    }
}

#[test]
fn overrides_change_a_case_and_are_validated_like_the_file() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../launch_configs/ulbra_flume.yaml");
    let set = |o: &[&str]| {
        Case::from_path_with(&path, &o.iter().map(|s| s.to_string()).collect::<Vec<_>>())
    };
    let c = set(&[
        "numerics.dp_m=0.01",
        "open_flume.reservoir_particles=2500",
        "phases.1.sediment.ks_over_d50=7",
    ])
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(c.numerics.dp_m, 0.01);
    assert_eq!(
        c.open_flume.as_ref().map(|f| f.reservoir_particles),
        Some(2500)
    );
    assert_eq!(
        c.phases[1].sediment.as_ref().map(|s| s.ks_over_d50),
        Some(7.0)
    );
    assert_eq!(
        c.name,
        launch_config("ulbra_flume.yaml").name,
        "the rest is the file's"
    );
    for (bad, field, reason) in [
        ("numerics.dp_m=-1", "numerics.dp_m", "positive"),
        ("numerics.dpm=0.01", "numerics", "unknown field `dpm`"),
        (
            "phases.7.name=x",
            "phases.7.name",
            "index 7 past the list's 2 items",
        ),
        ("nowhere.dp_m=1", "nowhere.dp_m", "no section nowhere"),
        ("numerics.dp_m", "numerics.dp_m", "key=value"),
    ] {
        match set(&[bad]) {
            Err(ConfigError::Invalid {
                field: f,
                reason: r,
                ..
            })
            | Err(ConfigError::Parse {
                field: f,
                reason: r,
                ..
            }) => {
                assert!(
                    f.starts_with(field) && r.contains(reason),
                    "{bad}: {f}: {r}"
                );
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
}

/// Whether the held bed stands as a wall is said twice, by the case (the bed-contact check's
/// felt factor) and by the uniform both engines read (`SimParams::held_bed_is_wall`, as
/// `params.wgsl`): the two agree on the flume under each boundary and release, and on
/// Louvain's Drucker-Prager bed under the generalised walls.
#[test]
fn the_case_and_the_uniform_agree_on_a_held_bed_standing_as_a_wall() {
    let variants: [(&str, &[&str], bool); 4] = [
        ("ulbra_flume.yaml", &[], false),
        (
            "ulbra_flume.yaml",
            &["numerics.boundary={method: generalised}"],
            true,
        ),
        (
            "ulbra_flume.yaml",
            &[
                "numerics.boundary={method: generalised}",
                "phases.1.sediment.erosion=van_rijn_pickup",
            ],
            true,
        ),
        (
            "louvain_dambreak.yaml",
            &["numerics.boundary={method: generalised}"],
            false,
        ),
    ];
    for (name, set, want) in variants {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../launch_configs")
            .join(name);
        let mut set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        set.push("numerics.dp_m=0.02".to_string());
        let case = Case::from_path_with(&path, &set).unwrap_or_else(|e| panic!("{e}"));
        let sim = flume_solver::Simulation::new(flume_solver::Backend::cpu(1), &case)
            .unwrap_or_else(|e| panic!("{name} {set:?}: {e}"));
        assert_eq!(case.held_bed_is_wall(), want, "{name} {set:?}");
        assert_eq!(sim.params().held_bed_is_wall(), want, "{name} {set:?}");
    }
}

/// The bundled flume at dp = 2 cm with `set`, built on the CPU backend, and the CPU
/// backend's sediment model of it.
fn flume_with(
    set: &[&str],
) -> (
    flume_solver::Simulation,
    flume_solver::physics::sediment::pass::SedimentModel,
) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../launch_configs/ulbra_flume.yaml");
    let mut set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    set.push("numerics.dp_m=0.02".to_string());
    let case = Case::from_path_with(&path, &set).unwrap_or_else(|e| panic!("{e}"));
    let sim = flume_solver::Simulation::new(flume_solver::Backend::cpu(1), &case)
        .unwrap_or_else(|e| panic!("{set:?}: {e}"));
    let model = flume_solver::contract::sediment_model(&case, sim.derived()).expect("sand");
    (sim, model)
}

#[test]
fn the_erosion_reaches_both_backends_and_a_wrong_one_is_named() {
    for (erosion, rate, integrated) in [
        ("threshold", false, 0),
        ("van_rijn_pickup", true, 0),
        ("van_rijn_integrated", true, 1),
        ("van_rijn_exner", true, 1),
    ] {
        let (sim, model) = flume_with(&[&format!("phases.1.sediment.erosion={erosion}")]);
        let block = sim.params().sediment;
        assert_eq!(block.pickup_per_s > 0.0, rate, "{erosion}");
        assert_eq!(block.pickup_integrated, integrated, "{erosion}");
        assert_eq!(model.pickup_integrated, integrated == 1, "{erosion}");
        // The saltation length over dp = 2 cm (pickup.rs: 4.8456e-3 m): Exner's only.
        let step = if erosion == "van_rijn_exner" {
            0.242_28
        } else {
            0.0
        };
        assert!(
            (model.exner_step_per_stage - step).abs() < 1e-5,
            "{erosion}: {model:?}"
        );
    }
    let (f, r) = refused(&ULBRA.replace(
        "      criterion: shields_only\n",
        "      criterion: shields_only\n      erosion: van_rijn_worn\n",
    ));
    assert!(f.starts_with("phases"), "{f}: {r}");
    assert!(r.contains("van_rijn_integrated"), "{f}: {r}");
}

#[test]
fn the_shields_speed_reaches_both_backends_and_a_wrong_one_is_named() {
    for (set, want) in [
        (vec![], 0),
        (vec!["phases.1.sediment.shields_speed=relative_to_grain"], 0),
        (vec!["phases.1.sediment.shields_speed=water"], 1),
    ] {
        let (sim, model) = flume_with(&set);
        assert_eq!(sim.params().sediment.water_speed, want, "{set:?}");
        assert_eq!(model.water_speed, want == 1, "{set:?}");
    }
    let (f, r) = refused(&ULBRA.replace(
        "      criterion: shields_only\n",
        "      criterion: shields_only\n      shields_speed: grain\n",
    ));
    assert!(f.starts_with("phases"), "{f}: {r}");
    assert!(r.contains("unknown variant `grain`"), "{r}");
    assert!(
        r.contains("relative_to_grain") && r.contains("water"),
        "{r}"
    );
}

#[test]
fn where_a_grain_comes_to_rest_reaches_both_backends_and_a_wrong_one_is_named() {
    for (set, want) in [
        (vec![], 0),
        (vec!["phases.1.sediment.comes_to_rest=anywhere"], 0),
        (vec!["phases.1.sediment.comes_to_rest=beside_a_solid"], 1),
    ] {
        let (sim, model) = flume_with(&set);
        assert_eq!(sim.params().sediment.rests_beside_solid, want, "{set:?}");
        assert_eq!(model.rests_beside_solid, want == 1, "{set:?}");
    }
    let (f, r) = refused(&ULBRA.replace(
        "      criterion: shields_only\n",
        "      criterion: shields_only\n      comes_to_rest: in_a_row\n",
    ));
    assert!(f.starts_with("phases"), "{f}: {r}");
    assert!(r.contains("unknown variant `in_a_row`"), "{r}");
    assert!(
        r.contains("anywhere") && r.contains("beside_a_solid"),
        "{r}"
    );
}

/// The water the pores take is parked, and only an open flume parks: a closed tank's bed with
/// pores is refused by name, not run without them.
#[test]
fn pores_need_an_open_flume() {
    let tank = include_str!("cases/sediment_bed_2d.yaml");
    let from = "ks_over_d50: 3.0";
    assert!(tank.contains(from));
    let to = "ks_over_d50: 3.0\n      pores: { porosity: 0.4, conductivity_m_per_s: 1.5e-3, suction_m: 0.05 }";
    let (f, r) = refused(&tank.replace(from, to));
    assert_eq!(f, "phases[1].sediment.pores");
    assert!(r.contains("open flume"), "{r}");
}
