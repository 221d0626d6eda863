//! The gauge time series, one row per output interval.
//!
//! Each row is flushed as it is written so that a run that fails or is killed keeps every
//! interval it completed.

use flume_solver::Observations;
use flume_solver::budget::{BudgetRow, STRETCHES};
use std::fmt::Write as _;
use std::io::{self, Write};

const FIXED_COLUMNS: [&str; 8] = [
    "time_s",
    "step",
    "dt_s",
    "front_m",
    "max_speed_m_per_s",
    "max_density_error",
    "cfl",
    "recoveries",
];

pub struct GaugeCsv<W: Write> {
    w: W,
    columns: usize,
}

impl<W: Write> GaugeCsv<W> {
    /// Writes the header: the fixed columns, then `<gauge>_m` per gauge and `<probe>_pa` per probe.
    pub fn new(mut w: W, gauges: &[String], probes: &[String]) -> io::Result<Self> {
        let header: Vec<String> = FIXED_COLUMNS
            .iter()
            .map(|c| c.to_string())
            .chain(gauges.iter().map(|g| field(&format!("{g}_m"))))
            .chain(probes.iter().map(|p| field(&format!("{p}_pa"))))
            .collect();
        writeln!(w, "{}", header.join(","))?;
        w.flush()?;
        Ok(GaugeCsv {
            w,
            columns: header.len(),
        })
    }

    pub fn row(&mut self, obs: &Observations) -> io::Result<()> {
        let mut line = String::new();
        // Time is the host's f64; every other figure comes from f32 GPU data, and printing
        // it as f32 (shortest round-trip text) avoids digits that mean nothing.
        let _ = write!(
            line,
            "{},{},{},{},{},{},{},{}",
            obs.time_s,
            obs.steps,
            obs.dt_s as f32,
            obs.front_m
                .map_or_else(String::new, |x| (x as f32).to_string()),
            obs.max_speed_m_per_s as f32,
            obs.max_density_error as f32,
            obs.cfl as f32,
            obs.recoveries
        );
        let levels = obs.gauges.iter().map(|g| g.level_m);
        let pressures = obs.probes.iter().map(|p| p.pressure_pa);
        let mut cells = FIXED_COLUMNS.len();
        for value in levels.chain(pressures) {
            line.push(',');
            if let Some(v) = value {
                let _ = write!(line, "{}", v as f32);
            }
            cells += 1;
        }
        if cells != self.columns {
            return Err(io::Error::other(format!(
                "observation has {cells} values but gauges.csv has {} columns",
                self.columns
            )));
        }
        writeln!(self.w, "{line}")?;
        self.w.flush()
    }
}

/// The layer profile, one row per column per output interval (long format, so that a
/// spreadsheet or pandas can pivot it): time, x, free surface, then the top of each phase.
pub struct ProfileCsv<W: Write> {
    w: W,
}

impl<W: Write> ProfileCsv<W> {
    pub fn new(mut w: W, phases: &[String]) -> io::Result<Self> {
        let header: Vec<String> = ["time_s", "x_m", "surface_m"]
            .iter()
            .map(|c| c.to_string())
            .chain(phases.iter().map(|p| field(&format!("{p}_top_m"))))
            .collect();
        writeln!(w, "{}", header.join(","))?;
        w.flush()?;
        Ok(ProfileCsv { w })
    }

    pub fn rows(&mut self, obs: &Observations) -> io::Result<()> {
        for col in &obs.profile {
            let mut line = format!("{},{},", obs.time_s, col.x_m as f32);
            let cells = std::iter::once(col.surface_m).chain(col.layer_tops_m.iter().copied());
            let text: Vec<String> = cells
                .map(|v| v.map_or_else(String::new, |v| (v as f32).to_string()))
                .collect();
            line.push_str(&text.join(","));
            writeln!(self.w, "{line}")?;
        }
        self.w.flush()
    }
}

/// The paper's bed interfaces, one row per column per output interval (long format): time, x,
/// Zb (moving / immobile grains), Zs (water / moving grains), Zw (free surface), m; a cell is
/// empty where the column does not hold that interface.
pub struct BedProfileCsv<W: Write> {
    w: W,
}

impl<W: Write> BedProfileCsv<W> {
    pub fn new(mut w: W) -> io::Result<Self> {
        writeln!(w, "time_s,x_m,zb_m,zs_m,zw_m")?;
        w.flush()?;
        Ok(BedProfileCsv { w })
    }

