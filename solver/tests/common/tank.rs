//! What a tank case must keep, and the dam-break front it is held to: particles inside the
//! tank, mass by phase, and Martin & Moyce's (1952) front positions.

use flume_solver::{Case, Particles, Simulation};

/// The points (T, Z/a) of a front-position series of the validation data
/// ([`super::validation_path`]).
pub fn read_front(path: &str) -> Vec<(f64, f64)> {
    std::fs::read_to_string(super::validation_path(path))
        .expect("validation data")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let mut it = l
                .split(',')
                .map(|v| v.trim().parse::<f64>().expect("number"));
            (it.next().expect("T"), it.next().expect("Z/a"))
        })
        .collect()
}

/// `curve` at `t`, linearly between its points (its ends extended).
pub fn interpolate(curve: &[(f64, f64)], t: f64) -> f64 {
    let k = curve.partition_point(|p| p.0 < t).clamp(1, curve.len() - 1);
    let (t0, z0) = curve[k - 1];
    let (t1, z1) = curve[k];
    z0 + (z1 - z0) * (t - t0) / (t1 - t0)
}

/// Particles must stay in the tank: inside its side walls and above its floor, allowing one
/// dp of the wall's own thickness.
pub fn assert_in_tank(c: &Case, p: &Particles) {
    let d = c.dim();
    let dp = c.numerics.dp_m as f32;
    for i in 0..p.len() {
        let x = p.positions[i];
        for k in 0..d {
            let lo = c.domain.min_m[k] as f32 - dp;
            assert!(
                x[k] >= lo,
                "particle {i} left the tank through the {k}-min face: {x:?}"
            );
            if k < d - 1 {
                assert!(
                    x[k] <= c.domain.max_m[k] as f32 + dp,
                    "particle {i} left through the {k}-max face: {x:?}"
                );
            }
            assert!(x[k].is_finite());
        }
    }
}

/// Mass is carried by particles of fixed mass: it is conserved exactly when no particle is
/// lost, duplicated or changes phase. Checks that every id is present with its phase.
pub fn assert_mass_conserved(sim: &Simulation, now: &Particles) {
    let init = sim.initial_particles();
    assert_eq!(now.len(), init.len());
    let mass = |p: &Particles| -> f64 {
        (0..p.len())
            .map(|i| sim.derived().phases[p.phase(i) as usize].mass)
            .sum()
    };
    for i in 0..init.len() {
        assert_eq!(
            now.phase(i),
            init.phase(i),
            "particle {i} changed phase or is missing"
        );
    }
    assert_eq!(mass(now), mass(init), "total mass");
}
