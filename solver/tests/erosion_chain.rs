//! The erosion chain on the flowing flume, grain by grain, against an oracle written here from
//! the paper's equations (`MODEL.md`, Eqs. 16-26) in f64: its own neighbour search (every pair),
//! its own kernel, the friction velocity by a scan and bisection on the velocity profile (the
//! code takes Newton steps in f32, piece by piece), and its own region of Figure 2 in the
//! Shields-only mode.
//!
//! The CI-size ULBRA flume (dp = 1 cm, the case's DBC walls) at 5 s, while the front's wake
//! moves the bed, and at 15 s, once it has filled. For every sand grain: whether it lies at the
//! bed's surface (Eq. 26); for those at the surface, the nearest water particle's distance z and
//! relative speed u, the friction velocity u* (Eqs. 19-21), the bed shear stress (Eq. 18) and its
//! critical value on the local slope (Eqs. 16-17, 22-24), as `Simulation::shields_chains` gives
//! them; and the region the backend itself gave the grain, wherever the oracle's decision is not
//! within 10 % of the threshold (the backend's regions are those of the last step's start, a
//! tenth of a millimetre of motion before the particles read).
//!
//! The z of the log law is the distance between the grain's centre and the nearest water
//! particle's, as the paper's Section 2.5.1 says its DualSPHysics implementation stores it ("the
//! closest water particle to a sediment particle is identified during the neighbour search ...
//! and its distance to a sediment particle is stored"), the sediment surface being the grain
//! that Eq. 26 marks: at dp = 1 cm it is 1.5-1.9 cm.
//!
//! The slope of Eqs. 22-24 is the bed's: the normal out of the sand and walls around the grain
//! (`pass.rs` says why not the water's), and a down-slope past the friction angle holds no grain.
//!
//! Measured on the paper's bed (the test prints them): at 5 s, 129 grains at the surface (the
//! front has wetted the bed to x = 1.3 m), 5 of them over the threshold, Shields numbers
//! 0.02-0.03 against about 0.04; at 15 s, 246 at the surface and 11 over it, Shields 0.01-0.02
//! (tau_b / tau_bcr 0.2-0.5). With the fixed apron the case had before 2026-11-27, the front
//! had crossed the bed by 5 s: 214 at the surface, 194 over the threshold, Shields 0.04-0.07.
//! The paper's bed brought two grains the oracle had not met: one under the roof of the hole
//! the jet digs (a bed that faces down, where the code's factor was already 0, now said on both
//! sides), and one whose profile passes its speed twice near Re_k = 5 (the code takes the
//! smaller u*, as its documentation says; the oracle's bisection found the larger, and now
//! scans up from the smallest).

mod common;

use common::ulbra_ci;
use flume_solver::physics::sediment::pass::ShieldsChain;
use flume_solver::{Backend, Case, ParticleRegion, Particles, Region, Simulation};

const KARMAN: f64 = 0.41;

/// The case's constants as the oracle needs them, from the case file alone.
struct Oracle {
    h: f64,
    m_sand: f64,
    m_water: f64,
    /// The walls are of the first phase, as the backends make them.
    m_wall: f64,
    sand: u32,
    water: u32,
    surface_mass: f64,
    ks: f64,
    d50: f64,
    nu: f64,
    rho_s: f64,
    rho_w: f64,
    g: f64,
    phi: f64,
}

/// What the oracle finds for one grain.
#[derive(Debug)]
struct Grain {
    at_surface: bool,
    /// Its sediment kernel mass over the surface threshold (Eq. 26).
    mass_ratio: f64,
    z: f64,
    speed: f64,
    u_star: f64,
    /// z over the viscous sub-layer's thickness.
    z_over_delta: f64,
    tau_b: f64,
    tau_bcr: f64,
    c_v: f64,
}

