//! Wendland C2 smoothing kernel with support 2h (Wendland 1995; Zubeldia et al. 2018, Eq. 8).
//!
//! `W(q) = a_d (1 - q/2)^4 (2q + 1)` for `q = r/h < 2`, with `a_d = 7 / (4 pi h^2)` in 2-D and
//! `21 / (16 pi h^3)` in 3-D.

use super::lanes::Real;
use std::f32::consts::PI;

/// Normalisation constant a_d of the Wendland C2 kernel; `dim` is 2 or 3 (anything else is 3-D).
pub fn alpha_d(dim: u32, h: f32) -> f32 {
    debug_assert!(dim == 2 || dim == 3, "dim must be 2 or 3, got {dim}");
    if dim == 2 {
        7.0 / (4.0 * PI * h * h)
    } else {
        21.0 / (16.0 * PI * h * h * h)
    }
}

/// Kernel value W(r, h), 1/m^dim.
pub fn w(r: f32, h: f32, dim: u32) -> f32 {
    Wendland::new(h, dim).w(r)
}

/// Factor F with `grad_i W_ij = (x_i - x_j) F`, i.e. `F = (dW/dr) / r`.
///
/// Dividing dW/dr by r analytically removes the 0/0 at r = 0, so F stays finite for coincident
/// particles (F(0) = -5 a_d / h^2).
pub fn grad_factor(r: f32, h: f32, dim: u32) -> f32 {
    Wendland::new(h, dim).grad_factor(r)
}

/// The kernel's gradient with its constants worked out once for a smoothing length: a
/// neighbour loop calls it for every pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wendland {
    inv_h: f32,
    ad: f32,
    /// `-5 a_d / h^2`.
    grad_coef: f32,
}

impl Wendland {
    pub fn new(h: f32, dim: u32) -> Wendland {
        Wendland {
            inv_h: 1.0 / h,
            ad: alpha_d(dim, h),
            grad_coef: alpha_d(dim, h) * (-5.0 / (h * h)),
        }
    }

    /// W of [`w`].
    #[inline(always)]
    pub fn w<L: Real>(&self, r: L) -> L {
        let s = L::splat;
        let q = r * s(self.inv_h);
        let t = s(1.0) - s(0.5) * q;
        let t2 = t * t;
        L::select(
            q.lt(s(2.0)),
            s(self.ad) * t2 * t2 * (s(2.0) * q + s(1.0)),
            s(0.0),
        )
    }

    /// F of [`grad_factor`].
    #[inline(always)]
    pub fn grad_factor<L: Real>(&self, r: L) -> L {
        let s = L::splat;
        let q = r * s(self.inv_h);
        let t = s(1.0) - s(0.5) * q;
        L::select(q.lt(s(2.0)), s(self.grad_coef) * (t * t * t), s(0.0))
    }
}

