//! The pair formulas by hand and on small lattices.

use super::super::Phase;
use super::super::kernel::{grad_factor, smoothing_length};
use super::*;

fn sub3(a: &[f32; 4], b: &[f32; 4]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

const WATER: usize = 0;
const WALL: usize = 1;

fn water(mass: f32) -> Phase {
    Phase {
        rho0: 1000.0,
        mass,
        mu: 1e-3,
        mobile: true,
        generalised_wall: false,
    }
}

fn wall(mass: f32) -> Phase {
    Phase {
        rho0: 1000.0,
        mass,
        mu: 0.0,
        mobile: false,
        generalised_wall: false,
    }
}

fn params_2d(h: f32, c0: f32, mass: f32) -> Params {
    Params {
        dim: 2,
        h,
        c0,
        gravity: [0.0, -9.81, 0.0],
        delta: 0.0,
        hydrostatic_diffusion: true,
        clamp_negative_pressure: false,
        generalised_walls: false,
        viscosity: Viscosity::Artificial { alpha: 0.0 },
        cfl: 0.2,
        phases: vec![water(mass), wall(mass)],
    }
}

fn at(x: f32, y: f32, phase: usize) -> [f32; 4] {
    [x, y, 0.0, f32::from_bits(phase as u32)]
}

/// A 2-D block of `nx * ny` particles with spacing dp, cell-centred from the origin.
fn block(nx: usize, ny: usize, dp: f32, phase: usize) -> Vec<[f32; 4]> {
    let mut pos = Vec::new();
    for iy in 0..ny {
        for ix in 0..nx {
            pos.push(at((ix as f32 + 0.5) * dp, (iy as f32 + 0.5) * dp, phase));
        }
    }
    pos
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * b.abs().max(a.abs())
}

#[test]
fn two_particles_by_hand() {
    // h = 1, r = 1: q = 1, F = 7/(4 pi) * (-5) * (1/2)^3 = -0.348_151_2.
    // c0 = 10, rho0 = 1000: B = 100 000 / 7 = 14 285.714.
    // rho_i = 1010: p_i = B (1.01^7 - 1) = 1030.505; p_j = 0 at rho_j = 1000.
    // a_i,x = -m (p_i / rho_i^2) F x_ij = 1030.505 / 1010^2 * 0.348_151_2 = 3.517_03e-4.
    // v_i = (-0.1, 0), v_j = 0: vdotr = -0.1, d rho_i/dt = m vdotr F = 0.034_815_12.
    let mut params = params_2d(1.0, 10.0, 1.0);
    params.gravity = [0.0; 3];
    let pos = [at(1.0, 0.0, WATER), at(0.0, 0.0, WATER)];
    let vel_rho = [[-0.1, 0.0, 0.0, 1010.0], [0.0, 0.0, 0.0, 1000.0]];
    let out = interact(&params, &pos, &vel_rho);
    let [a_i, a_j] = [out.forces[0], out.forces[1]];
    assert!(close(a_i[0], 3.517_03e-4, 1e-5), "{a_i:?}");
    assert_eq!(a_i[1], 0.0);
    assert!(close(a_i[3], 0.034_815_12, 1e-6), "{a_i:?}");
    assert!(close(a_j[3], 0.034_815_12, 1e-6), "{a_j:?}");
    // Equal masses: equal and opposite momentum change.
    assert_eq!(a_i[0], -a_j[0]);
    // dt: sqrt(h / |a|) = 37.7 loses to h / (c0 + |h vdotr / (r2 + eta2)|) = 1 / (10 + 0.1/1.01).
    assert!(close(out.dt_limit[0], 1.0 / (10.0 + 0.1 / 1.01), 1e-6));
}

#[test]
fn a_fixed_particle_sums_its_density_rate_only() {
    // The pair of `two_particles_by_hand` with diffusion: particle i held fixed keeps the
    // density rate it had (continuity 0.034_815_12 and the diffusion towards j), takes no
    // acceleration and does not bound the step; j, free, feels i in full.
    let mut params = params_2d(1.0, 10.0, 1.0);
    params.gravity = [0.0; 3];
    params.delta = 0.1;
    let model = PairModel::new(&params);
    let (p_i, p_j) = (at(1.0, 0.0, WATER), at(0.0, 0.0, WATER));
    let (v_i, v_j) = ([-0.1, 0.0, 0.0, 1010.0], [0.0, 0.0, 0.0, 1000.0]);
    let free = model.side(&p_i, &v_i);
    let fixed = Side {
        fixed: true,
        ..free
    };
    let j = model.side(&p_j, &v_j);
    let sums = |i: &Side| {
        let mut sum = PairSum::default();
        model.add_pair(i, &j, true, &mut sum);
        model.finish(i, &sum, true)
    };
    let ((f_free, dt_free), (f_fixed, dt_fixed)) = (sums(&free), sums(&fixed));
    assert_eq!(f_fixed[3], f_free[3]);
    assert!(f_free[3] != 0.034_815_12 && f_free[0] != 0.0, "{f_free:?}");
    assert_eq!(f_fixed[..3], [0.0; 3]);
    assert!(dt_free.is_finite() && dt_fixed == f32::INFINITY);
    // j's sums read i's position, velocity and density only: the same either way.
    let of_j = |i: &Side| {
        let mut sum = PairSum::default();
        model.add_pair(&j, i, true, &mut sum);
        model.finish(&j, &sum, true)
    };
    assert_eq!(of_j(&fixed), of_j(&free));
}

#[test]
fn lonely_particle_falls() {
    let params = params_2d(0.02, 20.0, 0.4);
    let out = interact(&params, &[at(0.0, 0.0, WATER)], &[[0.0, 0.0, 0.0, 1000.0]]);
    assert_eq!(out.forces[0], [0.0, -9.81, 0.0, 0.0]);
    let expected = (0.02_f32 / 9.81).sqrt().min(0.02 / 20.0);
    assert_eq!(out.dt_limit[0], expected);
}

#[test]
fn resting_lattice_has_no_forces() {
    let dp = 0.01;
    let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
    let mut params = params_2d(h, 20.0, 1000.0 * dp * dp);
    let pos = block(15, 15, dp, WATER);

    // At rho0 every pressure is exactly 0: only gravity remains, and nothing compresses.
    // (Density diffusion stays off here: under gravity it rightly drives a uniform density
    // towards the hydrostatic profile.)
    let vel_rho = vec![[0.0, 0.0, 0.0, 1000.0]; pos.len()];
    let out = interact(&params, &pos, &vel_rho);
    for f in &out.forces {
        assert_eq!(*f, [0.0, -9.81, 0.0, 0.0]);
    }
    params.delta = 0.1;

    // Uniformly compressed: a particle with a full, symmetric neighbourhood feels no net
    // pressure force. Compare with the size of one neighbour's push.
    params.gravity = [0.0; 3];
    let vel_rho = vec![[0.0, 0.0, 0.0, 1010.0]; pos.len()];
    let out = interact(&params, &pos, &vel_rho);
    let b = tait_b(20.0, 1000.0);
    let p = pressure(1010.0, 1000.0, b);
    let one_pair =
        params.phases[0].mass * 2.0 * p / (1010.0 * 1010.0) * grad_factor(dp, h, 2).abs() * dp;
    let centre = 7 * 15 + 7;
    let a = out.forces[centre];
    assert!(
        a[0].abs() < 1e-4 * one_pair && a[1].abs() < 1e-4 * one_pair,
        "{a:?} vs {one_pair}"
    );
    assert_eq!(a[3], 0.0);
    // Near the free edge the unbalanced pressure pushes outwards (-x at the left column).
    assert!(out.forces[7 * 15][0] < 0.0);
}

/// Hydrostatic density `rho0 (1 + rho0 g (H - z) / B)^(1/7)`.
fn hydrostatic(z: f32, surface: f32, params: &Params) -> f32 {
    let rho0 = 1000.0_f64;
    let b = f64::from(tait_b(params.c0, 1000.0));
    let depth = f64::from(surface) - f64::from(z);
    (rho0 * (1.0 + rho0 * 9.81 * depth / b).powf(1.0 / 7.0)) as f32
}

/// Molteni-Colagrossi term of particle 1 on particle 0 without the hydrostatic correction.
fn plain_diffusion(params: &Params, pos: &[[f32; 4]; 2], vel_rho: &[[f32; 4]; 2]) -> f32 {
    let (h, rho_i, rho_j) = (params.h, vel_rho[0][3], vel_rho[1][3]);
    let x_ij = sub3(&pos[0], &pos[1]);
    let r2 = dot3(x_ij, x_ij);
    let f = grad_factor(r2.sqrt(), h, params.dim);
    params.delta * h * params.c0 * 2.0 * (rho_j - rho_i) * (-r2 * f) / (r2 + 0.01 * h * h)
        * (params.phases[0].mass / rho_j)
}

#[test]
fn hydrostatic_pair_is_not_diffused() {
    let surface = 0.5_f32;
    let dp = 0.01_f32;
    let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
    let c0 = c0_dualsphysics(surface);
    let mut params = params_2d(h, c0, 1000.0 * dp * dp);
    params.delta = 0.1;
    let b = f64::from(tait_b(c0, 1000.0));

    // i at height z_i, j one kernel radius-ish below and beside it.
    for z_i in [surface, 0.4, 0.25, 0.1, 2.0 * h] {
        let pos = [
            at(0.2, z_i, WATER),
            at(0.2 + 0.5 * dp, z_i - 1.5 * dp, WATER),
        ];
        let rho = [
            hydrostatic(pos[0][1], surface, &params),
            hydrostatic(pos[1][1], surface, &params),
        ];
        let vel_rho = [[0.0, 0.0, 0.0, rho[0]], [0.0, 0.0, 0.0, rho[1]]];
        // At rest the continuity term vanishes: drho is the diffusion term alone.
        let drho = interact(&params, &pos, &vel_rho).forces[0][3];

        let plain = plain_diffusion(&params, &pos, &vel_rho);
        // The correction takes i as the top of a water column (p_i = 0), so it is exact at
        // the surface and leaves a second-order residue below it:
        // (rho_j - rho_i - rho_h) / (rho_j - rho_i) ~ -(6/7) rho0 g (H - z_i) / B.
        let depth_term = 1000.0 * 9.81 * f64::from(surface - z_i) / b;
        let allowed = 1.2 * 6.0 / 7.0 * depth_term + 2e-3;
        let ratio = f64::from(drho / plain).abs();
        assert!(
            ratio <= allowed,
            "z_i {z_i}: corrected/plain = {ratio}, allowed {allowed}"
        );
    }
}

/// DualSPHysics' default c0 = 10 sqrt(g H) for a still-water height H.
fn c0_dualsphysics(height: f32) -> f32 {
    super::super::eos::c0_from_coefsound(10.0, 9.81, f64::from(height)) as f32
}

#[test]
fn laminar_viscosity_slows_the_fast_layer() {
    let dp = 0.01;
    let (nx, ny) = (15, 9);
    let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
    let mut params = params_2d(h, 20.0, 1000.0 * dp * dp);
    params.gravity = [0.0; 3];
    params.viscosity = Viscosity::Laminar;
    let pos = block(nx, ny, dp, WATER);
    // Linear shear u = gamma y, at rest density.
    let vel_rho: Vec<[f32; 4]> = pos
        .iter()
        .map(|p| [50.0 * p[1], 0.0, 0.0, 1000.0])
        .collect();
    let out = interact(&params, &pos, &vel_rho);

    let top = (ny - 1) * nx + nx / 2;
    let bottom = nx / 2;
    let middle = (ny / 2) * nx + nx / 2;
    assert!(out.forces[top][0] < 0.0, "fastest layer must slow down");
    assert!(
        out.forces[bottom][0] > 0.0,
        "slowest layer must be dragged along"
    );
    // Inside, a linear profile has no Laplacian.
    assert!(out.forces[middle][0].abs() < 1e-4 * out.forces[top][0].abs());
    // Equal masses and pairwise antisymmetric terms: momentum is conserved.
    let total: f32 = out.forces.iter().map(|f| f[0]).sum();
    let scale: f32 = out.forces.iter().map(|f| f[0].abs()).sum();
    assert!(total.abs() < 1e-5 * scale, "{total} vs {scale}");
}

#[test]
fn artificial_viscosity_damps_approach_only() {
    let mut params = params_2d(1.0, 10.0, 1.0);
    params.gravity = [0.0; 3];
    params.viscosity = Viscosity::Artificial { alpha: 0.1 };
    let pos = [at(1.0, 0.0, WATER), at(0.0, 0.0, WATER)];
    let approach = [[-0.1, 0.0, 0.0, 1000.0], [0.0, 0.0, 0.0, 1000.0]];
    let out = interact(&params, &pos, &approach);
    // By hand: mu = -0.1 / 1.01, pi = 0.1 * 10 * 0.1 / 1.01 / 1000, a = -pi F.
    let expected = 0.1 * 10.0 * (0.1 / 1.01) / 1000.0 * 0.348_151_2;
    assert!(
        close(out.forces[0][0], expected, 1e-5),
        "{:?}",
        out.forces[0]
    );
    assert_eq!(out.forces[0][0], -out.forces[1][0]);
    let recede = [[0.1, 0.0, 0.0, 1000.0], [0.0, 0.0, 0.0, 1000.0]];
    let out = interact(&params, &pos, &recede);
    assert_eq!(out.forces[0][0], 0.0);
}

#[test]
fn walls_only_feel_fluid_density_rate() {
    let mut params = params_2d(1.0, 10.0, 1.0);
    params.delta = 0.1;
    let pos = [at(0.0, 0.0, WALL), at(1.0, 0.0, WALL), at(0.5, 1.0, WATER)];
    // Wall densities differ and walls "move" (velocity field set) to show that wall-wall pairs
    // contribute nothing.
    let vel_rho = [
        [0.3, 0.0, 0.0, 1005.0],
        [0.0, 0.0, 0.0, 1000.0],
        [0.0, -0.2, 0.0, 1000.0],
    ];
    let out = interact(&params, &pos, &vel_rho);
    for i in 0..2 {
        assert_eq!(out.forces[i][..3], [0.0; 3]);
        assert_eq!(out.dt_limit[i], f32::INFINITY);
        let x_ij = sub3(&pos[i], &pos[2]);
        let v_ij = sub3(&vel_rho[i], &vel_rho[2]);
        let r = dot3(x_ij, x_ij).sqrt();
        let expected = params.phases[0].mass * dot3(v_ij, x_ij) * grad_factor(r, 1.0, 2);
        assert_eq!(out.forces[i][3], expected);
    }
    // The fluid above the compressed wall is pushed up, and diffusion ignores the walls.
    assert!(out.forces[2][1] > -9.81);
    assert!(out.dt_limit[2].is_finite());
}

#[test]
fn three_d_uses_z_as_vertical() {
    let dp = 0.02_f32;
    let h = smoothing_length(1.2, 3, f64::from(dp)) as f32;
    let mut params = params_2d(h, 20.0, 1000.0 * dp * dp * dp);
    params.dim = 3;
    params.gravity = [0.0, 0.0, -9.81];
    params.delta = 0.1;
    let surface = 0.3;
    let z = [surface, surface - dp];
    let rho = z.map(|zz| hydrostatic(zz, surface, &params));
    let phase = f32::from_bits(WATER as u32);
    let pos = [[0.1, 0.1, z[0], phase], [0.1, 0.1, z[1], phase]];
    let vel_rho = [[0.0, 0.0, 0.0, rho[0]], [0.0, 0.0, 0.0, rho[1]]];
    let out = interact(&params, &pos, &vel_rho);
    // i at the surface of a hydrostatic column: the correction cancels the diffusion up to
    // f32 rounding, as in the 2-D test.
    let plain = plain_diffusion(&params, &pos, &vel_rho);
    assert!(plain > 0.0);
    assert!(
        out.forces[0][3].abs() < 2e-3 * plain,
        "{} vs {plain}",
        out.forces[0][3]
    );
    // Pressure acts along z only.
    assert_eq!(out.forces[0][..2], [0.0, 0.0]);
}

/// The held bed's contact force by hand: dp = 1 cm, c0 = 10 m/s, so D = 1 m2/s2 and r0 =
/// 0.6 dp (the sand's particle volume is dp^2 too). A water particle 0.5 dp above a held sand
/// particle standing as a wall, both at rest density (no pressure) and at rest: (r0 / r)^2 =
/// 1.44, (r0 / r)^4 = 2.0736, (r0 / r)^12 = 8.916100, so the force is D 6.842500 / r =
/// 6.842500 / 0.005 = 1368.50 m/s2 straight up, under the generalised condition only; none at
/// 0.65 dp (beyond r0) nor in a gap of the lattice (dp / sqrt(2)), none on sand of the bed's
/// own phase, none from a wall.
#[test]
fn held_bed_contact_force_by_hand() {
    let dp = 0.01;
    let h = smoothing_length(1.2, 2, f64::from(dp)) as f32;
    let mut params = params_2d(h, 10.0, 1000.0 * dp * dp);
    params.gravity = [0.0; 3];
    let sand = Phase {
        rho0: 2710.0,
        mass: 2710.0 * dp * dp,
        ..water(0.0)
    };
    params.phases.push(sand);
    const SAND: usize = 2;
    let up = |params: &Params, gap: f32, (above, below): (usize, usize)| {
        let pos = [at(0.0, gap, above), at(0.0, 0.0, below)];
        let rest = |phase: usize| [0.0, 0.0, 0.0, params.phases[phase].rho0];
        let vel = [rest(above), rest(below)];
        interact_with_bed_walls(params, &pos, &vel, &[false, below == SAND]).forces[0][1]
    };
    assert_eq!(
        up(&params, 0.5 * dp, (WATER, SAND)),
        0.0,
        "none under DBC walls"
    );
    params.generalised_walls = true;
    params.phases[WALL].generalised_wall = true;
    let a = up(&params, 0.5 * dp, (WATER, SAND));
    assert!(close(a, 1368.5, 1e-5), "{a}");
    assert_eq!(up(&params, 0.65 * dp, (WATER, SAND)), 0.0);
    assert_eq!(up(&params, dp / 2.0_f32.sqrt(), (WATER, SAND)), 0.0);
    assert_eq!(
        up(&params, 0.5 * dp, (SAND, SAND)),
        0.0,
        "on the bed's own sand"
    );
    assert_eq!(up(&params, 0.5 * dp, (WATER, WALL)), 0.0, "from a wall");
}
