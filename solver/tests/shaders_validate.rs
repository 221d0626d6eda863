//! Tier 1, no GPU needed: every stage composes, naga validates it, its declared bindings and
//! workgroup size match the WGSL, and the Rust mirrors of WGSL structs have naga's layout.

use flume_solver::contract::{
    ExcludedParticle, Extremes, FlumeGpu, InletQuery, PhaseParams, ScanInfo, SedimentGpu,
    SimParams, StepState,
};
use flume_solver::gpu::stage::Access;
use flume_solver::gpu::stages::ALL;
use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::mem::offset_of;

fn parse(stage_name: &str, src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{stage_name}: {}", e.emit_to_string(src)))
}

#[test]
fn every_stage_composes_and_validates() {
    for spec in ALL {
        let src = spec.source();
        let module = parse(spec.name, &src);
        Validator::new(ValidationFlags::all(), Capabilities::empty())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}: {}", spec.name, e.emit_to_string(&src)));
    }
}

#[test]
fn declared_bindings_match_the_wgsl_globals() {
    for spec in ALL {
        let module = parse(spec.name, &spec.source());
        let mut found: Vec<(String, u32, Access)> = module
            .global_variables
            .iter()
            .filter_map(|(_, g)| {
                let b = g.binding.as_ref()?;
                assert_eq!(b.group, 0, "{}: only group 0 is used", spec.name);
                let access = match g.space {
                    naga::AddressSpace::Uniform => Access::Uniform,
                    naga::AddressSpace::Storage { access }
                        if access.contains(naga::StorageAccess::STORE) =>
                    {
                        Access::ReadWrite
                    }
                    naga::AddressSpace::Storage { .. } => Access::Read,
                    naga::AddressSpace::Handle => match &module.types[g.ty].inner {
                        naga::TypeInner::Image {
                            class:
                                naga::ImageClass::Sampled {
                                    kind: naga::ScalarKind::Float,
                                    multi: false,
                                },
                            dim: naga::ImageDimension::D2,
                            arrayed: false,
                        } => Access::Texture,
                        naga::TypeInner::Image {
                            class:
                                naga::ImageClass::Storage {
                                    format: naga::StorageFormat::Rgba32Float,
                                    access,
                                },
                            dim: naga::ImageDimension::D2,
                            arrayed: false,
                        } if *access == naga::StorageAccess::STORE => Access::TextureWrite,
                        other => panic!("{}: unexpected handle type {other:?}", spec.name),
                    },
                    other => panic!("{}: unexpected address space {other:?}", spec.name),
                };
                Some((g.name.clone().unwrap_or_default(), b.binding, access))
            })
            .collect();
        found.sort_by_key(|b| b.1);
        let declared: Vec<(String, u32, Access)> = spec
            .bindings
            .iter()
            .map(|(n, i, a)| (n.to_string(), *i, *a))
            .collect();
        assert_eq!(found, declared, "stage {}", spec.name);
    }
}

#[test]
fn entry_points_and_workgroup_sizes_match() {
    for spec in ALL {
        let module = parse(spec.name, &spec.source());
        let names: Vec<&str> = module
            .entry_points
            .iter()
            .map(|e| e.name.as_str())
            .collect();
        assert_eq!(names, spec.entry_points, "stage {}", spec.name);
        for e in &module.entry_points {
            assert_eq!(
                e.workgroup_size,
                [spec.workgroup, 1, 1],
                "stage {} entry {}",
                spec.name,
                e.name
            );
        }
        assert!(
            spec.entry_points.contains(&spec.name) || spec.entry_points.len() > 1,
            "a single-entry stage is named after its entry point: {}",
            spec.name
        );
    }
}

/// The literal a WGSL constant of `stage`'s composed module is initialised with.
fn wgsl_constant(stage: &str, name: &str) -> naga::Literal {
    let spec = ALL
        .iter()
        .find(|s| s.name == stage)
        .unwrap_or_else(|| panic!("no stage {stage}"));
    let module = parse(stage, &spec.source());
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL constant {name} in {stage}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(v) => v,
        ref other => panic!("{name} is not a literal: {other:?}"),
    }
}