impl Oracle {
    fn new(case: &Case) -> Oracle {
        let dp = case.numerics.dp_m;
        let (k_sand, k_water) = case.sediment_phases().expect("sand in water");
        let (sand, water) = (&case.phases[k_sand], &case.phases[k_water]);
        let sed = sand.sediment.as_ref().expect("a sediment");
        Oracle {
            h: case.numerics.coefh * 2f64.sqrt() * dp,
            m_sand: sand.rho0_kg_per_m3 * dp * dp,
            m_water: water.rho0_kg_per_m3 * dp * dp,
            m_wall: case.phases[0].rho0_kg_per_m3 * dp * dp,
            sand: k_sand as u32 + 1,
            water: k_water as u32 + 1,
            surface_mass: sed.surface_mass_fraction * sand.rho0_kg_per_m3 * dp * dp,
            ks: sed.ks_over_d50 * sed.d50_m,
            d50: sed.d50_m,
            nu: water.viscosity_pa_s / water.rho0_kg_per_m3,
            rho_s: sand.rho0_kg_per_m3,
            rho_w: water.rho0_kg_per_m3,
            g: -case.gravity_m_per_s2[1],
            phi: sed.friction_angle_deg.to_radians(),
        }
    }

    /// Wendland C2 in 2-D (Eq. 8) and `(dW/dr) / r`.
    fn kernel(&self, r: f64) -> (f64, f64) {
        let (h, q) = (self.h, r / self.h);
        if q >= 2.0 {
            return (0.0, 0.0);
        }
        let a = 7.0 / (4.0 * std::f64::consts::PI * h * h);
        let w = a * (1.0 - q / 2.0).powi(4) * (2.0 * q + 1.0);
        let dw_dr = -5.0 * q * a * (1.0 - q / 2.0).powi(3) / h;
        (w, if r > 0.0 { dw_dr / r } else { 0.0 })
    }

    /// u(z) of Eqs. 19-21 for friction velocity `u_star`.
    fn profile(&self, u_star: f64, z: f64) -> f64 {
        let delta = 11.6 * self.nu / u_star;
        if z <= delta {
            return u_star * u_star * z / self.nu;
        }
        let re_k = self.ks * u_star / self.nu;
        let z0 = if re_k <= 5.0 {
            0.11 * self.nu / u_star
        } else if re_k >= 70.0 {
            0.033 * self.ks
        } else {
            0.11 * self.nu / u_star + 0.033 * self.ks
        };
        u_star / KARMAN * (z / z0).ln()
    }

