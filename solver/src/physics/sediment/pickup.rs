//! Erosion at the rate sand is picked up from its bed, for a particle far larger than a grain.
//!
//! The paper releases a surface particle as soon as Shields' criterion holds (Eq. 25). That is a
//! grain's rule: at dp = 1 cm a particle is a layer 25 grains thick, and when the flow passes
//! the threshold the whole top row leaves at once, where the flow would pick up a grain at a
//! time. Here a held particle that Shields would release waits for the mass it holds to be
//! picked up: it is released in a step with the probability that van Rijn's (1984) pick-up rate
//! lifts a particle's mass from its share of the bed in that step (Einstein's 1950 view of
//! entrainment as a chance per grain per unit time). The bed then loses sand at van Rijn's rate
//! whatever dp is.
//!
//! van Rijn, L. C. (1984). Sediment pick-up functions. J. Hydraul. Eng. 110(10), 1494-1502:
//! `E = 0.00033 rho_s sqrt(Delta g d50) D*^0.3 T^1.5` kg/m2/s, with
//! `D* = d50 (Delta g / nu^2)^(1/3)`, `T = (tau_b - tau_bcr) / tau_bcr` and
//! `Delta = rho_s / rho_w - 1`, for 130 <= d50 <= 1500 um.
//!
//! A particle of mass `rho_s dp^dim` has `dp^(dim-1)` of bed, so it is picked up at the rate
//! `E dp^(dim-1) / (rho_s dp^dim) = 0.00033 sqrt(Delta g d50) D*^0.3 T^1.5 / dp` per second.
//! The draw is a hash of the particle's id and the run's step count, the same on every engine
//! (`pickup_draw` in `shaders/common/sediment.wgsl`).

/// van Rijn's (1984) pick-up constant, dimensionless.
pub const VAN_RIJN_PICKUP: f64 = 0.00033;

/// The rate at which a surface particle of size `dp_m` is picked up per unit `T^1.5`, 1/s:
/// `0.00033 sqrt(Delta g d50) D*^0.3 / dp` (module doc), for grains of `d50_m` and density
/// `rho_s` in water of density `rho_w` and kinematic viscosity `nu_w` under gravity `g`.
pub fn pickup_per_s(d50_m: f64, rho_s: f64, rho_w: f64, nu_w: f64, g: f64, dp_m: f64) -> f64 {
    let delta_g = (rho_s / rho_w - 1.0) * g;
    let d_star = d50_m * (delta_g / (nu_w * nu_w)).cbrt();
    VAN_RIJN_PICKUP * (delta_g * d50_m).sqrt() * d_star.powf(0.3) / dp_m
}

/// The rate at which one particle is picked up, 1/s: `per_s T^1.5` with van Rijn's transport
/// stage `T = tau_b / tau_bcr - 1` (0 at or below the threshold).
pub fn pickup_rate(per_s: f32, tau_b: f32, tau_bcr: f32) -> f32 {
    let stage = (tau_b / tau_bcr - 1.0).max(0.0);
    per_s * stage * stage.sqrt()
}

/// A uniform 32-bit draw for particle `id` at run step `step`: the PCG hash (Jarzynski & Olano
/// 2020, "Hash functions for GPU rendering", JCGT 9(3)) of the id mixed with the hashed step.
pub fn pickup_draw(id: u32, step: u32) -> u32 {
    pcg(id ^ pcg(step))
}

fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Whether particle `id` is picked up at run step `step`, a step of `dt_s` at `rate` per second:
/// its draw falls under `rate dt` of the 32-bit range (below one step in 4e9: never).
pub fn picked_up(id: u32, step: u32, rate: f32, dt_s: f32) -> bool {
    let chance = (rate * dt_s).clamp(0.0, LARGEST_CHANCE);
    pickup_draw(id, step) < (chance * 4_294_967_296.0) as u32
}

/// The largest chance of a step, just under 1, whose share of the 32-bit range is a u32.
const LARGEST_CHANCE: f32 = 0.999_999_94;

