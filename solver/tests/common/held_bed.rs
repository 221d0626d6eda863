//! The held bed standing as a wall (the Shields-only mode under the generalised wall condition,
//! `flume_solver::physics::boundary`), for any backend: two Verlet steps of a sand bed in
//! motion under water against the oracle, whose force pass takes each step's held sand as walls
//! (`interaction::interact_with_bed_walls`) and whose integrator gives them the density that
//! pass gave (`integrate::bed_wall`).

use super::sand_stages::{
    TwoSteps, sediment_in_motion, shields_only_case, two_steps_of_sand_in_motion,
};
use super::stages::assert_step_close;
use flume_solver::Backend;
use flume_solver::config::BoundaryMethod;
use flume_solver::physics::sediment::{pass, stress};
use flume_solver::physics::{integrate, interaction};

pub fn check_verlet_steps_with_held_bed_walls(backend: &Backend) {
    let mut c = shields_only_case();
    c.numerics.boundary = BoundaryMethod::Generalised;
    let TwoSteps {
        particles,
        params,
        model,
        after,
        dt,
        dt2,
    } = two_steps_of_sand_in_motion(backend, &c, 53, |p| water_against_the_bed(p, &c));

    let n = particles.len();
    let forces = |pos: &[[f32; 4]], vel: &[[f32; 4]], held_before: &[bool]| {
        let r = pass::rheology_pass(&params, &model, pos, vel, held_before);
        let held: Vec<bool> = r.iter().map(|r| r.held).collect();
        let mut f = interaction::interact_with_bed_walls(&params, pos, vel, &held).forces;
        for (f, s) in f.iter_mut().zip(stress::stress_divergence_with_bed_walls(
            &params, pos, vel, &r, &held,
        )) {
            for k in 0..3 {
                f[k] += s[k];
            }
        }
        (f, held)
    };
    // The holds of the step from `pos`, `vel` under forces `f`, the held bed a wall, and the
    // case's clamp on free particles' densities.
    let walls = |(pos, vel): (&[[f32; 4]], &[[f32; 4]]),
                 f: &[[f32; 4]],
                 held: &[bool],
                 s: &mut integrate::VerletState| {
        let phases = &params.phases;
        integrate::hold_at_rest(phases, params.clamp_negative_pressure, pos, vel, held, s);
        for i in 0..n {
            let phase = &phases[pos[i][3].to_bits() as usize];
            if held[i] {
                s.1[i][3] = integrate::bed_wall(phase, &pos[i], &f[i]).1[3];
            } else if phase.mobile && params.clamp_negative_pressure {
                // No tension: a free particle's density stays at or above rest.
                s.1[i][3] = s.1[i][3].max(phase.rho0);
            }
        }
    };
    let (pos0, vel0) = (&particles.positions, &particles.vel_rho);
    let (f0, held1) = forces(pos0, vel0, &vec![false; n]);
    let mut s1 = integrate::verlet(&params.phases, dt, 0.0, true, pos0, vel0, vel0, &f0);
    walls((pos0, vel0), &f0, &held1, &mut s1);
    let (f1, held2) = forces(&s1.0, &s1.1, &held1);
    let mut s2 = integrate::verlet(&params.phases, dt2, dt, false, &s1.0, &s1.1, &s1.2, &f1);
    walls((&s1.0, &s1.1), &f1, &held2, &mut s2);
    assert_step_close(&after, &s2.0, &s2.1, &[&f0, &f1], dt, 2.0);
    // Not vacuous: sand held in both steps that stands under water takes the water's pressure,
    // a density above rest.
    let pressed = (0..n)
        .filter(|&i| held1[i] && held2[i])
        .filter(|&i| s2.1[i][3] > params.phases[pos0[i][3].to_bits() as usize].rho0)
        .count();
    eprintln!(
        "held {} then {}; {pressed} held in both take the water's pressure",
        held1.iter().filter(|&&h| h).count(),
        held2.iter().filter(|&&h| h).count()
    );
    assert!(pressed > 0, "no held sand takes the water's pressure");
    // And the held bed's contact force is exercised: water within its reach (0.6 dp) of held
    // sand at the start (`water_against_the_bed`).
    let dp = c.numerics.dp_m as f32;
    let close = (0..n)
        .filter(|&i| particles.phase(i) == 1)
        .flat_map(|i| (0..n).filter(|&j| held1[j]).map(move |j| (i, j)))
        .filter(|&(i, j)| {
            let (a, b) = (pos0[i], pos0[j]);
            (a[0] - b[0]).hypot(a[1] - b[1]) < interaction::CONTACT_REACH * dp
        })
        .count();
    assert!(
        close > 0,
        "no water close enough to the held bed to feel its contact force"
    );
}

