//! The Shields criterion's formulas against hand-computed values and the validation table.

use super::*;

const NU: f32 = 1.0e-6;
const DEG: f32 = std::f32::consts::PI / 180.0;

/// The shared validation table, two levels above the solver crate.
const SHIELDS_VALUES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../shared/validation/shields_reference_values.txt"
);

fn rel(a: f32, b: f32) -> f32 {
    (a - b).abs() / b.abs()
}

#[test]
fn critical_shields_by_hand() {
    // Re* = 1: 0 + 0.110476 + 0.0027197 = 0.1131957.
    assert!((critical_shields(1.0) - 0.113_195_7).abs() < 1e-7);
    // Re* = 10: 0.010595 * 2.302585 + 0.0110476 + 0.0027197 = 0.0381632 (near the minimum
    // of the curve, at Re* = 0.110476 / 0.010595 = 10.43).
    assert!((critical_shields(10.0) - 0.038_163_2).abs() < 1e-7);
    // Far above 500 it is the constant.
    assert_eq!(critical_shields(1e4), 0.068);
    assert_eq!(critical_shields(0.0), f32::INFINITY);
    assert_eq!(critical_shields(-1.0), f32::INFINITY);
    assert!(critical_shields(f32::NAN).is_nan());
}

#[test]
fn critical_shields_jumps_at_500() {
    // Below: 0.010595 ln(499.9) + 0.110476 / 499.9 + 0.0027197 = 0.0687823.
    let below = critical_shields(499.9);
    assert!((below - 0.068_782_3).abs() < 2e-7, "{below}");
    // The left limit at 500 is 0.0687844; from 500 on the constant 0.068: a jump of -7.8e-4,
    // as Eq. 17 is written.
    let left_limit = critical_shields(500.0 * (1.0 - f32::EPSILON));
    assert!((left_limit - 0.068_784_4).abs() < 2e-7, "{left_limit}");
    assert_eq!(critical_shields(500.0), 0.068);
    assert_eq!(critical_shields(500.1), 0.068);
}

#[test]
fn stresses_by_hand() {
    // Eq. 16: 0.05 * (2650 - 1000) * 9.81 * 0.001 = 0.809325 Pa.
    let t = critical_bed_shear_stress(0.05, 2650.0, 1000.0, 9.81, 0.001);
    assert!((t - 0.809_325).abs() < 1e-6, "{t}");
    // Eq. 18: 1000 * 0.02^2 = 0.4 Pa.
    assert!((bed_shear_stress(1000.0, 0.02) - 0.4).abs() < 1e-7);
}

#[test]
fn roughness_length_regimes() {
    let ks = 1.2e-3;
    // Re_k = ks u* / nu: u* = 5 nu / ks is exactly smooth-limit, 70 nu / ks rough.
    let u_smooth = 2e-3; // Re_k = 2.4
    assert_eq!(roughness_regime(u_smooth, ks, NU), Roughness::Smooth);
    assert!(rel(roughness_length(u_smooth, ks, NU), 0.11 * NU / u_smooth) < 1e-6);
    let u_trans = 2e-2; // Re_k = 24
    assert_eq!(roughness_regime(u_trans, ks, NU), Roughness::Transitional);
    let z0 = 0.11 * NU / u_trans + 0.033 * ks; // 5.5e-6 + 3.96e-5
    assert!(rel(roughness_length(u_trans, ks, NU), z0) < 1e-6);
    let u_rough = 0.1; // Re_k = 120
    assert_eq!(roughness_regime(u_rough, ks, NU), Roughness::Rough);
    assert!(rel(roughness_length(u_rough, ks, NU), 0.033 * ks) < 1e-6);
    // The limits themselves: Re_k = 5 is smooth, 70 rough (Eq. 21's <= and >=).
    assert_eq!(roughness_regime(5.0, 1.0, 1.0), Roughness::Smooth);
    assert_eq!(roughness_regime(70.0, 1.0, 1.0), Roughness::Rough);
    // ks = 0: always smooth.
    assert_eq!(roughness_regime(10.0, 0.0, NU), Roughness::Smooth);
}