/// Where a held particle's mass picked up so far sits in its region word: above the region's
/// byte and `REGION_HELD`, in the word's top 23 bits. Under `van_rijn_integrated` they count
/// [`PICKUP_WHOLE`]ths of the particle lost; under `van_rijn_exner` they are a two's complement
/// of [`EXNER_WHOLE`]ths, negative where more has settled on a particle than was worn off it
/// ([`word_units`]).
pub const PICKUP_SHIFT: u32 = 9;

/// The units of a whole particle's mass worn by the pick-up alone: 2^23, all the bits of the
/// word above the hold.
pub const PICKUP_WHOLE: u32 = 1 << 23;

/// The units of a whole particle's mass worn net of what settles (`van_rijn_exner`): 2^22, so
/// that a whole particle's surplus fits the signed 23 bits above the hold as well as its loss.
pub const EXNER_WHOLE: u32 = 1 << 22;

/// The units a particle worn whole keeps under `van_rijn_exner` (all but one of
/// [`EXNER_WHOLE`], the most the signed bits hold): its mass went downstream as bed load, so
/// it carries none of its own wherever it goes, until what settles on it makes it sand again.
pub const EXNER_SPENT: i32 = EXNER_WHOLE as i32 - 1;

/// The units a held particle's word holds: signed, in [`EXNER_WHOLE`]ths, under `exner`; else
/// in [`PICKUP_WHOLE`]ths.
pub fn word_units(word: u32, exner: bool) -> i32 {
    if exner {
        (word as i32) >> PICKUP_SHIFT
    } else {
        (word >> PICKUP_SHIFT) as i32
    }
}

/// A held particle's `units` in the bits of its word above the hold.
pub fn units_word(units: i32) -> u32 {
    (units as u32) << PICKUP_SHIFT
}

/// The mass a held particle has lost to the flow after a step of `dt_s` at `rate` per second
/// (`van_rijn_integrated`), from the `units` lost before: None once it reaches the whole
/// particle, which the flow then carries off. A particle far larger than a grain is not lifted
/// whole by a chance: its layer of grains is worn away at the rate, as the Exner equation
/// lowers a bed, and it leaves when nothing of it is left. A step's share, often under one
/// unit, is rounded down or up by particle `id`'s draw at run step `step`, with the chance of
/// its fraction, so that no share is lost to the rounding on average.
pub fn integrated_pickup(units: u32, id: u32, step: u32, rate: f32, dt_s: f32) -> Option<u32> {
    let share = (rate * dt_s).clamp(0.0, 1.0) * PICKUP_WHOLE as f32;
    // The draw's top 24 bits, exact in f32: a uniform fraction in [0, 1).
    let fraction = (pickup_draw(id, step) >> 8) as f32 * (1.0 / 16_777_216.0);
    let total = units.saturating_add((share + fraction) as u32);
    (total < PICKUP_WHOLE).then_some(total)
}

/// van Rijn's (1984a) saltation length of bed load per unit `T^0.9`, m: `3 d50 D*^0.6`
/// (van Rijn, L. C. (1984). Sediment transport, part I: bed load transport. J. Hydraul. Eng.
/// 110(10), 1431-1456: `lambda_b / d50 = 3 D*^0.6 T^0.9`), for grains of `d50_m` and density
/// `rho_s` in water of density `rho_w` and kinematic viscosity `nu_w` under gravity `g`.
pub fn saltation_length_per_stage(d50_m: f64, rho_s: f64, rho_w: f64, nu_w: f64, g: f64) -> f64 {
    let delta_g = (rho_s / rho_w - 1.0) * g;
    let d_star = d50_m * (delta_g / (nu_w * nu_w)).cbrt();
    3.0 * d50_m * d_star.powf(0.6)
}

/// The bed load the flow over a held surface particle can carry, in particles per second
/// (`van_rijn_exner`; [`exner_exchange`] says how much of it the particle passes on): what it
/// is picked up at, `rate` per second, times the grains' step `step_per_stage T^0.9` in
/// particle widths (`step_per_stage` the saltation length per unit `T^0.9` over dp). Grains
/// picked up from a particle's share of the bed land one step on; where the step is shorter
/// than dp, most land on the particle they left.
pub fn bed_load_flux(rate: f32, step_per_stage: f32, tau_b: f32, tau_bcr: f32) -> f32 {
    let stage = (tau_b / tau_bcr - 1.0).max(0.0);
    rate * step_per_stage * stage.powf(0.9)
}