/// The symplectic integrator's branches for the held bed (the predictor's and the corrector's,
/// `symplectic_predictor.wgsl` and `symplectic_corrector.wgsl`) on `backend` against the CPU
/// backend's (which the Verlet check above holds to the oracle): two steps of the same state,
/// positions within 1e-7 m, velocities within 1e-5 m/s and densities within 1e-3 kg/m3 (f32
/// sums in another order; the steps move particles by about 1e-5 m). Sand held from the start
/// (the bed at rest) stands still and takes the water's pressure on both; sand held later
/// moved before its hold.
pub fn check_symplectic_steps_with_held_bed_walls(backend: &Backend) {
    let mut c = shields_only_case();
    c.numerics.boundary = BoundaryMethod::Generalised;
    c.numerics.integrator = flume_solver::config::Integrator::Symplectic;
    let run = |backend: &Backend| {
        let (mut sim, particles, _) =
            sediment_in_motion(backend, &c, 31, |p| water_against_the_bed(p, &c));
        sim.advance_to(2.0e-5).expect("step 1");
        sim.advance_to(3.5e-5).expect("step 2");
        assert_eq!(sim.steps(), 2);
        let regions = sim.regions().expect("regions");
        (particles, sim.read_particles().expect("readback"), regions)
    };
    let (start, cpu, cpu_regions) = run(&Backend::cpu(2));
    let (_, other, other_regions) = run(backend);
    assert_eq!(cpu_regions, other_regions, "the holds differ");
    let mut pressed = 0;
    for (i, &word) in cpu_regions.iter().enumerate().take(start.len()) {
        let (a, b) = (&cpu, &other);
        for k in 0..2 {
            let dx = (a.positions[i][k] - b.positions[i][k]).abs();
            assert!(dx <= 1e-7, "particle {i} position[{k}]: {dx:.1e} apart");
            let dv = (a.vel_rho[i][k] - b.vel_rho[i][k]).abs();
            assert!(dv <= 1e-5, "particle {i} velocity[{k}]: {dv:.1e} apart");
        }
        let drho = (a.vel_rho[i][3] - b.vel_rho[i][3]).abs();
        assert!(drho <= 1e-3, "particle {i} density: {drho:.1e} apart");
        let held = word & pass::REGION_HELD != 0;
        if held && start.vel_rho[i][..3] == [0.0; 3] {
            assert_eq!(
                b.positions[i], start.positions[i],
                "held particle {i} moved"
            );
            pressed += usize::from(b.vel_rho[i][3] > 2710.0);
        }
    }
    assert!(pressed > 0, "no held sand takes the water's pressure");
}

/// Turns the moving sand particle nearest to the sand at rest (which the first rheology pass
/// holds) into water at rest (so that Shields does not release that sand) and at rest density,
/// and moves it to half a dp from that sand particle, so
/// that water stands within the held bed's contact reach (`interaction::CONTACT_REACH`, 0.6
/// dp) in the checks, as water does that a pick-up's hole let into the bed. The lattice's
/// perturbation alone brings water that close only by chance.
fn water_against_the_bed(p: &mut flume_solver::Particles, c: &flume_solver::config::Case) {
    let (sand_k, water_k) = c.sediment_phases().expect("a sand bed under water");
    // Case phase k is the particles' phase k + 1 (0: walls).
    let (sand_phase, water_phase) = (sand_k as u32 + 1, water_k as u32 + 1);
    let at_rest = |p: &flume_solver::Particles, i: usize| p.vel_rho[i][..3] == [0.0; 3];
    let sand: Vec<usize> = (0..p.len()).filter(|&i| p.phase(i) == sand_phase).collect();
    let gap = |i: usize, j: usize| {
        let (a, b) = (p.positions[i], p.positions[j]);
        (a[0] - b[0]).hypot(a[1] - b[1])
    };
    let nearest = sand
        .iter()
        .filter(|&&i| !at_rest(p, i))
        .flat_map(|&i| {
            sand.iter()
                .filter(|&&j| at_rest(p, j))
                .map(move |&j| (i, j))
        })
        .min_by(|&(a, b), &(c, d)| gap(a, b).total_cmp(&gap(c, d)))
        .expect("moving sand over sand at rest");
    let (i, j) = nearest;
    let scale = 0.5 * c.numerics.dp_m as f32 / gap(i, j);
    for k in 0..2 {
        p.positions[i][k] = p.positions[j][k] + (p.positions[i][k] - p.positions[j][k]) * scale;
    }
    p.positions[i][3] = f32::from_bits(water_phase);
    p.vel_rho[i] = [0.0, 0.0, 0.0, c.phases[water_k].rho0_kg_per_m3 as f32];
}