/// Every constant that the WGSL and the Rust each state, by value, from the composed module of
/// a stage that uses it: one side changed alone fails here. (`HUGE`, WGSL's stand-in for an
/// infinite viscosity, has no Rust twin.)
#[test]
fn every_constant_stated_on_both_sides_agrees() {
    use flume_solver::contract as c;
    use flume_solver::physics::sediment::{hold, pass, pickup, rheology, shields, suspension};
    use flume_solver::{Health, Region};
    use naga::Literal::{F32, I32, U32};
    let region = |r: Region| U32(r as u32);
    let checks = [
        (
            "interaction",
            "TEXEL_ROW_SHIFT",
            U32(flume_solver::gpu::state::TEXEL_ROW_SHIFT),
        ),
        (
            "interaction",
            "VISCOSITY_MULTIPHASE",
            U32(c::VISCOSITY_MULTIPHASE),
        ),
        (
            "interaction",
            "BOUNDARY_GENERALISED",
            U32(c::BOUNDARY_GENERALISED),
        ),
        (
            "prefix_sum",
            "BLOCK",
            U32(flume_solver::gpu::stages::PREFIX_SUM_BLOCK),
        ),
        (
            "dt_update",
            "EXCLUDED_LOG_LEN",
            U32(c::EXCLUDED_LOG_LEN as u32),
        ),
        ("dt_update", "STATUS_NON_FINITE", U32(Health::NON_FINITE)),
        (
            "dt_update",
            "STATUS_DENSITY_RUNAWAY",
            U32(Health::DENSITY_RUNAWAY),
        ),
        ("dt_update", "STATUS_DT_COLLAPSE", U32(Health::DT_COLLAPSE)),
        ("hold", "FLOW_ONSET", F32(hold::FLOW_ONSET)),
        (
            "interaction",
            "CONTACT_REACH",
            F32(flume_solver::physics::interaction::CONTACT_REACH),
        ),
        ("rheology", "KARMAN", F32(shields::KARMAN)),
        (
            "rheology",
            "SUBLAYER_WALL_UNITS",
            F32(shields::SUBLAYER_WALL_UNITS),
        ),
        ("rheology", "SMOOTH_RE_K", F32(shields::SMOOTH_RE_K)),
        ("rheology", "ROUGH_RE_K", F32(shields::ROUGH_RE_K)),
        ("rheology", "Z0_SMOOTH", F32(shields::Z0_SMOOTH)),
        ("rheology", "Z0_ROUGH", F32(shields::Z0_ROUGH)),
        (
            "rheology",
            "BISECTION_REL_TOL",
            F32(shields::BISECTION_REL_TOL),
        ),
        (
            "rheology",
            "FRICTION_VELOCITY_MAX_ITERATIONS",
            U32(shields::FRICTION_VELOCITY_MAX_ITERATIONS),
        ),
        (
            "rheology",
            "PAPANASTASIOU_SERIES_LIMIT",
            F32(rheology::PAPANASTASIOU_SERIES_LIMIT),
        ),
        (
            "rheology",
            "SUSPENSION_CONCENTRATION",
            F32(suspension::SUSPENSION_CONCENTRATION),
        ),
        ("rheology", "REGION_UNYIELDED", region(Region::Unyielded)),
        ("rheology", "REGION_YIELDED", region(Region::Yielded)),
        ("rheology", "REGION_BED_LOAD", region(Region::BedLoad)),
        ("rheology", "REGION_SUSPENDED", region(Region::Suspended)),
        ("rheology", "REGION_WATER", region(Region::Water)),
        ("rheology", "REGION_HELD", U32(pass::REGION_HELD)),
        ("rheology", "PICKUP_SHIFT", U32(pickup::PICKUP_SHIFT)),
        ("rheology", "PICKUP_WHOLE", U32(pickup::PICKUP_WHOLE)),
        ("rheology", "EXNER_WHOLE", U32(pickup::EXNER_WHOLE)),
        ("rheology", "EXNER_SPENT", I32(pickup::EXNER_SPENT)),
        ("rheology", "NO_FLUX", F32(pass::NO_FLUX)),
        ("rheology", "NO_TARGET", U32(pass::NO_TARGET)),
        (
            "symplectic_predictor",
            "REGION_HELD_BIT",
            U32(pass::REGION_HELD),
        ),
        ("verlet_update", "REGION_HELD_BIT", U32(pass::REGION_HELD)),
        (
            "probe_interpolate",
            "REGION_UNYIELDED_WORD",
            region(Region::Unyielded),
        ),
    ];
    for (stage, name, rust) in checks {
        assert_eq!(wgsl_constant(stage, name), rust, "{name} in {stage}");
    }
}

/// Offsets and size of a named WGSL struct as naga lays it out.
fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32)>, u32) {
    let ty = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL struct {name}"))
        .1;
    match &ty.inner {
        naga::TypeInner::Struct { members, span } => (
            members
                .iter()
                .map(|m| (m.name.clone().unwrap_or_default(), m.offset))
                .collect(),
            *span,
        ),
        other => panic!("{name} is not a struct: {other:?}"),
    }
}