/// Exner's balance for a held surface particle under `van_rijn_exner`: what it passes on and
/// what it gains or loses per second (`(out, net)`, `net = out - upstream` always, so no sand is
/// made or lost between particles). It passes on its own bed load `flux`, but no more than
/// what comes from `upstream` plus what is picked up of it at `rate`, and what is picked up of
/// it no more than is left of it (its `units` worn before, in `EXNER_WHOLE`ths, against
/// [`EXNER_SPENT`]; `dt_s` the step): a bed worn only by the flow cannot supply more, and a
/// particle worn whole supplies nothing. What settles on it (a negative net) fills what was
/// worn off it and then builds it up, to at most a whole particle more than its own mass;
/// beyond that what comes from upstream passes over it.
pub fn exner_exchange(flux: f32, upstream: f32, rate: f32, units: i32, dt_s: f32) -> (f32, f32) {
    let room = (units as f32 + EXNER_WHOLE as f32) / (EXNER_WHOLE as f32 * dt_s);
    let left = (EXNER_SPENT - units).max(0) as f32 / (EXNER_WHOLE as f32 * dt_s);
    let net = (flux.min(upstream + rate) - upstream).clamp(-room, left);
    (upstream + net, net)
}

/// The mass a held particle has lost to the flow after a step of `dt_s` with `net` per second
/// worn off it ([`exner_exchange`]: negative where more settles on it than leaves), from the
/// `units` lost before: None once it is worn whole ([`EXNER_SPENT`]). What settles builds it
/// up to a whole particle more than its own mass, and no further. A step's share is rounded
/// down or up by particle `id`'s draw at run step `step`, as in [`integrated_pickup`].
pub fn exner_pickup(units: i32, id: u32, step: u32, net: f32, dt_s: f32) -> Option<i32> {
    let whole = EXNER_WHOLE as i32;
    let share = (net * dt_s).clamp(-1.0, 1.0) * EXNER_WHOLE as f32;
    let fraction = (pickup_draw(id, step) >> 8) as f32 * (1.0 / 16_777_216.0);
    let total = units + (share + fraction).floor() as i32;
    (total < EXNER_SPENT).then_some(total.max(-whole))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ULBRA sand (d50 0.4 mm, 2710 kg/m3) in water at 20 C, dp = 1 cm, by hand:
    /// Delta g = 1.71 x 9.81 = 16.775 m/s2; D* = 4e-4 (16.775 / 1e-12)^(1/3) = 10.240;
    /// D*^0.3 = 2.0095; sqrt(Delta g d50) = 0.081915 m/s; so 0.00033 x 0.081915 x 2.0095 / 0.01
    /// = 5.432e-3 per second.
    #[test]
    fn pickup_per_second_of_the_flume_sand() {
        let per_s = pickup_per_s(4e-4, 2710.0, 1000.0, 1e-6, 9.81, 0.01);
        assert!((per_s - 5.432e-3).abs() < 1e-6, "{per_s}");
        // The mass flux it stands for is van Rijn's E whatever dp: E = rate rho_s dp.
        let at_4mm = pickup_per_s(4e-4, 2710.0, 1000.0, 1e-6, 9.81, 0.004);
        assert!((at_4mm * 0.004 - per_s * 0.01).abs() < 1e-12);
    }

    /// T = 0.5: 3 x 0.5^1.5 = 1.06066; T = 3: 3 x 3^1.5 = 15.5885; at or below the threshold
    /// nothing is picked up.
    #[test]
    fn rate_goes_with_the_transport_stage() {
        assert!((pickup_rate(3.0, 1.5, 1.0) - 1.060_66).abs() < 1e-6);
        assert!((pickup_rate(3.0, 0.8, 0.2) - 15.588_46).abs() < 1e-4);
        assert_eq!(pickup_rate(3.0, 1.0, 1.0), 0.0);
        assert_eq!(pickup_rate(3.0, 0.5, 1.0), 0.0);
        assert_eq!(pickup_rate(3.0, 0.0, f32::INFINITY), 0.0);
    }

    /// The draw's first values, worked out apart (in Python's integers, modulo 2^32) from the
    /// published constants: pcg(0) = 129708002, pcg(pcg(0)) = 817759070; and the mix of id and
    /// step differs when either changes.
    #[test]
    fn draw_is_the_pcg_hash() {
        assert_eq!(pcg(0), 129_708_002);
        assert_eq!(pickup_draw(0, 0), 817_759_070);
        assert_ne!(pickup_draw(1, 0), pickup_draw(0, 0));
        assert_ne!(pickup_draw(0, 1), pickup_draw(0, 0));
    }

    /// A particle worn at a constant rate leaves once the rate's integral reaches its mass:
    /// at 0.5 per second and steps of 1e-3 s, each step takes 2^22 / 1000 = 4194.304 units,
    /// 4,194 or 4,195 after the draw's rounding. After 1,999 steps at most 1,999 x 4,195 =
    /// 8,385,805 are gone, under the whole 2^23 = 8,388,608; after 2,001 at least 2,001 x 4,194
    /// = 8,392,194.
    #[test]
    fn a_particle_worn_at_a_constant_rate_leaves_when_its_mass_is_gone() {
        let mut units = 0;
        let mut left = None;
        for step in 1..=3000u32 {
            match integrated_pickup(units, 7, step, 0.5, 1e-3) {
                Some(u) => units = u,
                None => {
                    left = Some(step);
                    break;
                }
            }
        }
        let left = left.expect("worn away");
        assert!((2000..=2001).contains(&left), "left at step {left}");
        // Nothing is taken without a rate, and a step's whole share takes it at once.
        assert_eq!(integrated_pickup(5, 7, 1, 0.0, 1e-3), Some(5));
        assert_eq!(integrated_pickup(0, 7, 1, 2.0, 1.0), None);
    }

    /// A share far under one unit a step is not lost to the rounding: 1e5 steps of 0.25 units
    /// take 25,000 +/- 3 sigma (sqrt(1e5 x 0.25 x 0.75) = 137, so 411) units, and none without
    /// the draw's help would be taken at all.
    #[test]
    fn shares_under_a_unit_add_up_on_average() {
        let rate = 0.25 / PICKUP_WHOLE as f32;
        let mut units = 0;
        for step in 0..100_000u32 {
            units = integrated_pickup(units, 11, step, rate, 1.0).expect("far from whole");
        }
        assert!((24_589..=25_411).contains(&units), "{units}");
    }

    /// Over many steps a particle is picked up as often as its rate says: 1e5 steps at a
    /// chance of 1e-2 give 1000 +/- 3 sigma (95).
    #[test]
    fn picked_up_as_often_as_the_rate_says() {
        let hits = (0..100_000u32)
            .filter(|&step| picked_up(7, step, 100.0, 1e-4))
            .count();
        assert!((905..=1095).contains(&hits), "{hits}");
        let ids = (0..100_000u32)
            .filter(|&id| picked_up(id, 12, 100.0, 1e-4))
            .count();
        assert!((905..=1095).contains(&ids), "{ids}");
        assert!(!(0..10_000u32).any(|s| picked_up(3, s, 0.0, 1e-4)));
        assert!((0..10_000u32).all(|s| picked_up(3, s, 1e9, 1.0)));
    }

    /// The ULBRA sand's saltation length by hand: D* = 10.2396 (above), D*^0.6 =
    /// exp(0.6 ln 10.2396) = 4.03803, so 3 x 4e-4 x 4.03803 = 4.8456e-3 m per unit T^0.9. At
    /// T = 1 and a pick-up of 2 per second with the step half a particle the bed load is 1
    /// particle per second; at T = 0.5, 0.5^0.9 = 0.535887 of it; none at the threshold.
    #[test]
    fn bed_load_is_the_pick_up_carried_a_saltation_length() {
        let length = saltation_length_per_stage(4e-4, 2710.0, 1000.0, 1e-6, 9.81);
        assert!((length - 4.8456e-3).abs() < 1e-7, "{length}");
        assert!((bed_load_flux(2.0, 0.5, 2.0, 1.0) - 1.0).abs() < 1e-6);
        assert!((bed_load_flux(1.0, 1.0, 1.5, 1.0) - 0.535_887).abs() < 1e-6);
        assert_eq!(bed_load_flux(3.0, 0.5, 1.0, 1.0), 0.0);
    }

    /// Exner's balance worn into a particle: nothing net leaves it as it was for any draw; a
    /// net 0.5 per second over 1e-3 s takes 2,097 or 2,098 units off what was worn (2^21 /
    /// 1000 = 2097.15), through none to a surplus, down to a whole particle more and no
    /// further; and a net loss that reaches the whole releases it, as the pick-up alone does.
    #[test]
    fn what_settles_fills_what_was_worn_then_builds_the_bed() {
        for step in 0..100 {
            assert_eq!(exner_pickup(1234, 7, step, 0.0, 1e-3), Some(1234));
        }
        let filled = exner_pickup(10_000, 7, 1, -0.5, 1e-3).expect("held");
        assert!((7_902..=7_903).contains(&filled), "{filled}");
        let built = exner_pickup(100, 7, 1, -0.5, 1e-3).expect("held");
        assert!((-1_998..=-1_997).contains(&built), "{built}");
        let whole = EXNER_WHOLE as i32;
        assert_eq!(exner_pickup(5 - whole, 7, 1, -0.5, 1e-3), Some(-whole));
        assert_eq!(exner_pickup(whole - 10, 7, 1, 0.5, 1e-3), None);
        assert_eq!(
            exner_pickup(EXNER_SPENT, 7, 1, 0.0, 1e-3),
            None,
            "worn whole"
        );
        let worn = exner_pickup(10_000, 7, 1, 0.5, 1e-3).expect("held");
        assert!((12_097..=12_098).contains(&worn), "{worn}");
    }

    /// The balance by hand, per second: a particle that could carry 3 with 1 from upstream and
    /// 0.5 picked up of it passes on 1.5 and loses 0.5; one that carries 0.2 of the same 1
    /// keeps 0.8; one already built up to a whole particle more keeps none and passes all 1
    /// on; one with 0.25 of a particle's room left, over a step of 0.1 s, keeps 2.5 per second;
    /// one worn nearly whole loses no more than is left of it.
    #[test]
    fn a_particle_passes_on_what_it_does_not_keep() {
        let whole = EXNER_WHOLE as i32;
        assert_eq!(exner_exchange(3.0, 1.0, 0.5, 0, 1e-3), (1.5, 0.5));
        let (out, net) = exner_exchange(0.2, 1.0, 0.5, 0, 1e-3);
        assert!(
            (out - 0.2).abs() < 1e-6 && (net + 0.8).abs() < 1e-6,
            "{out} {net}"
        );
        assert_eq!(exner_exchange(0.2, 1.0, 0.5, -whole, 1e-3), (1.0, 0.0));
        // Worn all but 1,000 units, over 1e-3 s, it can lose no more than 1,000 units' worth
        // (0.2384 per second, 1000 / 2^22 / 1e-3); worn whole, nothing.
        let (out, net) = exner_exchange(3.0, 1.0, 0.5, EXNER_SPENT - 1000, 1e-3);
        assert!(
            (net - 0.238_419).abs() < 1e-5 && out == 1.0 + net,
            "{out} {net}"
        );
        assert_eq!(exner_exchange(3.0, 1.0, 0.5, EXNER_SPENT, 1e-3), (1.0, 0.0));
        let (out, net) = exner_exchange(0.0, 10.0, 0.5, -3 * whole / 4, 0.1);
        assert!(
            (net + 2.5).abs() < 1e-5 && (out - 7.5).abs() < 1e-5,
            "{out} {net}"
        );
    }

    /// A word's units come back signed under Exner's balance, a surplus as well as a loss,
    /// past the region's bits; a loss under the pick-up alone, up to its larger whole.
    #[test]
    fn units_round_trip_through_the_word() {
        let whole = EXNER_WHOLE as i32;
        for units in [0, 1, -1, whole - 1, -whole, 12_345, -54_321] {
            assert_eq!(word_units(units_word(units) | 0x1ff, true), units);
            if units >= 0 {
                assert_eq!(word_units(units_word(units) | 0x1ff, false), units);
            }
        }
    }
}