    pub fn rows(&mut self, obs: &Observations) -> io::Result<()> {
        for (col, bed) in obs.profile.iter().filter_map(|c| c.bed.map(|b| (c, b))) {
            let cell = |v: Option<f64>| v.map_or_else(String::new, |v| (v as f32).to_string());
            writeln!(
                self.w,
                "{},{},{},{},{}",
                obs.time_s,
                col.x_m as f32,
                cell(bed.zb_m),
                cell(bed.zs_m),
                cell(bed.zw_m)
            )?;
        }
        self.w.flush()
    }
}

/// An open flume's discharge and eroded mass, one row per output interval (Eq. 34).
pub struct ErodedMassCsv<W: Write> {
    w: W,
}

impl<W: Write> ErodedMassCsv<W> {
    pub fn new(mut w: W) -> io::Result<Self> {
        writeln!(
            w,
            "time_s,inflow_m3_per_s,eroded_particles,eroded_kg_per_m,eroded_kg,eroded_rate_kg_per_s,parked_particles,pores_particles,worn_particles"
        )?;
        w.flush()?;
        Ok(ErodedMassCsv { w })
    }

    pub fn row(&mut self, obs: &Observations) -> io::Result<()> {
        let Some(f) = obs.flume else {
            return Ok(());
        };
        writeln!(
            self.w,
            "{},{},{},{},{},{},{},{},{}",
            obs.time_s,
            f.inflow_m3_per_s,
            f.eroded_particles,
            f.eroded_kg_per_m,
            f.eroded_kg,
            f.eroded_rate_kg_per_s,
            f.parked_particles,
            f.soaked_particles,
            f.worn_particles
        )?;
        self.w.flush()
    }
}

/// sediment_budget.csv: where the sand the flow has moved is at each output, in grains
/// (`flume_solver::budget`), the mass worn off grains still held (`worn`, in grains), and the
/// grains mobilised and the mass worn from each stretch of the bed, the stretch named by its
/// bounds along the flume.
pub struct BudgetCsv<W: Write> {
    w: W,
}

impl<W: Write> BudgetCsv<W> {
    pub fn new(mut w: W, edges_m: &[f64; STRETCHES + 1]) -> io::Result<Self> {
        let mut header = String::from(
            "time_s,mobilised,moving,suspended,deposited,past_bed,collected,excluded,\
             travelled_far,furthest_m,worn",
        );
        for what in ["mobilised", "worn"] {
            for k in 0..STRETCHES {
                // Three decimals tell the stretches of any flume apart (each is at least a dp
                // wide).
                let _ = write!(
                    header,
                    ",{what}_from_{:.3}_{:.3}_m",
                    edges_m[k],
                    edges_m[k + 1]
                );
            }
        }
        writeln!(w, "{header}")?;
        w.flush()?;
        Ok(BudgetCsv { w })
    }

    pub fn row(&mut self, r: &BudgetRow) -> io::Result<()> {
        let stretches: Vec<String> = (r.mobilised_by_stretch.iter().map(u64::to_string))
            .chain(r.worn_by_stretch.iter().map(|w| format!("{w:.6}")))
            .collect();
        writeln!(
            self.w,
            "{},{},{},{},{},{},{},{},{},{},{:.6},{}",
            r.time_s,
            r.mobilised,
            r.moving,
            r.suspended,
            r.deposited,
            r.past_bed,
            r.collected,
            r.excluded,
            r.travelled_far,
            r.furthest_m,
            r.worn,
            stretches.join(",")
        )?;
        self.w.flush()
    }
}

