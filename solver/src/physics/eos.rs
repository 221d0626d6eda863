//! Tait equation of state with gamma = 7 (Monaghan 1994; Zubeldia et al. 2018, Eq. 4):
//! `p = B ((rho / rho0)^7 - 1)`, `B = c0^2 rho0 / 7`.

/// Tait stiffness `B = c0^2 rho0 / 7`, Pa.
pub fn tait_b(c0: f32, rho0: f32) -> f32 {
    c0 * c0 * rho0 / 7.0
}

/// Pressure from density, Pa.
///
/// The seventh power is built from products in this exact order because the GPU shader does the
/// same, so both round identically (powf would not).
pub fn pressure(rho: f32, rho0: f32, b: f32) -> f32 {
    let x = rho / rho0;
    let x2 = x * x;
    let x4 = x2 * x2;
    let x7 = x4 * x2 * x;
    b * (x7 - 1.0)
}

/// Speed of sound from DualSPHysics' `coefsound`: `c0 = coefsound sqrt(g hswl)`, m/s, with `g` the
/// gravity magnitude (m/s2) and `hswl` the still-water height (m).
pub fn c0_from_coefsound(coefsound: f64, g: f64, hswl: f64) -> f64 {
    coefsound * (g * hswl).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stiffness_by_hand() {
        // 20^2 * 1000 / 7 = 57142.857...
        assert!((tait_b(20.0, 1000.0) - 57_142.857).abs() < 0.01);
        // 70^2 * 1000 / 7 = 700000 exactly.
        assert_eq!(tait_b(70.0, 1000.0), 700_000.0);
    }

    #[test]
    fn pressure_by_hand() {
        let b = 700_000.0;
        assert_eq!(pressure(1000.0, 1000.0, b), 0.0);
        // 1.01^7 = 1.0721353521...; p = 700000 * 0.0721353521 = 50494.746...
        let p = pressure(1010.0, 1000.0, b);
        assert!((p - 50_494.746).abs() < 0.1, "{p}");
        // 0.99^7 = 0.9320653479...; p = 700000 * (-0.0679346521) = -47554.256...
        let p = pressure(990.0, 1000.0, b);
        assert!((p + 47_554.256).abs() < 0.1, "{p}");
        // rho = 2 rho0: 2^7 - 1 = 127 exactly.
        assert_eq!(pressure(2000.0, 1000.0, 1.0), 127.0);
    }

    #[test]
    fn coefsound_by_hand() {
        // 10 sqrt(9.81 * 0.4) = 10 * 1.98090888... = 19.8090888...
        let c0 = c0_from_coefsound(10.0, 9.81, 0.4);
        assert!((c0 - 19.809_088_82).abs() < 1e-7, "{c0}");
        assert_eq!(c0_from_coefsound(20.0, 10.0, 0.1), 20.0);
    }
}