#[test]
fn velocity_profile_by_hand() {
    // Sub-layer: u* = 0.01, delta = 11.6e-6 / 0.01 = 1.16 mm; at z = 1 mm,
    // u = 1e-4 * 1e-3 / 1e-6 = 0.1 m/s.
    assert!(rel(velocity_profile(1e-3, 0.01, 0.0, NU), 0.1) < 1e-6);
    // Smooth log law at z = 2 cm, u* = 2e-3: z / z0 = 0.02 * 2e-3 / 1.1e-7 = 363.636,
    // u = (2e-3 / 0.41) ln(363.636) = 0.0287617 m/s.
    let u = velocity_profile(0.02, 2e-3, 1.2e-3, NU);
    assert!(rel(u, 0.028_761_7) < 1e-5, "{u}");
    // Rough, u* = 0.1, ks = 1.2 mm: z0 = 3.96e-5; at 2 cm, u = 0.243902 ln(505.0505)
    // = 1.518209 m/s.
    let u = velocity_profile(0.02, 0.1, 1.2e-3, NU);
    assert!(rel(u, 1.518_209) < 1e-5, "{u}");
    assert_eq!(velocity_profile(0.02, 0.0, 1.2e-3, NU), 0.0);
    // The drop at the top of the sub-layer (smooth): 11.6 u* below, 11.36 u* above.
    let (z, u_star_top) = (0.01_f32, SUBLAYER_WALL_UNITS * NU / 0.01);
    let below = velocity_profile(z, u_star_top * (1.0 - 1e-5), 0.0, NU) / u_star_top;
    let above = velocity_profile(z, u_star_top * (1.0 + 1e-5), 0.0, NU) / u_star_top;
    assert!((below - 11.6).abs() < 1e-3, "{below}");
    assert!((above - 11.361_66).abs() < 1e-3, "{above}");
}

/// Speeds reached from one u*, in each layer and regime, all with a unique root.
#[test]
fn friction_velocity_round_trip_by_regime() {
    let cases: [(&str, f32, f32, f32); 8] = [
        // (what, z, ks, u*)
        ("sub-layer", 1e-3, 1.2e-3, 0.005),
        ("sub-layer, slow", 1e-4, 1.2e-3, 1e-5),
        ("smooth log, ks = 0", 0.02, 0.0, 0.01),
        ("smooth log", 0.02, 1.2e-3, 2e-3),
        ("transitional", 0.02, 1.2e-3, 0.02),
        ("transitional, coarse", 0.05, 3.5e-3, 0.005),
        ("rough", 0.02, 1.2e-3, 0.1),
        ("rough, Louvain ks", 0.05, 1.75e-2, 0.05),
    ];
    for (what, z, ks, u_star) in cases {
        let u = velocity_profile(z, u_star, ks, NU);
        let r = friction_velocity(u, z, ks, NU);
        assert!(r.converged, "{what}: {r:?}");
        assert!(
            rel(r.u_star, u_star) < 1e-5,
            "{what}: u = {u}, u* {u_star} -> {r:?}"
        );
    }
}

/// The smallest-root rule, checked against a dense scan of the profile below the answer.
fn assert_smallest_root(u: f32, z: f32, ks: f32, u_star: f32, what: &str) {
    let mut s = 1e-9_f32;
    while s < u_star * (1.0 - 1e-4) {
        let v = velocity_profile(z, s, ks, NU);
        assert!(
            v < u * (1.0 + 1e-5),
            "{what}: profile reaches u = {u} at u* = {s} below the answer {u_star}"
        );
        s *= 1.002;
    }
}