/// Smoothing length `h = coefh sqrt(dim) dp` (DualSPHysics convention), m.
pub fn smoothing_length(coefh: f64, dim: u32, dp: f64) -> f64 {
    coefh * f64::from(dim).sqrt() * dp
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shared validation table, two levels above the solver crate.
    const KERNEL_VALUES: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/validation/kernel_consistency_values.txt"
    );

    // f64 twins of the production functions: the lattice sums below must reproduce the table to
    // 1e-5, which f32 rounding of each term would blur.
    fn alpha_d64(dim: u32, h: f64) -> f64 {
        if dim == 2 {
            7.0 / (4.0 * std::f64::consts::PI * h * h)
        } else {
            21.0 / (16.0 * std::f64::consts::PI * h * h * h)
        }
    }

    fn w64(r: f64, h: f64, dim: u32) -> f64 {
        let q = r / h;
        if q < 2.0 {
            alpha_d64(dim, h) * (1.0 - 0.5 * q).powi(4) * (2.0 * q + 1.0)
        } else {
            0.0
        }
    }

    fn grad_factor64(r: f64, h: f64, dim: u32) -> f64 {
        let q = r / h;
        if q < 2.0 {
            alpha_d64(dim, h) * (-5.0 / (h * h)) * (1.0 - 0.5 * q).powi(3)
        } else {
            0.0
        }
    }

    #[test]
    fn normalised_over_plane_and_space() {
        // Radial midpoint quadrature: the integrand is smooth on [0, 2h], so 20 000 intervals are
        // far more than enough for 1e-6.
        for dim in [2, 3] {
            let h = 0.037_f32;
            let n = 20_000;
            let dr = 2.0 * f64::from(h) / f64::from(n);
            let mut integral = 0.0_f64;
            for k in 0..n {
                let r = (f64::from(k) + 0.5) * dr;
                let shell = if dim == 2 {
                    2.0 * std::f64::consts::PI * r
                } else {
                    4.0 * std::f64::consts::PI * r * r
                };
                integral += f64::from(w(r as f32, h, dim)) * shell * dr;
            }
            assert!(
                (integral - 1.0).abs() < 1e-5,
                "dim {dim}: integral {integral}"
            );
        }
    }

    #[test]
    fn zero_outside_support_and_nonnegative() {
        for dim in [2, 3] {
            let h = 0.5;
            assert_eq!(w(2.0 * h, h, dim), 0.0);
            assert_eq!(w(3.0 * h, h, dim), 0.0);
            assert_eq!(grad_factor(2.0 * h, h, dim), 0.0);
            for k in 0..200 {
                let r = k as f32 * 0.01 * h;
                assert!(w(r, h, dim) >= 0.0);
                assert!(grad_factor(r, h, dim) <= 0.0);
            }
        }
    }

    #[test]
    fn grad_factor_matches_finite_difference() {
        for dim in [2, 3] {
            let h = 0.02_f64;
            for k in 1..200 {
                let r = f64::from(k) * 0.01 * h;
                let e = 1e-6 * h;
                let dwdr = (w64(r + e, h, dim) - w64(r - e, h, dim)) / (2.0 * e);
                let f = grad_factor(r as f32, h as f32, dim);
                let scale = grad_factor64(0.0, h, dim).abs() * r;
                assert!(
                    (f64::from(f) * r - dwdr).abs() <= 1e-5 * scale,
                    "dim {dim} r/h {}: F r = {}, dW/dr = {dwdr}",
                    r / h,
                    f64::from(f) * r
                );
            }
        }
    }

    #[test]
    fn f32_agrees_with_f64() {
        for dim in [2, 3] {
            for h in [0.01_f32, 0.017, 1.0, 3.3] {
                let w0 = w64(0.0, f64::from(h), dim);
                let f0 = grad_factor64(0.0, f64::from(h), dim).abs();
                for k in 0..400 {
                    let r = k as f32 * 0.005 * h;
                    let (r64, h64) = (f64::from(r), f64::from(h));
                    let (wr, fr) = (w64(r64, h64, dim), grad_factor64(r64, h64, dim));
                    // Near q = 2 the factor (1 - q/2) cancels, so the rounding of q = r/h alone
                    // exceeds 1e-6 relative there; measure those against the peak value instead.
                    let q = r64 / h64;
                    let (wtol, ftol) = if q <= 1.5 {
                        (1e-6 * wr.abs(), 1e-6 * fr.abs())
                    } else {
                        (1e-6 * w0, 1e-6 * f0)
                    };
                    assert!(
                        (f64::from(w(r, h, dim)) - wr).abs() <= wtol,
                        "w dim {dim} q {q}"
                    );
                    assert!(
                        (f64::from(grad_factor(r, h, dim)) - fr).abs() <= ftol,
                        "F dim {dim} q {q}"
                    );
                }
            }
        }
    }

    #[test]
    fn smoothing_length_convention() {
        let h = smoothing_length(1.2, 2, 0.01);
        assert!((h - 1.2 * 2.0_f64.sqrt() * 0.01).abs() < 1e-15);
        let h = smoothing_length(1.0, 3, 1.0);
        assert!((h - 3.0_f64.sqrt()).abs() < 1e-15);
    }

    struct Row {
        dim: u32,
        h_over_dx: f64,
        sum_vw: f64,
        m_xx: f64,
    }

    /// Number after `key` up to the next space, ':' or ';'.
    fn field(line: &str, key: &str) -> Result<f64, String> {
        let start = line
            .find(key)
            .ok_or_else(|| format!("no '{key}' in: {line}"))?
            + key.len();
        let rest = line[start..].trim_start();
        let end = rest.find([' ', ':', ';']).unwrap_or(rest.len());
        rest[..end]
            .parse()
            .map_err(|e| format!("bad number after '{key}' in: {line}: {e}"))
    }

    /// WendlandC2 rows only: the CubicSpline rows are for a kernel this solver does not use.
    fn wendland_rows(text: &str) -> Result<Vec<Row>, String> {
        let mut rows = Vec::new();
        for line in text
            .lines()
            .filter(|l| l.trim_start().starts_with("WendlandC2"))
        {
            let dim = if line.contains(" 2D ") {
                2
            } else if line.contains(" 3D ") {
                3
            } else {
                return Err(format!("no dimension in: {line}"));
            };
            rows.push(Row {
                dim,
                h_over_dx: field(line, "h/dx=")?,
                sum_vw: field(line, "sum V W =")?,
                m_xx: field(line, "M_xx =")?,
            });
        }
        Ok(rows)
    }

    /// Lattice sums about a particle at the origin of a unit-spacing Cartesian lattice
    /// (V_j = dx^dim), self term included:
    /// - `sum_j V_j W(x_j)` (Shepard sum, 1 in the continuum);
    /// - `M_xx = sum_j V_j (x_j - x_i)_x (grad_i W_ij)_x`, the xx entry of the gradient-consistency
    ///   matrix (a gradient estimate `sum_j V_j (f_j - f_i) grad_i W_ij` is exact for linear f only
    ///   when this matrix is I, its continuum value).
    fn lattice_sums(
        dim: u32,
        h_over_dx: f64,
        kernel_w: impl Fn(f64, f64) -> f64,
        kernel_f: impl Fn(f64, f64) -> f64,
    ) -> (f64, f64) {
        let dx = 1.0_f64;
        let h = h_over_dx * dx;
        let vol = dx.powi(dim as i32);
        let n = (2.0 * h / dx).ceil() as i32 + 1;
        let zs = if dim == 3 { -n..=n } else { 0..=0 };
        let (mut sum_vw, mut m_xx) = (0.0, 0.0);
        for kz in zs {
            for ky in -n..=n {
                for kx in -n..=n {
                    let xj = [f64::from(kx) * dx, f64::from(ky) * dx, f64::from(kz) * dx];
                    let r = (xj[0] * xj[0] + xj[1] * xj[1] + xj[2] * xj[2]).sqrt();
                    // x_i = 0, so x_ij = -x_j and grad_i W_ij = -x_j F.
                    let grad_x = -xj[0] * kernel_f(r, h);
                    sum_vw += vol * kernel_w(r, h);
                    m_xx += vol * xj[0] * grad_x;
                }
            }
        }
        (sum_vw, m_xx)
    }

    #[test]
    fn lattice_sums_match_validation_table() {
        let text = std::fs::read_to_string(KERNEL_VALUES)
            .unwrap_or_else(|e| panic!("cannot read {KERNEL_VALUES}: {e}"));
        let rows = wendland_rows(&text).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(rows.len(), 10, "expected 5 h/dx values in 2-D and 3-D");
        for row in rows {
            let (dim, hdx) = (row.dim, row.h_over_dx);
            let (s, m) = lattice_sums(
                dim,
                hdx,
                |r, h| w64(r, h, dim),
                |r, h| grad_factor64(r, h, dim),
            );
            assert!(
                (s - row.sum_vw).abs() < 1e-5,
                "{dim}D h/dx={hdx}: sum V W {s} vs {}",
                row.sum_vw
            );
            assert!(
                (m - row.m_xx).abs() < 1e-5,
                "{dim}D h/dx={hdx}: M_xx {m} vs {}",
                row.m_xx
            );
            // The production f32 functions give the same table (terms summed in f64).
            let (s32, m32) = lattice_sums(
                dim,
                hdx,
                |r, h| f64::from(w(r as f32, h as f32, dim)),
                |r, h| f64::from(grad_factor(r as f32, h as f32, dim)),
            );
            assert!(
                (s32 - row.sum_vw).abs() < 1e-5,
                "{dim}D h/dx={hdx}: f32 sum V W {s32}"
            );
            assert!(
                (m32 - row.m_xx).abs() < 1e-5,
                "{dim}D h/dx={hdx}: f32 M_xx {m32}"
            );
        }
    }
}