    /// The smallest u* whose profile reaches `speed` at `z`. The profile jumps down where its
    /// laws meet (the sub-layer's top, Re_k = 5), so it can pass `speed` more than once, and a
    /// bisection over the whole range finds any of the crossings: a scan up a geometric grid of
    /// u* from 1e-7 to 10 m/s finds the first point at or above `speed`, then bisection between
    /// it and the point before.
    fn friction_velocity(&self, speed: f64, z: f64) -> f64 {
        const STEPS: i32 = 40_000;
        let ratio = (10.0f64 / 1e-7).powf(1.0 / f64::from(STEPS));
        let (mut lo, mut hi) = (0.0, 1e-7);
        for _ in 0..STEPS {
            if self.profile(hi, z) >= speed {
                break;
            }
            (lo, hi) = (hi, hi * ratio);
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.profile(mid, z) < speed {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Critical Shields parameter, Eq. 17 (van Rijn 1993).
    fn theta_cr(re_star: f64) -> f64 {
        if re_star < 500.0 {
            0.010595 * re_star.ln() + 0.110476 / re_star + 0.0027197
        } else {
            0.068
        }
    }

    fn grain(&self, p: &Particles, i: usize) -> Grain {
        let at = |k: usize| [f64::from(p.positions[k][0]), f64::from(p.positions[k][1])];
        let vel = |k: usize| [f64::from(p.vel_rho[k][0]), f64::from(p.vel_rho[k][1])];
        let rho = |k: usize| f64::from(p.vel_rho[k][3]);
        let (xi, vi) = (at(i), vel(i));
        let own = self.m_sand / rho(i);
        let mut mass = self.m_sand * self.kernel(0.0).0 * own;
        let (mut sand_v, mut all_v) = (own, own);
        let mut nearest = (f64::INFINITY, 0.0, [0.0; 2]);
        let mut normal = [0.0; 2];
        for j in (0..p.len()).filter(|&j| j != i) {
            let xj = at(j);
            let d = [xi[0] - xj[0], xi[1] - xj[1]];
            let r = d[0].hypot(d[1]);
            if r >= 2.0 * self.h {
                continue;
            }
            let (w, f) = self.kernel(r);
            if p.phase(j) == self.sand || p.is_wall(j) {
                // The bed's normal points out of the solid: the sand's and the walls' volume.
                let m = if p.is_wall(j) {
                    self.m_wall
                } else {
                    self.m_sand
                };
                let v = m / rho(j);
                normal = [normal[0] - v * f * d[0], normal[1] - v * f * d[1]];
            }
            if p.phase(j) == self.sand {
                let v = self.m_sand / rho(j);
                mass += self.m_sand * w * v;
                (sand_v, all_v) = (sand_v + v, all_v + v);
            } else if p.phase(j) == self.water {
                let v = self.m_water / rho(j);
                all_v += v;
                if r < nearest.0 {
                    let du = [vel(j)[0] - vi[0], vel(j)[1] - vi[1]];
                    nearest = (r, du[0].hypot(du[1]), du);
                }
            }
        }
        let (z, speed, du) = nearest;
        let at_surface = z.is_finite() && mass < self.surface_mass;
        let mut g = Grain {
            at_surface,
            mass_ratio: mass / self.surface_mass,
            z,
            speed,
            u_star: 0.0,
            z_over_delta: 0.0,
            tau_b: 0.0,
            tau_bcr: f64::INFINITY,
            c_v: sand_v / all_v,
        };
        if at_surface {
            let u_star = self.friction_velocity(speed, z);
            let tau_bcr0 = Self::theta_cr(u_star * self.d50 / self.nu)
                * (self.rho_s - self.rho_w)
                * self.g
                * self.d50;
            // Eq. 22: beta the bed's tilt along the flow, from the bed's outward normal;
            // minus for a flow running down the slope (the normal leaning the flow's way).
            let n_s = normal[0] * du[0].signum();
            let beta = n_s.abs().atan2(normal[1]);
            let k_beta = if du[0] == 0.0 || normal == [0.0, 0.0] {
                1.0
            } else if n_s > 0.0 {
                // A down-slope past the friction angle holds no grain: no critical stress.
                ((self.phi - beta).sin() / self.phi.sin()).max(0.0)
            } else {
                (self.phi + beta).sin() / self.phi.sin()
            };
            // A bed that faces down (the roof of the hole the jet digs under the orifice of the
            // paper's bed) holds no grain: gravity pulls the grain off it, so friction cannot
            // hold it, and Eq. 22 no longer applies.
            let k_beta = if normal[1] < 0.0 { 0.0 } else { k_beta };
            g.u_star = u_star;
            g.z_over_delta = z * u_star / (11.6 * self.nu);
            g.tau_b = self.rho_w * u_star * u_star;
            g.tau_bcr = k_beta * tau_bcr0;
        }
        g
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-12)
}

/// The code's chain of grain `i` against the oracle's, field by field.
fn check_grain(t: f64, i: usize, code: &ShieldsChain, want: &Grain) {
    let got = |v: f32| f64::from(v);
    let near_threshold = (want.mass_ratio - 1.0).abs() < 1e-4;
    if !near_threshold {
        assert_eq!(
            code.at_surface, want.at_surface,
            "t = {t} s, grain {i}: {want:?}"
        );
    }
    if !(code.at_surface && want.at_surface) {
        return;
    }
    assert!(close(got(code.z_m), want.z, 1e-5), "z: {code:?} {want:?}");
    assert!(
        (got(code.speed_m_per_s) - want.speed).abs() <= 1e-4 * want.speed + 1e-6,
        "u: {code:?} {want:?}"
    );
    // Where z lies near the sub-layer's edge the profile's two laws meet with a small jump,
    // and a root may sit on either side of it.
    if (want.z_over_delta - 1.0).abs() > 0.1 {
        assert!(
            close(got(code.u_star_m_per_s), want.u_star, 2e-3),
            "u*: {code:?} {want:?}"
        );
        assert!(
            close(got(code.tau_b_pa), want.tau_b, 4e-3),
            "tau_b: {code:?} {want:?}"
        );
        assert!(
            close(got(code.tau_bcr_pa), want.tau_bcr, 2e-3),
            "tau_bcr: {code:?} {want:?}"
        );
    }
}

/// The oracle's region in the Shields-only mode, or None within 10 % of a threshold.
fn clear_region(g: &Grain) -> Option<Region> {
    if (g.c_v - 0.3).abs() < 0.03 {
        return None;
    }
    if g.c_v < 0.3 {
        return Some(Region::Suspended);
    }
    let ratio = g.tau_b / g.tau_bcr;
    match g.at_surface {
        true if (ratio - 1.0).abs() < 0.1 => None,
        true if ratio > 1.0 => Some(Region::BedLoad),
        _ => Some(Region::Unyielded),
    }
}

#[test]
fn the_erosion_chain_of_the_flowing_flumes_grains_matches_the_oracle() {
    let case = ulbra_ci();
    let oracle = Oracle::new(&case);
    let mut sim = Simulation::new(Backend::cpu(0), &case).expect("builds");
    for t in [5.0, 15.0] {
        sim.advance_to(t).expect("runs");
        let particles = sim.read_particles().expect("readback");
        let regions = sim.regions().expect("regions");
        let chains = sim.shields_chains(&particles).expect("a sediment");
        let (mut surface, mut eroding, mut compared) = (0, 0, 0);
        for (i, code) in &chains {
            let want = oracle.grain(&particles, *i);
            check_grain(t, *i, code, &want);
            surface += usize::from(want.at_surface);
            eroding += usize::from(want.at_surface && want.tau_b > want.tau_bcr);
            if let Some(region) = clear_region(&want) {
                let engine = ParticleRegion::from_word(regions[*i]).region;
                assert_eq!(engine, Some(region), "t = {t} s, grain {i}: {want:?}");
                compared += 1;
            }
        }
        // A handful of surface grains along the flume, for the log.
        let shown: Vec<&(usize, ShieldsChain)> = chains
            .iter()
            .filter(|(_, c)| c.at_surface)
            .step_by((surface / 6).max(1))
            .collect();
        for (i, c) in shown {
            let x = particles.positions[*i][0];
            let theta =
                f64::from(c.tau_b_pa) / ((oracle.rho_s - oracle.rho_w) * oracle.g * oracle.d50);
            eprintln!(
                "t = {t} s, grain {i} at x = {x:.3} m: z = {:.4} m, u = {:.3} m/s, u* = {:.4} m/s, \
                 Shields {theta:.3}, tau_b / tau_bcr = {:.2}",
                c.z_m,
                c.speed_m_per_s,
                c.u_star_m_per_s,
                c.tau_b_pa / c.tau_bcr_pa
            );
        }
        eprintln!(
            "t = {t} s: {} grains, {surface} at the surface, {eroding} over the threshold; \
             {compared} regions compared with the backend's",
            chains.len()
        );
        // The top row of the 2.1 m bed is about 210 grains, of which the front has wetted some
        // 130 by 5 s on the paper's bed (x < 1.3 m): a surface test that marked none, or all
        // 1,100, would pass the checks above vacuously.
        assert!(
            (100..=400).contains(&surface),
            "t = {t} s: {surface} at the surface"
        );
    }
}