#[test]
fn friction_velocity_round_trip_sweep() {
    let (mut exact, mut smaller_root) = (0, 0);
    let mut exact_by_layer = [0; 4];
    for &ks in &[0.0_f32, 1e-4, 4e-4, 1.2e-3, 3.5e-3, 1.75e-2] {
        for kz in 0..12 {
            let z = 1e-4_f32 * 500.0_f32.powf(kz as f32 / 11.0);
            for ku in 0..40 {
                let u_star = 1e-5_f32 * 1e5_f32.powf(ku as f32 / 39.0);
                let u = velocity_profile(z, u_star, ks, NU);
                if !(1e-6..=5.0).contains(&u) {
                    continue;
                }
                let what = format!("ks {ks} z {z} u* {u_star} u {u}");
                let r = friction_velocity(u, z, ks, NU);
                assert!(r.converged, "{what}: {r:?}");
                assert!(r.iterations <= 6, "{what}: {r:?}");
                let back = velocity_profile(z, r.u_star, ks, NU);
                if rel(r.u_star, u_star) < 1e-5 {
                    exact += 1;
                    let layer = if z <= sublayer_thickness(u_star, NU) {
                        0
                    } else {
                        1 + roughness_regime(u_star, ks, NU) as usize
                    };
                    exact_by_layer[layer] += 1;
                } else {
                    // Where two pieces of the profile both reach u, the smaller u* is
                    // returned; it must still reproduce u.
                    assert!(r.u_star < u_star, "{what}: {r:?}");
                    assert!(rel(back, u) < 1e-5, "{what}: back {back} {r:?}");
                    smaller_root += 1;
                }
                assert_smallest_root(u, z, ks, r.u_star, &what);
            }
        }
    }
    assert!(
        exact > 10 * smaller_root,
        "{exact} exact, {smaller_root} smaller"
    );
    for (layer, n) in exact_by_layer.iter().enumerate() {
        assert!(*n > 20, "layer {layer}: only {n} exact round trips");
    }
}

#[test]
fn friction_velocity_converges_over_the_working_range() {
    // u from 1e-6 to 5 m/s, z from 0.1 mm to 5 cm, roughness from none to the Louvain
    // pellets' 5 d50. It converges everywhere except where no u* exists (z inside the rough
    // bed's roughness height and u above what the sub-layer reaches).
    for &ks in &[0.0_f32, 1e-4, 4e-4, 1.2e-3, 3.5e-3, 1.75e-2] {
        for kz in 0..15 {
            let z = 1e-4_f32 * 500.0_f32.powf(kz as f32 / 14.0);
            for ku in 0..60 {
                let u = 1e-6_f32 * 5e6_f32.powf(ku as f32 / 59.0);
                let what = format!("ks {ks} z {z} u {u}");
                let r = friction_velocity(u, z, ks, NU);
                assert!(r.iterations <= 6, "{what}: {r:?}");
                let sublayer_max = SUBLAYER_WALL_UNITS * SUBLAYER_WALL_UNITS * NU / z;
                if !r.converged {
                    assert!(z <= 0.033 * ks * (1.0 + 1e-6), "{what}: {r:?}");
                    assert!(u > sublayer_max * (1.0 - 1e-6), "{what}: {r:?}");
                    assert!(rel(r.u_star, SUBLAYER_WALL_UNITS * NU / z) < 1e-6);
                    continue;
                }
                assert!(r.u_star > 0.0 && r.u_star.is_finite(), "{what}: {r:?}");
                // Either the profile gives u back, or u is in the gap of the upward jump at
                // Re_k = 70 and the answer is that jump.
                let back = velocity_profile(z, r.u_star, ks, NU);
                let at_jump = ks > 0.0 && rel(r.u_star, ROUGH_RE_K * NU / ks) < 1e-6;
                assert!(rel(back, u) < 1e-5 || at_jump, "{what}: back {back} {r:?}");
                assert_smallest_root(u, z, ks, r.u_star, &what);
            }
        }
    }
}

#[test]
fn friction_velocity_edge_cases() {
    assert_eq!(
        friction_velocity(0.0, 0.01, 1e-3, NU),
        FrictionVelocity {
            u_star: 0.0,
            iterations: 0,
            converged: true
        }
    );
    for (u, z, ks, nu) in [
        (-1.0, 0.01, 1e-3, NU),
        (f32::NAN, 0.01, 1e-3, NU),
        (1.0, 0.0, 1e-3, NU),
        (1.0, 0.01, -1e-3, NU),
        (1.0, 0.01, 1e-3, 0.0),
        (f32::INFINITY, 0.01, 1e-3, NU),
    ] {
        let r = friction_velocity(u, z, ks, nu);
        assert!(!r.converged && r.u_star == 0.0, "{u} {z} {ks} {nu}: {r:?}");
    }
    // Inside the roughness height of a rough bed (z = 0.1 mm < 0.033 * 17.5 mm): slow enough
    // for the sub-layer, u* = sqrt(1 * 1e-6 / 1e-4) = 0.1; faster than its top
    // (11.6^2 nu / z = 1.3456 m/s), no solution.
    let r = friction_velocity(1.0, 1e-4, 1.75e-2, NU);
    assert!(r.converged && rel(r.u_star, 0.1) < 1e-6, "{r:?}");
    let r = friction_velocity(2.0, 1e-4, 1.75e-2, NU);
    assert!(!r.converged, "{r:?}");
    assert!(rel(r.u_star, 0.116) < 1e-6, "{r:?}");
}

