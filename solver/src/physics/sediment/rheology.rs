//! Strain rate and the Herschel-Bulkley-Papanastasiou (HBP) apparent viscosity of the sediment
//! (Zubeldia et al. 2018, Eqs. 12-15; Fourtakas & Rogers 2016):
//! - velocity gradient (Eq. 13): `du_a/dx_b |_i = sum_j (m_j / rho_j) (u_j - u_i)_a dW_ij/dx_b`;
//! - strain rate (Eq. 12): `eps_ab = 1/2 (du_a/dx_b + du_b/dx_a) - 1/3 delta_ab du_c/dx_c`;
//! - second invariant: `II_D = 1/2 eps_ab eps_ab`;
//! - HBP (Eq. 15): `mu = tau_c / sqrt(II_D) (1 - exp(-m sqrt(II_D))) + 2 mu_s (4 II_D)^((n-1)/2)`;
//! - viscous stress (Eqs. 11, 14): `tau = 2 mu eps`.
//!
//! Tensors are `[[f32; 3]; 3]` indexed `[a][b]`; in 2-D the plane is (x, y) and every entry with
//! an index >= 2 is zero.
//!
//! The factor 2 of Eq. 15, kept as MODEL.md writes it: with `tau = 2 mu eps` and
//! `sqrt(J2) = sqrt(1/2 tau_ab tau_ab) = 2 mu sqrt(II_D)`, the limits are
//! - m = 0, n = 1: a Newtonian fluid of viscosity 2 mu_s (not mu_s);
//! - m -> inf, n = 1: `mu sqrt(II_D) -> tau_c + 2 mu_s sqrt(II_D)`, so the stress invariant at the
//!   onset of flow is `sqrt(J2) = 2 tau_c`, twice the yield stress that Drucker-Prager compares
//!   `sqrt(J2)` with (Eq. 30).
//!
//! Both limits become the textbook ones (viscosity mu_s, `sqrt(J2) -> tau_c`) if Eq. 15 is read as
//! twice the apparent viscosity, i.e. `tau = mu_HBP eps`. The shear rate `gamma_dot = sqrt(4 II_D)`
//! makes the textbook form visible: Eq. 15 is `2 (tau_c / gamma_dot (1 - exp(-m gamma_dot / 2)) +
//! mu_s gamma_dot^(n-1))`. The code keeps MODEL.md's `tau = 2 mu eps`; whoever sets mu_s and reads
//! the yield stresses should know which reading the calibration assumed.

/// A 3 x 3 tensor, `[a][b]`.
pub type Tensor3 = [[f32; 3]; 3];

/// Below this `x = m sqrt(II_D)` the Papanastasiou factor `(1 - exp(-x)) / x` comes from its
/// Taylor series instead of the exponential.
///
/// At x = 0 the closed form is 0/0 and just above it `1 - exp(-x)` cancels catastrophically (its
/// f32 relative error is about 1.2e-7 / x). The five-term series has a truncation error below
/// x^5 / 720 = 1.4e-8 at 0.1, where the closed form's rounding is about 1e-6, so both sides of the
/// switch are good to about 1e-6 and the series tends to the exact limit 1 (the HBP viscosity to
/// `tau_c m + ...`, finite at zero strain rate, which is the point of Papanastasiou's
/// regularisation).
pub const PAPANASTASIOU_SERIES_LIMIT: f32 = 0.1;

/// Velocity gradient of one particle i (Eq. 13), 1/s: `G[a][b] = du_a/dx_b`.
///
/// `volumes[j] = m_j / rho_j` (m3, or m2 in 2-D), `du[j] = u_j - u_i` (m/s) and
/// `grad_w[j] = grad_i W_ij` (for example `(x_i - x_j) F` with
/// [`grad_factor`](crate::physics::kernel::grad_factor)), one entry per neighbour.
///
/// Panics if the slices differ in length: a bug of the caller, not bad data.
pub fn velocity_gradient(volumes: &[f32], du: &[[f32; 3]], grad_w: &[[f32; 3]]) -> Tensor3 {
    assert_eq!(volumes.len(), du.len(), "volumes and du differ in length");
    assert_eq!(
        volumes.len(),
        grad_w.len(),
        "volumes and grad_w differ in length"
    );
    let mut g = [[0.0_f32; 3]; 3];
    for ((&v, dv), gw) in volumes.iter().zip(du).zip(grad_w) {
        for a in 0..3 {
            for b in 0..3 {
                g[a][b] += v * dv[a] * gw[b];
            }
        }
    }
    g
}

