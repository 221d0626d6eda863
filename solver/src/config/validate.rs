//! The checks of a parsed case that need nothing but the case: each refusal names the field
//! (its dotted path) and the reason. Checks that need derived quantities (c0) are in
//! `crate::derived`, run after these by the loader.

use super::{
    BedPores, Case, DensityDiffusion, Integrator, OpenFlume, PhaseConfig, SedimentConfig, Viscosity,
};

impl Case {
    /// Every check, in the order of the file's sections; the first refusal is returned.
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        self.validate_tank()?;
        self.validate_phases()?;
        self.validate_fluid_blocks()?;
        self.validate_numerics()?;
        self.validate_time()?;
        self.validate_observations()?;
        if let Some(f) = &self.open_flume {
            self.validate_open_flume(f)?;
        }
        Ok(())
    }

    /// Dimension, domain, gravity and walls.
    fn validate_tank(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        if self.dimension != 2 && self.dimension != 3 {
            return err(
                "dimension",
                format!("must be 2 or 3, got {}", self.dimension),
            );
        }
        let d = self.dim();
        for (field, v) in [
            ("domain.min_m", &self.domain.min_m),
            ("domain.max_m", &self.domain.max_m),
            ("gravity_m_per_s2", &self.gravity_m_per_s2),
        ] {
            check_vector(field, v, d)?;
        }
        for k in 0..d {
            if self.domain.max_m[k] <= self.domain.min_m[k] {
                return err(
                    "domain.max_m",
                    format!("component {k} must exceed domain.min_m's"),
                );
            }
        }
        if self.gravity_m_per_s2[..d - 1].iter().any(|g| *g != 0.0)
            || self.gravity_m_per_s2[d - 1] >= 0.0
        {
            return err(
                "gravity_m_per_s2",
                "must point down the last (vertical) axis, e.g. [0, -9.81]".to_string(),
            );
        }
        if self.walls.layers == 0 || self.walls.layers > 8 {
            return err(
                "walls.layers",
                format!("must be 1..=8, got {}", self.walls.layers),
            );
        }
        for (i, b) in self.walls.blocks.iter().enumerate() {
            check_vector(&format!("walls.blocks[{i}].min_m"), &b.min_m, d)?;
            check_vector(&format!("walls.blocks[{i}].max_m"), &b.max_m, d)?;
        }
        Ok(())
    }

    /// The phase table and each sediment's material.
    fn validate_phases(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        if self.phases.is_empty() {
            return err("phases", "at least one phase is needed".to_string());
        }
        if self.phases.len() > 3 {
            return err("phases", "at most 3 phases are supported".to_string());
        }
        for (i, p) in self.phases.iter().enumerate() {
            if !(p.rho0_kg_per_m3.is_finite() && p.rho0_kg_per_m3 > 0.0) {
                return err(
                    &format!("phases[{i}].rho0_kg_per_m3"),
                    "must be a positive number".into(),
                );
            }
            if !(p.viscosity_pa_s.is_finite() && p.viscosity_pa_s >= 0.0) {
                return err(
                    &format!("phases[{i}].viscosity_pa_s"),
                    "must be >= 0".into(),
                );
            }
            if self.phases[..i].iter().any(|q| q.name == p.name) {
                return err(
                    &format!("phases[{i}].name"),
                    format!("`{}` is defined twice", p.name),
                );
            }
            if let Some(sed) = &p.sediment {
                self.validate_sediment(i, sed)?;
            }
        }
        Ok(())
    }

    /// Each block names a phase and lies inside the domain.
    fn validate_fluid_blocks(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let d = self.dim();
        if self.fluid_blocks.is_empty() {
            return err(
                "fluid_blocks",
                "at least one block of fluid is needed".to_string(),
            );
        }
        for (i, b) in self.fluid_blocks.iter().enumerate() {
            if self.phase_index(&b.phase).is_none() {
                return err(
                    &format!("fluid_blocks[{i}].phase"),
                    format!("no phase named `{}` in `phases`", b.phase),
                );
            }
            check_vector(&format!("fluid_blocks[{i}].min_m"), &b.min_m, d)?;
            check_vector(&format!("fluid_blocks[{i}].max_m"), &b.max_m, d)?;
            for k in 0..d {
                if b.max_m[k] <= b.min_m[k] {
                    return err(
                        &format!("fluid_blocks[{i}].max_m"),
                        format!("component {k} must exceed min_m's"),
                    );
                }
                if b.min_m[k] < self.domain.min_m[k] - 1e-9
                    || b.max_m[k] > self.domain.max_m[k] + 1e-9
                {
                    return err(
                        &format!("fluid_blocks[{i}]"),
                        "must lie inside the domain".to_string(),
                    );
                }
            }
        }
        Ok(())
    }

    /// dp, h, CFL, sound speed and the options of each numerical method.
    fn validate_numerics(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let d = self.dim();
        let n = &self.numerics;
        let extent = (0..d)
            .map(|k| self.domain.max_m[k] - self.domain.min_m[k])
            .fold(f64::MAX, f64::min);
        if !(n.dp_m.is_finite() && n.dp_m > 0.0 && n.dp_m < extent / 4.0) {
            return err(
                "numerics.dp_m",
                format!(
                    "must be positive and below a quarter of the smallest tank size ({extent} m), got {}",
                    n.dp_m
                ),
            );
        }
        if !(n.coefh.is_finite() && (0.5..=3.0).contains(&n.coefh)) {
            return err(
                "numerics.coefh",
                format!("must be in 0.5..=3, got {}", n.coefh),
            );
        }
        if !(n.cfl.is_finite() && n.cfl > 0.0 && n.cfl <= 1.0) {
            return err("numerics.cfl", format!("must be in (0, 1], got {}", n.cfl));
        }
        self.validate_sound_speed()?;
        match n.density_diffusion {
            DensityDiffusion::MolteniColagrossi2009 { delta }
            | DensityDiffusion::Fourtakas2019 { delta }
                if !(delta.is_finite() && (0.0..=1.0).contains(&delta)) =>
            {
                return err(
                    "numerics.density_diffusion.delta",
                    format!("must be in 0..=1, got {delta}"),
                );
            }
            _ => {}
        }
        self.validate_viscosity()?;
        if let Integrator::Verlet { euler_every_steps } = n.integrator
            && !(1..=1000).contains(&euler_every_steps)
        {
            return err(
                "numerics.integrator.euler_every_steps",
                format!("must be in 1..=1000, got {euler_every_steps}"),
            );
        }
        Ok(())
    }

    /// The sound speed: exactly one of c0 and coefsound, positive.
    fn validate_sound_speed(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let n = &self.numerics;
        match (n.sound_speed.c0_m_per_s, n.sound_speed.coefsound) {
            (Some(c), None) if !(c.is_finite() && c > 0.0) => {
                return err(
                    "numerics.sound_speed.c0_m_per_s",
                    format!("must be positive, got {c}"),
                );
            }
            (None, Some(c)) if !(c.is_finite() && c > 0.0) => {
                return err(
                    "numerics.sound_speed.coefsound",
                    format!("must be positive, got {c}"),
                );
            }
            (Some(_), Some(_)) | (None, None) => {
                return err(
                    "numerics.sound_speed",
                    "give exactly one of c0_m_per_s and coefsound".into(),
                );
            }
            _ => {}
        }
        Ok(())
    }

    /// The viscosity's parameters: Smagorinsky's constant, the eddy viscosity (given instead
    /// of alpha), alpha.
    fn validate_viscosity(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let n = &self.numerics;
        if let Viscosity::Multiphase { smagorinsky_cs, .. } = n.viscosity
            && !(smagorinsky_cs.is_finite() && (0.0..=1.0).contains(&smagorinsky_cs))
        {
            return err(
                "numerics.viscosity.smagorinsky_cs",
                format!("must be in 0..=1, got {smagorinsky_cs}"),
            );
        }
        if let Viscosity::Multiphase {
            alpha,
            eddy_m2_per_s,
            ..
        } = n.viscosity
        {
            if !(eddy_m2_per_s.is_finite() && (0.0..=0.01).contains(&eddy_m2_per_s)) {
                return err(
                    "numerics.viscosity.eddy_m2_per_s",
                    format!("must be in 0..=0.01, got {eddy_m2_per_s}"),
                );
            }
            if eddy_m2_per_s > 0.0 && alpha != 0.0 {
                return err(
                    "numerics.viscosity.eddy_m2_per_s",
                    format!("sets Monaghan's alpha itself; give it or alpha ({alpha}), not both"),
                );
            }
        }
        if let Viscosity::Artificial { alpha } | Viscosity::Multiphase { alpha, .. } = n.viscosity
            && !(alpha.is_finite() && (0.0..=10.0).contains(&alpha))
        {
            return err(
                "numerics.viscosity.alpha",
                format!("must be in 0..=10, got {alpha}"),
            );
        }
        Ok(())
    }

    /// End time and output interval.
    fn validate_time(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let t = &self.time;
        if !(t.end_s.is_finite() && t.end_s > 0.0) {
            return err("time.end_s", "must be positive".into());
        }
        if !(t.output_interval_s.is_finite() && t.output_interval_s > 0.0) {
            return err("time.output_interval_s", "must be positive".into());
        }
        Ok(())
    }

    /// Gauges, profile and probes inside the domain.
    fn validate_observations(&self) -> Result<(), (String, String)> {
        let err = |field: &str, reason: String| Err((field.to_string(), reason));
        let d = self.dim();
        for (i, g) in self.observations.gauges.iter().enumerate() {
            check_vector(
                &format!("observations.gauges[{i}].position_m"),
                &g.position_m,
                d - 1,
            )?;
            for k in 0..d - 1 {
                if !(self.domain.min_m[k]..=self.domain.max_m[k]).contains(&g.position_m[k]) {
                    return err(
                        &format!("observations.gauges[{i}].position_m"),
                        "must lie inside the domain".into(),
                    );
                }
            }
        }
        if let Some(p) = &self.observations.profile {
            let inside = |x: f64| (self.domain.min_m[0]..=self.domain.max_m[0]).contains(&x);
            if !(p.x_min_m.is_finite()
                && p.x_max_m.is_finite()
                && inside(p.x_min_m)
                && inside(p.x_max_m))
                || p.x_max_m < p.x_min_m
            {
                return err(
                    "observations.profile",
                    "x_min_m <= x_max_m, both inside the domain".into(),
                );
            }
            if !(1..=10_000).contains(&p.columns) {
                return err(
                    "observations.profile.columns",
                    format!("must be 1..=10000, got {}", p.columns),
                );
            }
            if d == 3 && !(self.domain.min_m[1]..=self.domain.max_m[1]).contains(&p.y_m) {
                return err(
                    "observations.profile.y_m",
                    "must lie inside the domain".into(),
                );
            }
        }
        for (i, p) in self.observations.pressure_probes.iter().enumerate() {
            check_vector(
                &format!("observations.pressure_probes[{i}].position_m"),
                &p.position_m,
                d,
            )?;
        }
        Ok(())
    }

    fn validate_sediment(&self, i: usize, s: &SedimentConfig) -> Result<(), (String, String)> {
        let field = |name: &str| format!("phases[{i}].sediment.{name}");
        let err = |name: &str, reason: &str| Err((field(name), reason.to_string()));
        if self.phases.iter().filter(|p| p.sediment.is_some()).count() > 1 {
            return Err((
                format!("phases[{i}].sediment"),
                "only one sediment phase is supported".into(),
            ));
        }
        let water: Vec<&PhaseConfig> = self
            .phases
            .iter()
            .filter(|p| p.sediment.is_none())
            .collect();
        if water.len() != 1 {
            return Err((
                "phases".into(),
                "a sediment needs exactly one water phase (a phase without `sediment`)".into(),
            ));
        }
        if self.phases[i].rho0_kg_per_m3 <= water[0].rho0_kg_per_m3 {
            return Err((
                format!("phases[{i}].rho0_kg_per_m3"),
                "a sediment must be denser than the water".into(),
            ));
        }
        if !matches!(self.numerics.viscosity, Viscosity::Multiphase { .. }) {
            return Err((
                "numerics.viscosity.method".into(),
                "a sediment phase needs `multiphase`".into(),
            ));
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(s.d50_m) {
            return err("d50_m", "must be positive");
        }
        if !(s.friction_angle_deg.is_finite()
            && s.friction_angle_deg > 0.0
            && s.friction_angle_deg < 90.0)
        {
            return err("friction_angle_deg", "must be between 0 and 90 degrees");
        }
        if !(s.cohesion_pa.is_finite() && s.cohesion_pa >= 0.0) {
            return err("cohesion_pa", "must be >= 0");
        }
        if !(s.hbp_m_s.is_finite() && s.hbp_m_s >= 0.0) {
            return err("hbp_m_s", "must be >= 0");
        }
        if !positive(s.hbp_n) {
            return err("hbp_n", "must be positive");
        }
        if !positive(s.ks_over_d50) {
            return err("ks_over_d50", "must be positive");
        }
        if !(positive(s.surface_mass_fraction) && s.surface_mass_fraction <= 1.0) {
            return err("surface_mass_fraction", "must be in (0, 1]");
        }
        if let Some(mu) = s.max_viscosity_pa_s
            && !positive(mu)
        {
            return err("max_viscosity_pa_s", "must be positive");
        }
        if let Some(pores) = &s.pores {
            return self.validate_pores(i, pores);
        }
        Ok(())
    }

    fn validate_pores(&self, i: usize, p: &BedPores) -> Result<(), (String, String)> {
        let err = |name: &str, reason: &str| {
            Err((format!("phases[{i}].sediment.pores.{name}"), reason.into()))
        };
        if !(p.porosity.is_finite() && p.porosity > 0.0 && p.porosity < 1.0) {
            return err("porosity", "must be between 0 and 1");
        }
        if !(p.conductivity_m_per_s.is_finite() && p.conductivity_m_per_s > 0.0) {
            return err("conductivity_m_per_s", "must be positive");
        }
        if !(p.suction_m.is_finite() && p.suction_m >= 0.0) {
            return err("suction_m", "must be >= 0");
        }
        if self.open_flume.is_none() {
            // The water the pores take is parked, as the outlet's is.
            return Err((
                format!("phases[{i}].sediment.pores"),
                "needs an open flume".into(),
            ));
        }
        Ok(())
    }

    fn validate_open_flume(&self, f: &OpenFlume) -> Result<(), (String, String)> {
        let err = |name: &str, reason: String| Err((format!("open_flume.{name}"), reason));
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if self.dimension != 2 {
            return err("", "an open flume is 2-D only for now".into());
        }
        if self.phases.len() > 2 {
            return err(
                "",
                "an open flume takes at most two phases (water and a sediment)".into(),
            );
        }
        if !positive(f.width_m) {
            return err("width_m", "must be positive".into());
        }
        if !(f.inflow_m3_per_s.is_finite() && f.inflow_m3_per_s >= 0.0) {
            return err("inflow_m3_per_s", "must be >= 0".into());
        }
        let (lo, hi) = (&self.domain.min_m, &self.domain.max_m);
        let dp = self.numerics.dp_m;
        if !(positive(f.inlet.height_m) && f.inlet.height_m >= dp) {
            return err("inlet.height_m", "must be at least dp".into());
        }
        if !(f.inlet.y_min_m >= lo[1] && f.inlet.y_min_m + f.inlet.height_m <= hi[1]) {
            return err(
                "inlet.y_min_m",
                "the inlet must lie within the domain's height".into(),
            );
        }
        if !(2..=16).contains(&f.inlet.layers) {
            return err(
                "inlet.layers",
                format!("must be 2..=16, got {}", f.inlet.layers),
            );
        }
        if !(f.outlet_weir_m > lo[1] && f.outlet_weir_m <= hi[1]) {
            return err(
                "outlet_weir_m",
                "must lie within the domain's height".into(),
            );
        }
        let c = &f.collector;
        if !(c.x_min_m < c.x_max_m && c.x_min_m >= lo[0] && c.x_max_m <= hi[0] && c.y_max_m > lo[1])
        {
            return err(
                "collector",
                "must be a box inside the flume (x_min < x_max, above the floor)".into(),
            );
        }
        self.validate_outlet_and_sill(f)?;
        // Sediment that starts in the collector would count as eroded at the first step.
        if let Some((k, _)) = self.sediment_phases() {
            let name = &self.phases[k].name;
            for b in self.fluid_blocks.iter().filter(|b| &b.phase == name) {
                if b.max_m[0] >= c.x_min_m && b.min_m[0] < c.x_max_m && b.min_m[1] < c.y_max_m {
                    return err(
                        "collector.x_min_m",
                        format!(
                            "the {name} block ending at x = {} m reaches into the collector",
                            b.max_m[0]
                        ),
                    );
                }
            }
        }
        Ok(())
    }

    /// The open flume's bottom outlet and sill, where it has them.
    fn validate_outlet_and_sill(&self, f: &OpenFlume) -> Result<(), (String, String)> {
        let err = |name: &str, reason: String| Err((format!("open_flume.{name}"), reason));
        let positive = |x: f64| x.is_finite() && x > 0.0;
        let (lo, hi) = (&self.domain.min_m, &self.domain.max_m);
        let dp = self.numerics.dp_m;
        if let Some(o) = &f.bottom_outlet {
            if !(o.x_min_m > lo[0] && o.x_min_m < hi[0]) {
                return err("bottom_outlet.x_min_m", "must lie inside the flume".into());
            }
            if !(o.y_min_m >= lo[1] && o.y_max_m - o.y_min_m >= dp && o.y_max_m <= hi[1]) {
                return err(
                    "bottom_outlet.y_max_m",
                    "the opening must be at least dp high, within the domain's height".into(),
                );
            }
            if !positive(o.velocity_m_s) {
                return err("bottom_outlet.velocity_m_s", "must be positive".into());
            }
            // Its bound, MAX_INLET_MACH c0, needs the derived c0: `derived::check_bottom_outlet`.
        }
        if let Some(s) = &f.sill {
            if !(s.x_min_m > lo[0] && s.x_max_m < hi[0] && s.x_max_m - s.x_min_m >= dp) {
                return err(
                    "sill",
                    "must lie inside the flume and be at least dp thick".into(),
                );
            }
            let Some(top) = self.bed_top_m() else {
                return err("sill", "ends a sediment bed, and the case has none".into());
            };
            if top - lo[1] < 2.0 * dp {
                return err(
                    "sill",
                    format!(
                        "its crest stands a row under the bed's top, and a bed {top} m high has no row under its top at dp = {dp} m"
                    ),
                );
            }
        }
        Ok(())
    }
}

fn check_vector(field: &str, v: &[f64], len: usize) -> Result<(), (String, String)> {
    if v.len() != len {
        return Err((
            field.to_string(),
            format!("needs {len} components, got {}", v.len()),
        ));
    }
    if v.iter().any(|x| !x.is_finite()) {
        return Err((
            field.to_string(),
            "components must be finite numbers".to_string(),
        ));
    }
    Ok(())
}