#[test]
fn friction_velocity_in_the_gap_at_re_k_70() {
    // At u* = 70 nu / ks, z0 drops from 0.11 nu/u* + 0.033 ks to 0.033 ks, so u(z) jumps up
    // and the speeds in between have no exact root; the jump itself is returned.
    let (z, ks) = (0.02_f32, 1.2e-3_f32);
    let b = ROUGH_RE_K * NU / ks;
    let below = profile_in(Layer::Log(Roughness::Transitional), z, b, ks, NU);
    let above = profile_in(Layer::Log(Roughness::Rough), z, b, ks, NU);
    assert!(above > below * 1.005, "{below} {above}");
    let r = friction_velocity(0.5 * (below + above), z, ks, NU);
    assert!(r.converged, "{r:?}");
    assert_eq!(r.u_star, b);
}

#[test]
fn k_beta_and_k_gamma_by_hand() {
    let phi = 30.0 * DEG;
    assert_eq!(k_beta(0.0, phi, true), 1.0);
    assert_eq!(k_beta(0.0, phi, false), 1.0);
    assert_eq!(k_gamma(0.0, phi), 1.0);
    // beta = 10 deg: down sin 20 / sin 30 = 0.6840403, up sin 40 / sin 30 = 1.2855752.
    let down = k_beta(10.0 * DEG, phi, true);
    let up = k_beta(10.0 * DEG, phi, false);
    assert!((down - 0.684_040_3).abs() < 1e-6, "{down}");
    assert!((up - 1.285_575_2).abs() < 1e-6, "{up}");
    // Gravity helps a grain down a slope and holds it back going up.
    assert!(down < 1.0 && 1.0 < up);
    assert_eq!(k_beta(-10.0 * DEG, phi, true), down);
    // At and beyond the angle of repose nothing holds the grain.
    assert_eq!(k_beta(phi, phi, true), 0.0);
    assert_eq!(k_beta(40.0 * DEG, phi, true), 0.0);
    // gamma = 10 deg: cos 10 sqrt(1 - tan^2 10 / tan^2 30) = 0.9377554.
    let side = k_gamma(10.0 * DEG, phi);
    assert!((side - 0.937_755_4).abs() < 1e-6, "{side}");
    assert_eq!(k_gamma(-10.0 * DEG, phi), side);
    assert_eq!(k_gamma(phi, phi), 0.0);
    assert_eq!(k_gamma(45.0 * DEG, phi), 0.0);
    let t = sloped_critical_stress(0.5, down, side);
    assert!((t - 0.5 * 0.684_040_3 * 0.937_755_4).abs() < 1e-6);
}

#[test]
fn surface_test() {
    // m_f = 0.9 of a 1 kg reference: a kernel mass of 0.8 kg with water near is surface.
    assert!(is_surface(true, 0.8, 1.0, 0.9));
    assert!(!is_surface(false, 0.8, 1.0, 0.9));
    assert!(!is_surface(true, 0.95, 1.0, 0.9));
    assert!(!is_surface(true, 0.9, 1.0, 0.9));
}

struct Row {
    name: String,
    d: f32,
    rho_s: f32,
    /// (value, half a unit in its last printed digit) for th_Re*, Re*, tau_Re*.
    columns: [(f32, f32); 3],
}