/// Strain rate tensor eps of Eq. 12 from a velocity gradient `grad[a][b] = du_a/dx_b`, 1/s.
///
/// Only the first `dim` rows and columns are used and filled; the rest of the result is zero.
///
/// The trace correction is 1/3 in 2-D as well, as MODEL.md writes it. The paper gives Eq. 12 once,
/// with 1/3, and no 2-D variant, although all its cases are 2-D. So in 2-D this tensor is not
/// traceless: `eps_xx + eps_yy = (du_x/dx + du_y/dy) / 3`. The two alternatives would be 1/2 (the
/// deviator within the plane) or the 3-D deviator of the plane-strain tensor, which adds an
/// `eps_zz = -div u / 3` to II_D. In weakly compressible SPH div u is only the relative density
/// rate, so the choice moves II_D very little.
pub fn strain_rate(grad: &Tensor3, dim: u32) -> Tensor3 {
    debug_assert!(dim == 2 || dim == 3, "dim must be 2 or 3, got {dim}");
    let n = if dim == 2 { 2 } else { 3 };
    let trace: f32 = (0..n).map(|c| grad[c][c]).sum();
    let mut eps = [[0.0_f32; 3]; 3];
    for a in 0..n {
        for b in 0..n {
            eps[a][b] = 0.5 * (grad[a][b] + grad[b][a]);
        }
        eps[a][a] -= trace / 3.0;
    }
    eps
}

/// Second invariant `1/2 t_ab t_ab` of a tensor: II_D for the strain rate (1/s2), J2 for a
/// deviatoric stress (Pa2, Eq. 28).
pub fn second_invariant(t: &Tensor3) -> f32 {
    let mut s = 0.0_f32;
    for row in t {
        for &x in row {
            s += x * x;
        }
    }
    0.5 * s
}

/// `(1 - exp(-x)) / x` for x >= 0, continuous through x = 0 where it is 1 (see
/// [`PAPANASTASIOU_SERIES_LIMIT`]).
fn papanastasiou_factor(x: f32) -> f32 {
    if x < PAPANASTASIOU_SERIES_LIMIT {
        // 1 - x/2 + x^2/6 - x^3/24 + x^4/120, Horner form.
        1.0 - x * (1.0 / 2.0 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0)))
    } else {
        (1.0 - (-x).exp()) / x
    }
}

/// HBP apparent viscosity of Eq. 15, Pa s.
///
/// - `ii_d`: second invariant of the strain rate, 1/s2 (negative rounding noise counts as 0);
/// - `tau_c`: yield stress, Pa (Drucker-Prager's tau_y or Shields' tau_bcr, by region);
/// - `m`: Papanastasiou exponent, s, >= 0; `n`: power-law index; `mu_s`: sediment viscosity, Pa s.
///
/// `tau_c / sqrt(II_D) (1 - exp(-m sqrt(II_D)))` is evaluated as
/// `tau_c m (1 - exp(-x)) / x` with `x = m sqrt(II_D)`, whose limit at zero strain rate is
/// `tau_c m`. The power-law term has no such limit for n < 1: `(4 II_D)^((n-1)/2)` diverges as
/// II_D -> 0 and is returned as infinity at II_D = 0, the model's own behaviour. For n = 1 it is
/// exactly 2 mu_s, zero strain rate included.
pub fn hbp_viscosity(ii_d: f32, tau_c: f32, m: f32, n: f32, mu_s: f32) -> f32 {
    let ii_d = ii_d.max(0.0);
    let s = ii_d.sqrt();
    let yield_term = tau_c * m * papanastasiou_factor(m * s);
    // x^0 is 1 for every x (IEEE 754's pow, NaN included): the Newtonian power law spares
    // the call into libm, to the same bits.
    let power = if n == 1.0 {
        1.0
    } else {
        (4.0 * ii_d).powf(0.5 * (n - 1.0))
    };
    let power_term = 2.0 * mu_s * power;
    yield_term + power_term
}

