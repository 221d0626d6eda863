//! Green & Ampt's (1911) infiltration of ponded water into a dry, uniform soil: a sharp wetting
//! front that moves down with the soil behind it saturated. With `S = (psi_f + h) dtheta` (the
//! suction at the front plus the ponded depth, times the moisture deficit), the depth of water
//! taken up `F` grows as `f = dF/dt = K (1 + S / F)`, whose solution from a dry start is
//! `K t = F - S ln(1 + F / S)` (Chow, Maidment & Mays 1988, Applied Hydrology, Eq. 4.3.6).
//!
//! The ponded depth changes as the flow goes by; each span is taken at the depth of its start
//! and continued from the time at which a constant `S` would have taken up the `F` already in
//! (time compression, as rainfall-runoff models apply Green-Ampt to unsteady ponding).

/// One bed's Green-Ampt parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GreenAmpt {
    /// Saturated hydraulic conductivity K, m/s.
    pub conductivity_m_per_s: f64,
    /// Suction head at the wetting front psi_f, m.
    pub suction_m: f64,
    /// Moisture deficit dtheta: the porosity less the water already in the pores.
    pub moisture_deficit: f64,
}

impl GreenAmpt {
    /// `S` of the ponding `head_m` deep, m.
    fn storage_suction(&self, head_m: f64) -> f64 {
        (self.suction_m + head_m.max(0.0)) * self.moisture_deficit
    }

    /// Time a constant ponding `head_m` deep takes to put `depth_m` of water into the dry
    /// soil, s.
    pub fn time_to_take(&self, depth_m: f64, head_m: f64) -> f64 {
        let s = self.storage_suction(head_m);
        let f = depth_m.max(0.0);
        let taken = if s > 0.0 { f - s * (f / s).ln_1p() } else { f };
        taken / self.conductivity_m_per_s
    }

    /// Depth of water taken up after `span_s` more of ponding `head_m` deep, from `depth_m`
    /// taken up already, m. The inverse of [`GreenAmpt::time_to_take`] by bisection: it rises
    /// with the depth, and the rate `K (1 + S / F)` bounds the step from above.
    pub fn after(&self, depth_m: f64, head_m: f64, span_s: f64) -> f64 {
        let f0 = depth_m.max(0.0);
        if span_s <= 0.0 {
            return f0;
        }
        let target = self.time_to_take(f0, head_m) + span_s;
        let k = self.conductivity_m_per_s;
        let s = self.storage_suction(head_m);
        // From F0 the rate only falls, so F0 + K (1 + S / F) t overshoots; from a dry start
        // F <= K t + sqrt(2 S K t) (the early-time limit F^2 = 2 S K t, plus gravity).
        let mut hi = f0 + k * span_s + (2.0 * s * k * target).sqrt();
        let mut lo = f0;
        while self.time_to_take(hi, head_m) < target {
            hi = 2.0 * hi + k * span_s;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.time_to_take(mid, head_m) < target {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-12 * hi {
                break;
            }
        }
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chow, Maidment & Mays (1988), Applied Hydrology, Example 4.4.1: a silt loam (K = 0.65
    /// cm/h, psi_f = 16.7 cm, effective porosity 0.486 at an initial effective saturation of
    /// 30 %, so dtheta = 0.340) under ponding takes up F = 3.17 cm in the first hour, then at
    /// f = K (1 + psi dtheta / F) = 1.81 cm/h.
    #[test]
    fn the_textbook_silt_loam_takes_3_17_cm_in_an_hour() {
        let cm = 0.01;
        let hour = 3600.0;
        let soil = GreenAmpt {
            conductivity_m_per_s: 0.65 * cm / hour,
            suction_m: 16.7 * cm,
            moisture_deficit: 0.340,
        };
        let f = soil.after(0.0, 0.0, hour);
        assert!((f / cm - 3.17).abs() < 0.005, "F = {} cm", f / cm);
        let dt = 1.0;
        let rate = (soil.after(f, 0.0, dt) - f) / dt;
        // The book's figures are rounded to 0.01.
        assert!(
            (rate / cm * hour - 1.81).abs() < 0.01,
            "f = {} cm/h",
            rate / cm * hour
        );
    }

    /// The time compression carries the depth over from one span to the next: a bug in it (a
    /// span started from a dry soil, or from the time of another head) takes up more water in
    /// ten spans than in one.
    #[test]
    fn ten_spans_take_what_one_does_at_a_constant_head() {
        let sand = GreenAmpt {
            conductivity_m_per_s: 1.5e-3,
            suction_m: 0.05,
            moisture_deficit: 0.4,
        };
        let whole = sand.after(0.0, 0.02, 3.0);
        let pieces = (0..10).fold(0.0, |f, _| sand.after(f, 0.02, 0.3));
        assert!((whole - pieces).abs() < 1e-9, "{whole} against {pieces}");
        // Deeper ponding drives water in faster; no suction leaves gravity and the head.
        assert!(sand.after(0.0, 0.04, 3.0) > whole);
        let no_suction = GreenAmpt {
            suction_m: 0.0,
            ..sand
        };
        assert!((no_suction.after(0.0, 0.0, 2.0) - 1.5e-3 * 2.0).abs() < 1e-12);
    }
}