fn find(members: &[(String, u32)], name: &str) -> u32 {
    members
        .iter()
        .find(|m| m.0 == name)
        .unwrap_or_else(|| panic!("no member {name}"))
        .1
}

#[test]
fn rust_mirrors_have_the_wgsl_layout() {
    let forces = ALL
        .iter()
        .find(|s| s.name == "interaction")
        .expect("forces stage");
    let module = parse("interaction", &forces.source());
    let (m, size) = wgsl_layout(&module, "SimParams");
    assert_eq!(size as usize, size_of::<SimParams>());
    macro_rules! same {
        ($ty:ty, $members:expr, $($field:ident),*) => {
            $(assert_eq!(find(&$members, stringify!($field)) as usize, offset_of!($ty, $field), stringify!($field));)*
        };
    }
    same!(
        SimParams,
        m,
        n_particles,
        n_cells,
        viscosity_mode,
        diffusion_mode,
        grid_dims,
        grid_origin,
        gravity,
        h,
        kernel_ad,
        c0,
        eta2,
        delta_h_c0,
        alpha,
        cfl,
        dt_visc,
        dt_min,
        rho_ratio_max,
        vertical_axis,
        n_probes,
        euler_every,
        clamp_pressure,
        phases,
        tait_b,
        sediment,
        flume
    );
    let (m, size) = wgsl_layout(&module, "Flume");
    assert_eq!(size as usize, size_of::<FlumeGpu>());
    same!(
        FlumeGpu,
        m,
        enabled,
        water_phase,
        parked_phase,
        parking_cols,
        inlet_x_face,
        inlet_y_min,
        inlet_y_max,
        inlet_u,
        outlet_x,
        collector_x_min,
        collector_x_max,
        collector_y_max,
        parking_x0,
        parking_y0,
        parking_dp,
        duct_x_min,
        duct_y_min,
        duct_y_max,
        duct_u
    );
    let (m, size) = wgsl_layout(&module, "Sediment");
    assert_eq!(size as usize, size_of::<SedimentGpu>());
    same!(
        SedimentGpu,
        m,
        phase,
        water_phase,
        shields_only,
        rho_s,
        rho_w,
        d50,
        nu_w,
        mu_w,
        mu_s,
        hbp_m,
        hbp_n,
        ks,
        surface_mass,
        dp_alpha,
        dp_kappa,
        phi,
        mu_max,
        submerged_weight,
        water_speed,
        pickup_per_s,
        pickup_integrated,
        exner_step_per_stage,
        dp
    );
    let (m, size) = wgsl_layout(&module, "Phase");
    assert_eq!(size as usize, size_of::<PhaseParams>());
    same!(PhaseParams, m, rho0, mass, mu, mobile);
    let (m, size) = wgsl_layout(&module, "StepState");
    assert_eq!(size as usize, size_of::<StepState>());
    same!(
        StepState,
        m,
        dt,
        t_rel,
        t_target,
        steps,
        dt_min_bits,
        status,
        last_dt,
        step_base,
        dt_prev,
        dt_taken,
        eroded,
        parked,
        excluded,
        excluded_sediment,
        excluded_log
    );
    let (m, size) = wgsl_layout(&module, "ExcludedParticle");
    assert_eq!(size as usize, size_of::<ExcludedParticle>());
    same!(ExcludedParticle, m, id, phase, x, y, u, v, rho);

    let observe = ALL
        .iter()
        .find(|s| s.name == "observe_reduce")
        .expect("observe stage");
    let module = parse("observe_reduce", &observe.source());
    let (m, size) = wgsl_layout(&module, "Extremes");
    assert_eq!(size as usize, size_of::<Extremes>());
    same!(
        Extremes,
        m,
        front_key,
        max_speed_bits,
        max_rho_err_bits,
        fluid_count
    );

    let scan = ALL
        .iter()
        .find(|s| s.name == "prefix_sum")
        .expect("scan stage");
    let (_, size) = wgsl_layout(&parse("prefix_sum", &scan.source()), "ScanInfo");
    assert_eq!(size as usize, size_of::<ScanInfo>());

    let inlet = ALL
        .iter()
        .find(|s| s.name == "inlet_scan")
        .expect("inlet stage");
    let (m, size) = wgsl_layout(&parse("inlet_scan", &inlet.source()), "InletQuery");
    assert_eq!(size as usize, size_of::<InletQuery>());
    same!(InletQuery, m, n_spots, radius2);
}