/// Sub-particle-scale eddy viscosity of the Smagorinsky model (Dalrymple & Rogers 2006, Eq. 12;
/// DualSPHysics' laminar + SPS), Pa s: `rho (C_s dp)^2 |S|` with `|S| = sqrt(2 S:S)`, which is
/// `2 sqrt(II_D)` for `II_D = S:S / 2`. `length2` is `(C_s dp)^2`, m2; `ii_d` the second
/// invariant of Eq. 12's strain rate (whose trace is the relative density rate, next to
/// nothing in weakly compressible water); negative rounding noise counts as 0. The model's
/// isotropic part (`-2/3 C_I dp^2 |S|^2`, an addition to the pressure) is left out: it does
/// not shear the flow.
pub fn sps_viscosity(rho: f32, length2: f32, ii_d: f32) -> f32 {
    rho * length2 * 2.0 * ii_d.max(0.0).sqrt()
}

/// Viscous stress `tau = 2 mu eps` (Eqs. 11 and 14), Pa.
pub fn viscous_stress(mu: f32, eps: &Tensor3) -> Tensor3 {
    let mut tau = [[0.0_f32; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            tau[a][b] = 2.0 * mu * eps[a][b];
        }
    }
    tau
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::kernel::grad_factor;

    fn close(a: f32, b: f32, rel: f32) -> bool {
        (a - b).abs() <= rel * b.abs().max(f32::MIN_POSITIVE)
    }

    /// Simple shear u_x = 30 y in 2-D: |S| = 30 1/s, so with C_s = 0.12 and dp = 1 cm the eddy
    /// viscosity is 1000 x (0.0012)^2 x 30 = 0.0432 Pa s, 43 times water's own.
    #[test]
    fn sps_viscosity_of_a_simple_shear() {
        let mut grad = [[0.0f32; 3]; 3];
        grad[0][1] = 30.0;
        let ii_d = second_invariant(&strain_rate(&grad, 2));
        let mu = sps_viscosity(1000.0, (0.12f32 * 0.01).powi(2), ii_d);
        assert!(close(mu, 0.0432, 1e-5), "{mu}");
        assert_eq!(sps_viscosity(1000.0, 1.44e-6, -1e-9), 0.0);
    }

    #[test]
    fn velocity_gradient_index_order() {
        // One neighbour, V = 2, u_j - u_i = (1, 2, 0), grad_i W = (3, 0, 0): only du/dx is seen,
        // G[a][0] = 2 * du_a * 3.
        let g = velocity_gradient(&[2.0], &[[1.0, 2.0, 0.0]], &[[3.0, 0.0, 0.0]]);
        assert_eq!(g[0][0], 6.0);
        assert_eq!(g[1][0], 12.0);
        for (a, row) in g.iter().enumerate() {
            for (b, &x) in row.iter().enumerate() {
                if b != 0 {
                    assert_eq!(x, 0.0, "G[{a}][{b}]");
                }
            }
        }
    }

    #[test]
    fn velocity_gradient_of_shear_flow_on_lattice() {
        // u_x = gamma y on a 2-D unit lattice with h/dx = 2: the sum gives gamma M_yy, and M_yy
        // equals the M_xx of the shared kernel table (0.999199) by the lattice's symmetry.
        let (gamma, dx, h) = (3.0_f32, 1.0_f32, 2.0_f32);
        let n = 5;
        let (mut vols, mut dus, mut grads) = (Vec::new(), Vec::new(), Vec::new());
        for ky in -n..=n {
            for kx in -n..=n {
                let xj = [kx as f32 * dx, ky as f32 * dx, 0.0];
                let r = (xj[0] * xj[0] + xj[1] * xj[1]).sqrt();
                let f = grad_factor(r, h, 2);
                vols.push(dx * dx);
                dus.push([gamma * xj[1], 0.0, 0.0]);
                // x_i = 0, so grad_i W_ij = (x_i - x_j) F = -x_j F.
                grads.push([-xj[0] * f, -xj[1] * f, 0.0]);
            }
        }
        let g = velocity_gradient(&vols, &dus, &grads);
        assert!((g[0][1] - gamma * 0.999_199).abs() < 1e-5 * gamma, "{g:?}");
        for (a, b) in [(0, 0), (1, 0), (1, 1)] {
            assert!(g[a][b].abs() < 1e-6, "G[{a}][{b}] = {}", g[a][b]);
        }
    }

    #[test]
    fn simple_shear_strain_rate_and_invariant() {
        // du_x/dy = gamma: eps_xy = eps_yx = gamma / 2, II_D = 1/2 * 2 (gamma/2)^2 = gamma^2 / 4.
        let gamma = 4.0;
        let mut grad = [[0.0; 3]; 3];
        grad[0][1] = gamma;
        for dim in [2, 3] {
            let eps = strain_rate(&grad, dim);
            assert_eq!(eps[0][1], 2.0);
            assert_eq!(eps[1][0], 2.0);
            assert_eq!(eps[0][0], 0.0);
            assert_eq!(eps[1][1], 0.0);
            assert_eq!(second_invariant(&eps), 4.0);
        }
    }

    #[test]
    fn trace_removed_with_one_third() {
        // Isotropic expansion: deviatoric, so zero in 3-D; in 2-D the 1/3 of MODEL.md leaves
        // eps_xx = eps_yy = a - 2a/3 = a/3.
        let a = 0.3_f32;
        let grad3 = [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]];
        let eps = strain_rate(&grad3, 3);
        for row in eps {
            for x in row {
                assert!(x.abs() < 1e-7);
            }
        }
        let grad2 = [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, 0.0]];
        let eps = strain_rate(&grad2, 2);
        assert!((eps[0][0] - 0.1).abs() < 1e-7);
        assert!((eps[1][1] - 0.1).abs() < 1e-7);
        assert_eq!(eps[2][2], 0.0);
    }

    #[test]
    fn strain_rate_is_symmetric_and_ignores_out_of_plane_in_2d() {
        let grad = [[1.0, 2.0, 3.0], [-4.0, 5.0, 6.0], [7.0, 8.0, -9.0]];
        let eps = strain_rate(&grad, 3);
        for (a, row) in eps.iter().enumerate() {
            for (b, &x) in row.iter().enumerate() {
                assert_eq!(x, eps[b][a]);
            }
        }
        // Off-diagonal: 1/2 (2 - 4) = -1; trace 1 + 5 - 9 = -3, so eps_xx = 1 + 1 = 2.
        assert_eq!(eps[0][1], -1.0);
        assert_eq!(eps[0][0], 2.0);
        let eps2 = strain_rate(&grad, 2);
        // Trace in the plane: 6, so eps_xx = 1 - 2 = -1, eps_yy = 5 - 2 = 3.
        assert_eq!(eps2[0][0], -1.0);
        assert_eq!(eps2[1][1], 3.0);
        assert_eq!(eps2[0][2], 0.0);
        assert_eq!(eps2[2][1], 0.0);
        assert_eq!(eps2[2][2], 0.0);
    }

    #[test]
    fn hbp_newtonian_limit() {
        // m = 0, n = 1: Eq. 15 gives 2 mu_s at every strain rate (zero included), so the stress
        // tau = 2 mu eps is 2 (2 mu_s) eps: Newtonian, with viscosity 2 mu_s as written.
        let mu_s = 0.75_f32;
        for ii_d in [0.0, 1e-12, 1e-3, 1.0, 1e6] {
            assert_eq!(
                hbp_viscosity(ii_d, 123.0, 0.0, 1.0, mu_s),
                2.0 * mu_s,
                "{ii_d}"
            );
        }
        let mut grad = [[0.0; 3]; 3];
        grad[0][1] = 4.0;
        let eps = strain_rate(&grad, 2);
        let mu = hbp_viscosity(second_invariant(&eps), 50.0, 0.0, 1.0, mu_s);
        let tau = viscous_stress(mu, &eps);
        assert_eq!(tau[0][1], 2.0 * (2.0 * mu_s) * eps[0][1]);
        assert_eq!(tau[0][1], 6.0);
    }

    #[test]
    fn hbp_bingham_limit() {
        // n = 1, m large: exp(-m sqrt(II_D)) vanishes, so
        // mu sqrt(II_D) = tau_c + 2 mu_s sqrt(II_D).
        let (tau_c, mu_s) = (40.0_f32, 0.5_f32);
        for s in [0.01_f32, 0.5, 3.0] {
            let mu = hbp_viscosity(s * s, tau_c, 1e5, 1.0, mu_s);
            let expected = tau_c + 2.0 * mu_s * s;
            assert!(
                close(mu * s, expected, 1e-6),
                "s {s}: {} vs {expected}",
                mu * s
            );
        }
        // The stress invariant at the onset of flow is then 2 tau_c (see the module doc).
        let mut grad = [[0.0; 3]; 3];
        grad[0][1] = 1e-3;
        let eps = strain_rate(&grad, 2);
        let mu = hbp_viscosity(second_invariant(&eps), tau_c, 1e9, 1.0, mu_s);
        let sqrt_j2 = second_invariant(&viscous_stress(mu, &eps)).sqrt();
        assert!(close(sqrt_j2, 2.0 * tau_c, 1e-4), "{sqrt_j2}");
    }

    #[test]
    fn hbp_by_hand_shear_thickening() {
        // The Louvain parameters m = 100, n = 1.2 with tau_c = 10 Pa, mu_s = 0.1 Pa s, II_D = 1:
        // 10 (1 - e^-100) + 0.2 * 4^0.1 = 10 + 0.2 * 1.148698355 = 10.229739671.
        let mu = hbp_viscosity(1.0, 10.0, 100.0, 1.2, 0.1);
        assert!(close(mu, 10.229_74, 1e-6), "{mu}");
        // II_D = 1/4 makes 4 II_D = 1: 10 / 0.5 (1 - e^-50) + 0.2 = 20.2.
        let mu = hbp_viscosity(0.25, 10.0, 100.0, 1.2, 0.1);
        assert!(close(mu, 20.2, 1e-6), "{mu}");
    }

    #[test]
    fn hbp_finite_at_zero_strain_rate() {
        // Limit of tau_c (1 - exp(-m s)) / s is tau_c m: 10 * 100 + 2 * 0.1 (n = 1).
        assert_eq!(hbp_viscosity(0.0, 10.0, 100.0, 1.0, 0.1), 1000.2);
        // Rounding noise below zero is read as zero.
        assert_eq!(hbp_viscosity(-1e-20, 10.0, 100.0, 1.0, 0.1), 1000.2);
        // n > 1: the power-law term vanishes with the strain rate.
        assert_eq!(hbp_viscosity(0.0, 10.0, 100.0, 1.2, 0.1), 1000.0);
        // n < 1 diverges, as the model does.
        assert!(hbp_viscosity(0.0, 10.0, 100.0, 0.8, 0.1).is_infinite());
    }

    #[test]
    fn papanastasiou_factor_matches_f64_through_the_switch() {
        // Against -expm1(-x) / x in f64 from deep in the series branch to far in the closed form.
        let mut x = 1e-9_f64;
        while x < 50.0 {
            let exact = -(-x).exp_m1() / x;
            let got = f64::from(papanastasiou_factor(x as f32));
            // x as f32 is rounded; exact at the rounded argument.
            let xr = f64::from(x as f32);
            let exact_r = -(-xr).exp_m1() / xr;
            assert!(
                (got - exact_r).abs() <= 2e-6 * exact_r,
                "x {x}: {got} vs {exact} ({exact_r})"
            );
            x *= 1.07;
        }
        // Both sides of the switch agree.
        let below = papanastasiou_factor(PAPANASTASIOU_SERIES_LIMIT * (1.0 - 1e-6));
        let at = papanastasiou_factor(PAPANASTASIOU_SERIES_LIMIT);
        assert!(close(below, at, 2e-6), "{below} vs {at}");
        assert_eq!(papanastasiou_factor(0.0), 1.0);
    }
}