/// Quotes a cell when a gauge name or an error message would otherwise break the CSV
/// (RFC 4180).
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flume_solver::{GaugeReading, ProbeReading};

    #[test]
    fn header_and_rows_with_missing_values() {
        let mut buf = Vec::new();
        let mut csv = GaugeCsv::new(
            &mut buf,
            &["near_wall".into(), "a,b".into()],
            &["toe".into()],
        )
        .unwrap();
        let obs = Observations {
            time_s: 0.005,
            steps: 42,
            dt_s: 1.25e-4,
            gauges: vec![
                GaugeReading {
                    name: "near_wall".into(),
                    level_m: Some(0.19),
                },
                GaugeReading {
                    name: "a,b".into(),
                    level_m: None,
                },
            ],
            probes: vec![ProbeReading {
                name: "toe".into(),
                pressure_pa: Some(1900.5),
            }],
            front_m: Some(0.1),
            profile: vec![],
            max_speed_m_per_s: 0.5,
            max_density_error: 0.002,
            fluid_particles: 3200,
            recoveries: 1,
            cfl: 0.1,
            region_counts: None,
            flume: None,
        };
        csv.row(&obs).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert_eq!(
            text,
            "time_s,step,dt_s,front_m,max_speed_m_per_s,max_density_error,cfl,recoveries,near_wall_m,\"a,b_m\",toe_pa\n\
             0.005,42,0.000125,0.1,0.5,0.002,0.1,1,0.19,,1900.5\n"
        );
    }

    /// Observations at `time_s` holding only a profile.
    fn profile_at(time_s: f64, profile: Vec<flume_solver::ProfileColumn>) -> Observations {
        Observations {
            profile,
            ..crate::test_support::observations_at(time_s)
        }
    }

    #[test]
    fn bed_profile_rows_skip_columns_without_interfaces() {
        let mut buf = Vec::new();
        let mut csv = BedProfileCsv::new(&mut buf).unwrap();
        let bed = flume_solver::BedInterfaces {
            zb_m: Some(0.05),
            zs_m: Some(0.0625),
            zw_m: None,
        };
        let obs = profile_at(
            0.25,
            vec![flume_solver::ProfileColumn {
                x_m: 1.0,
                surface_m: None,
                layer_tops_m: vec![None, Some(0.0625)],
                bed: Some(bed),
            }],
        );
        csv.rows(&obs).unwrap();
        assert_eq!(
            String::from_utf8(buf).unwrap(),
            "time_s,x_m,zb_m,zs_m,zw_m\n0.25,1,0.05,0.0625,\n"
        );
    }

    #[test]
    fn profile_rows_are_long_format_with_empty_cells_for_absent_layers() {
        let mut buf = Vec::new();
        let mut csv =
            ProfileCsv::new(&mut buf, &["water".to_string(), "sand".to_string()]).unwrap();
        let obs = profile_at(
            0.5,
            vec![
                flume_solver::ProfileColumn {
                    x_m: 0.25,
                    surface_m: Some(0.1),
                    layer_tops_m: vec![Some(0.1), Some(0.04)],
                    bed: None,
                },
                flume_solver::ProfileColumn {
                    x_m: 0.5,
                    surface_m: None,
                    layer_tops_m: vec![None, Some(0.03)],
                    bed: None,
                },
            ],
        );
        csv.rows(&obs).unwrap();
        assert_eq!(
            String::from_utf8(buf).unwrap(),
            "time_s,x_m,surface_m,water_top_m,sand_top_m\n0.5,0.25,0.1,0.1,0.04\n0.5,0.5,,,0.03\n"
        );
    }

    /// Each budget figure under its own name: the worn columns follow the mobilised ones, each
    /// stretch's value under that stretch's bounds.
    #[test]
    fn budget_rows_put_each_stretch_under_its_bounds() {
        let mut buf = Vec::new();
        let edges = [0.0, 0.4, 0.8, 1.2, 1.6, 2.0];
        let mut csv = BudgetCsv::new(&mut buf, &edges).unwrap();
        csv.row(&BudgetRow {
            time_s: 1.5,
            mobilised: 9,
            moving: 1,
            suspended: 2,
            deposited: 3,
            past_bed: 0,
            collected: 3,
            excluded: 1,
            travelled_far: 4,
            furthest_m: 0.25,
            mobilised_by_stretch: [5, 0, 0, 0, 4],
            worn: 0.75,
            worn_by_stretch: [0.5, 0.0, 0.0, 0.0, 0.25],
        })
        .unwrap();
        let text = String::from_utf8(buf).unwrap();
        let mut lines = text.lines();
        let names: Vec<&str> = lines.next().unwrap().split(',').collect();
        let values: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(names.len(), values.len(), "{text}");
        let cell = |name: &str| {
            let k = names.iter().position(|n| *n == name);
            values[k.unwrap_or_else(|| panic!("no column {name} in {text}"))]
        };
        assert_eq!(cell("collected"), "3");
        assert_eq!(cell("worn"), "0.750000");
        assert_eq!(cell("mobilised_from_0.000_0.400_m"), "5");
        assert_eq!(cell("mobilised_from_1.600_2.000_m"), "4");
        assert_eq!(cell("worn_from_0.000_0.400_m"), "0.500000");
        assert_eq!(cell("worn_from_1.600_2.000_m"), "0.250000");
        assert_eq!(cell("worn_from_0.400_0.800_m"), "0.000000");
    }
}
