//! An open flume's parked particles and its inlet, for any backend (`gpu_vs_reference.rs`,
//! `cpu_vs_reference.rs`): parked particles sort after every cell and take no part in the
//! neighbour passes or the integrators, and the inlet's scan answers what a scan of the whole
//! state would.

use flume_solver::config::Integrator;
use flume_solver::particles::{Particles, WALL_PHASE, parked_phase};
use flume_solver::{Backend, Case, Simulation};

/// The recycling flume (80 parked particles) with the given integrator.
fn flume(integrator: Integrator) -> Case {
    let mut c = super::stages::case("tests/cases/recycle_2d.yaml");
    c.numerics.integrator = integrator;
    c
}

fn sim(backend: &Backend, c: &Case, p: &Particles) -> Simulation {
    Simulation::from_particles(backend.clone(), c, p.clone()).expect("state builds")
}

fn bits(v: &[[f32; 4]]) -> Vec<[u32; 4]> {
    v.iter().map(|x| x.map(f32::to_bits)).collect()
}

/// The same perturbed flume twice, the second with its parked particle of the highest id
/// moved in among the water (still parked): the cell list puts it after every cell, it adds
/// nothing to any force, one step leaves it where it is and every other particle exactly as
/// in the first, and every particle in the flow has moved.
pub fn check_parked_take_no_part(backend: &Backend) {
    for integrator in [
        Integrator::Symplectic,
        Integrator::Verlet {
            euler_every_steps: 40,
        },
    ] {
        let c = flume(integrator);
        let parked = parked_phase(&c);
        let lattice = Simulation::new(backend.clone(), &c).expect("case builds");
        let a = super::perturbed(&lattice, 0.3, 31);
        let stray = (0..a.len())
            .rev()
            .find(|&i| a.phase(i) == parked)
            .expect("a parked particle");
        let mut b = a.clone();
        b.positions[stray][..2].copy_from_slice(&[0.2, 0.04]);
        let (mut sim_a, mut sim_b) = (sim(backend, &c, &a), sim(backend, &c, &b));

        let parked_ids: Vec<u32> = (0..b.len() as u32)
            .filter(|&i| b.phase(i as usize) == parked)
            .collect();
        let active = b.len() - parked_ids.len();
        let (starts, order) = sim_b.cell_list().expect("cell list");
        assert_eq!(starts.last(), Some(&(active as u32)), "active count");
        let mut tail = order[active..].to_vec();
        tail.sort_unstable();
        assert_eq!(tail, parked_ids, "the parked particles after every cell");
        let (_, order_a) = sim_a.cell_list().expect("cell list");
        assert_eq!(
            order_a[..active],
            order[..active],
            "the same cells in the same order"
        );

        let (forces_a, dt_a) = sim_a.compute_forces().expect("forces");
        let (forces_b, dt_b) = sim_b.compute_forces().expect("forces");
        assert_eq!(forces_b[stray], [0.0; 4], "a parked particle feels nothing");
        assert_eq!(
            bits(&forces_a),
            bits(&forces_b),
            "and adds nothing to any sum"
        );
        assert_eq!(dt_a.to_bits(), dt_b.to_bits());

        // Below the stable step: exactly one step of that length.
        let dt = 2.0e-5;
        sim_a.advance_to(dt).expect("one step");
        sim_b.advance_to(dt).expect("one step");
        assert_eq!((sim_a.steps(), sim_b.steps()), (1, 1));
        let after_a = sim_a.read_particles().expect("readback");
        let mut after_b = sim_b.read_particles().expect("readback");
        assert_eq!(
            after_b.positions[stray], b.positions[stray],
            "{integrator:?}"
        );
        assert_eq!(after_b.vel_rho[stray], b.vel_rho[stray], "{integrator:?}");
        after_b.positions[stray] = after_a.positions[stray];
        after_b.vel_rho[stray] = after_a.vel_rho[stray];
        assert_eq!(bits(&after_a.positions), bits(&after_b.positions));
        assert_eq!(bits(&after_a.vel_rho), bits(&after_b.vel_rho));
        for i in 0..a.len() {
            let ph = a.phase(i);
            if ph == parked || ph == WALL_PHASE {
                assert_eq!(after_a.positions[i], a.positions[i], "{integrator:?}: {i}");
            } else {
                assert_ne!(
                    after_a.vel_rho[i], a.vel_rho[i],
                    "{integrator:?}: {i} moved"
                );
            }
        }
    }
}

/// The inlet's scan against `engine::inlet_scan` over the whole state, on a state whose
/// lowest-id parked particles are back in the flow and some low-id water is parked; before and
/// after a step (which reorders the storage), and with more spots than parked particles.
pub fn check_inlet_scan(backend: &Backend) {
    let c = flume(Integrator::default());
    let parked = parked_phase(&c);
    let dp = c.numerics.dp_m as f32;
    let lattice = Simulation::new(backend.clone(), &c).expect("case builds");
    let mut p = lattice.initial_particles().clone();
    let water = (0..p.len())
        .filter(|&i| p.phase(i) == 1)
        .collect::<Vec<_>>();
    let lowest_parked = (0..p.len())
        .filter(|&i| p.phase(i) == parked)
        .take(2)
        .collect::<Vec<_>>();
    for (k, &i) in lowest_parked.iter().enumerate() {
        p.positions[i] = [0.3 + k as f32 * dp, 0.09, 0.0, f32::from_bits(1)];
    }
    for &i in &water[3..6] {
        p.positions[i][3] = f32::from_bits(parked);
    }
    let w = p.positions[water[40]];
    let spots = [
        [w[0], w[1]],
        [w[0] + 0.4 * dp, w[1]],
        [w[0] + 0.35 * dp, w[1] + 0.45 * dp],
        [p.positions[water[4]][0], p.positions[water[4]][1]],
        [0.3, 0.09],
        [0.2, 0.11],
    ];
    let want_occupied = [true, true, false, false, true, false];
    let mut sim = sim(backend, &c, &p);
    let radius = 0.5 * dp;
    let scan = |sim: &mut Simulation, spots: &[[f32; 2]]| {
        let got = sim.inlet_scan(spots, radius).expect("inlet scan");
        let now = sim.read_particles().expect("readback");
        let want =
            flume_solver::engine::inlet_scan(&now.positions, &now.ids, parked, spots, radius);
        let want_ids: Vec<u32> = want.parked_slots.iter().map(|&k| k as u32).collect();
        assert_eq!(got, (want.occupied, want_ids));
        got
    };
    let (occupied, ids) = scan(&mut sim, &spots);
    assert_eq!(occupied, want_occupied);
    let want_ids: Vec<u32> = (0..p.len() as u32)
        .filter(|&i| p.phase(i as usize) == parked)
        .take(spots.len())
        .collect();
    assert_eq!(ids, want_ids, "lowest id first");
    assert_eq!(
        ids[..3],
        [3, 4, 5].map(|k| water[k] as u32),
        "the parked water first"
    );

    sim.advance_to(2.0e-5).expect("one step");
    scan(&mut sim, &spots);
    // More spots than parked particles, in the air above the water: every parked one, in order.
    let air: Vec<[f32; 2]> = (0..100).map(|k| [0.06 + 0.003 * k as f32, 0.105]).collect();
    let (occupied, ids) = scan(&mut sim, &air);
    assert!(occupied.iter().all(|o| !o));
    let n_parked = sim.read_particles().expect("readback");
    let n_parked = (0..n_parked.len())
        .filter(|&i| n_parked.phase(i) == parked)
        .count();
    assert_eq!(ids.len(), n_parked);
}