/// Number right after `key` in `text`.
fn number_after(text: &str, key: &str) -> Result<f32, String> {
    let start = text
        .find(key)
        .ok_or_else(|| format!("no '{key}' in: {text}"))?
        + key.len();
    let rest = &text[start..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E')))
        .unwrap_or(rest.len());
    rest[..end]
        .parse()
        .map_err(|e| format!("bad number after '{key}' in: {text}: {e}"))
}

/// A printed number and half a unit of its last digit.
fn printed(token: &str) -> Result<(f32, f32), String> {
    let value: f32 = token
        .parse()
        .map_err(|e| format!("bad number {token}: {e}"))?;
    let decimals = token.split_once('.').map_or(0, |(_, frac)| frac.len());
    Ok((value, 0.5 * 10.0_f32.powi(-(decimals as i32))))
}

/// The constants of the first line and the rows of the case table (between the column header
/// and the first blank line).
struct Table {
    nu: f32,
    g: f32,
    rho_w: f32,
    rows: Vec<Row>,
}

fn table(text: &str) -> Result<Table, String> {
    let mut lines = text.lines();
    let head = lines.next().ok_or("empty file")?;
    let header = lines.next().ok_or("no column header")?;
    let names: Vec<&str> = header.split_whitespace().collect();
    let expected = ["th_Re*", "Re*", "tau_Re*"];
    if !names.ends_with(&expected) {
        return Err(format!("unexpected columns: {header}"));
    }
    let mut rows = Vec::new();
    for line in lines.take_while(|l| !l.trim().is_empty()) {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if tokens.len() < 9 {
            return Err(format!("short row: {line}"));
        }
        let n = tokens.len();
        let name = tokens[..n - 8].join(" ");
        let d_mm = number_after(&name, "d50=").or_else(|_| number_after(&name, " d="))?;
        rows.push(Row {
            d: d_mm * 1e-3,
            rho_s: number_after(&name, "rho_s=")?,
            columns: [
                printed(tokens[n - 3])?,
                printed(tokens[n - 2])?,
                printed(tokens[n - 1])?,
            ],
            name,
        });
    }
    Ok(Table {
        nu: number_after(head, "nu=")?,
        g: number_after(head, "g=")?,
        rho_w: number_after(head, "rho_w=")?,
        rows,
    })
}

#[test]
fn self_consistent_threshold_matches_validation_table() {
    let text = std::fs::read_to_string(SHIELDS_VALUES)
        .unwrap_or_else(|e| panic!("cannot read {SHIELDS_VALUES}: {e}"));
    let Table { nu, g, rho_w, rows } = table(&text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(rows.len(), 8, "expected the 8 sediments of the table");
    for row in rows {
        let c = critical_shields_self_consistent(row.d, row.rho_s, rho_w, nu, g)
            .unwrap_or_else(|| panic!("{}: rejected", row.name));
        assert!(c.converged, "{}: {c:?}", row.name);
        // Printed precision: half a unit of the last digit, plus f32 rounding of the value.
        let got = [c.theta_cr, c.re_star, c.tau_bcr0];
        for (k, (&v, (want, half_unit))) in got.iter().zip(row.columns).enumerate() {
            let tol = half_unit + 1e-6 * want.abs();
            assert!(
                (v - want).abs() <= tol,
                "{} column {k}: {v} vs printed {want} (tol {tol})",
                row.name
            );
        }
        // The fixed point: theta_cr is Eq. 17 at its own Re*.
        assert!(rel(critical_shields(c.re_star), c.theta_cr) < 1e-6, "{c:?}");
    }
}

#[test]
fn self_consistent_threshold_cycles_across_the_jump() {
    // Quartz of d = 6.0932 mm: theta = 0.068 gives Re* = 499.0, where Eq. 17 gives 0.068764,
    // which gives Re* = 501.8, where it is 0.068 again. No fixed point: reported.
    let c = critical_shields_self_consistent(6.093_2e-3, 2650.0, 1000.0, NU, 9.81)
        .unwrap_or_else(|| panic!("rejected"));
    assert!(!c.converged, "{c:?}");
    assert_eq!(c.iterations, CRITICAL_SHIELDS_MAX_ITERATIONS);
    // Just outside the sliver it settles at once.
    let c = critical_shields_self_consistent(6.2e-3, 2650.0, 1000.0, NU, 9.81)
        .unwrap_or_else(|| panic!("rejected"));
    assert!(
        c.converged && c.theta_cr == 0.068 && c.re_star > 500.0,
        "{c:?}"
    );
}

#[test]
fn self_consistent_threshold_rejects_floating_grains() {
    assert!(critical_shields_self_consistent(1e-3, 1000.0, 1000.0, NU, 9.81).is_none());
    assert!(critical_shields_self_consistent(1e-3, 900.0, 1000.0, NU, 9.81).is_none());
    assert!(critical_shields_self_consistent(0.0, 2650.0, 1000.0, NU, 9.81).is_none());
    assert!(critical_shields_self_consistent(1e-3, 2650.0, 1000.0, 0.0, 9.81).is_none());
    assert!(critical_shields_self_consistent(1e-3, f32::NAN, 1000.0, NU, 9.81).is_none());
}

#[test]
fn flat_bed_has_unit_slope_factor() {
    // Normal straight up: beta = gamma = 0, Eqs. 22-23 give sin(phi)/sin(phi) = 1 and
    // cos(0) sqrt(1 - 0) = 1, whichever way the water flows.
    for u in [[0.3, 0.0, 0.0], [-0.3, 0.0, 0.0]] {
        assert_eq!(slope_factors([0.0, 1.0, 0.0], u, 2, 30.0 * DEG), 1.0);
    }
    assert_eq!(
        slope_factors([0.0, 0.0, 2.0], [0.1, 0.2, 0.0], 3, 30.0 * DEG),
        1.0
    );
}

#[test]
fn slope_factor_by_hand() {
    // A 2-D bed sloping down towards +x at 10 deg: outward normal (sin 10, cos 10).
    // Flow towards +x runs down the slope: sin(30 - 10) / sin 30 = 0.342020 / 0.5 = 0.684040.
    // Flow towards -x runs up it: sin(40) / sin(30) = 0.642788 / 0.5 = 1.285575.
    let n = [(10.0 * DEG).sin(), (10.0 * DEG).cos(), 0.0];
    let down = slope_factors(n, [0.2, 0.0, 0.0], 2, 30.0 * DEG);
    let up = slope_factors(n, [-0.2, 0.0, 0.0], 2, 30.0 * DEG);
    assert!((down - 0.684_040).abs() < 1e-5, "{down}");
    assert!((up - 1.285_575).abs() < 1e-5, "{up}");
    // 3-D, the same tilt across a flow along y: gamma = 10 deg, beta = 0;
    // cos 10 sqrt(1 - tan^2 10 / tan^2 30) = 0.984808 sqrt(1 - 0.031091 / 0.333333)
    // = 0.984808 sqrt(0.906726) = 0.984808 * 0.952222 = 0.937755.
    let n3 = [(10.0 * DEG).sin(), 0.0, (10.0 * DEG).cos()];
    let across = slope_factors(n3, [0.0, 0.2, 0.0], 3, 30.0 * DEG);
    assert!((across - 0.937_755).abs() < 1e-5, "{across}");
}

#[test]
fn a_bed_that_faces_down_holds_no_grain() {
    // The roof of a hole, its normal 40 deg below the horizontal (beta = 130 deg): a flow
    // towards -x runs up that slope, where Eq. 22 alone would give sin(160) / sin(30) = 0.684;
    // towards +x down it, sin(-100) < 0. The grain hangs from the bed: no critical stress.
    let n = [(40.0 * DEG).cos(), -(40.0 * DEG).sin(), 0.0];
    for u in [[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0]] {
        assert_eq!(slope_factors(n, u, 2, 30.0 * DEG), 0.0, "{u:?}");
    }
    let n3 = [n[0], 0.0, n[1]];
    assert_eq!(slope_factors(n3, [-0.2, 0.1, 0.0], 3, 30.0 * DEG), 0.0);
    // Just above the horizontal, a wall of sand facing the flow still holds (beta = 89 deg:
    // sin(119) / sin(30) = 1.749).
    let wall = [(89.0 * DEG).sin(), (89.0 * DEG).cos(), 0.0];
    let k = slope_factors(wall, [-0.2, 0.0, 0.0], 2, 30.0 * DEG);
    assert!((k - 1.749_2).abs() < 1e-3, "{k}");
}
