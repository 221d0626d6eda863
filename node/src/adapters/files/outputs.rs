//! The files a run writes as it goes (`simulate`, and `run --out`): gauges.csv, profile.csv,
//! bed_profile.csv, eroded_mass.csv, sediment_budget.csv and particle snapshots.

use crate::adapters::files::{
    csv::{BedProfileCsv, BudgetCsv, ErodedMassCsv, GaugeCsv, ProfileCsv},
    vtk,
};
use crate::twin::solver_thread::{Opener, Recorder};
use anyhow::{Context, Result};
use flume_solver::budget::{BudgetRow, SedimentBudget};
use flume_solver::{Case, Observations, Particles, Simulation};
use std::fs::{self, File};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Creates `dir/name` and writes its header with `start`.
fn create_csv<T>(
    dir: &Path,
    name: &str,
    start: impl FnOnce(BufWriter<File>) -> std::io::Result<T>,
) -> Result<(PathBuf, T)> {
    let path = dir.join(name);
    let file = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
    let csv =
        start(BufWriter::new(file)).with_context(|| format!("cannot write {}", path.display()))?;
    Ok((path, csv))
}

/// The files of a run: gauges.csv gets a row per output interval, and every
/// `snapshot_every`-th interval k a snapshot `particles_kkkk.vtk`.
pub struct OutputFiles {
    dir: PathBuf,
    csv_path: PathBuf,
    csv: GaugeCsv<BufWriter<File>>,
    /// profile.csv, when the case asks for a layer profile.
    profile: Option<(PathBuf, ProfileCsv<BufWriter<File>>)>,
    /// bed_profile.csv, when the case has a sediment and a profile.
    bed_profile: Option<(PathBuf, BedProfileCsv<BufWriter<File>>)>,
    /// eroded_mass.csv, for an open flume.
    eroded: Option<(PathBuf, ErodedMassCsv<BufWriter<File>>)>,
    /// sediment_budget.csv, for an open flume with a sediment, and the budget's rows so far.
    budget: Option<Budget>,
    snapshot_every: Option<u64>,
}

/// The sediment budget of a run and its file.
struct Budget {
    path: PathBuf,
    csv: BudgetCsv<BufWriter<File>>,
    books: SedimentBudget,
    rows: Vec<BudgetRow>,
}

impl OutputFiles {
    /// Whether the run writes bed_profile.csv (a sediment and a profile).
    pub fn has_bed_profile(&self) -> bool {
        self.bed_profile.is_some()
    }

    /// The files of `case`, whose particles at the start are `initial` (the sediment budget
    /// follows each grain from where it was generated).
    pub fn create(
        dir: &Path,
        case: &Case,
        initial: &Particles,
        snapshot_every: Option<u64>,
    ) -> Result<OutputFiles> {
        fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory {}", dir.display()))?;
        let csv_path = dir.join("gauges.csv");
        let obs = &case.observations;
        let gauges: Vec<String> = obs.gauges.iter().map(|g| g.name.clone()).collect();
        let probes: Vec<String> = obs.pressure_probes.iter().map(|p| p.name.clone()).collect();
        let file = File::create(&csv_path)
            .with_context(|| format!("cannot create {}", csv_path.display()))?;
        let csv = GaugeCsv::new(BufWriter::new(file), &gauges, &probes)
            .with_context(|| format!("cannot write {}", csv_path.display()))?;
        let profile = match &obs.profile {
            None => None,
            Some(_) => {
                let phases: Vec<String> = case.phases.iter().map(|p| p.name.clone()).collect();
                Some(create_csv(dir, "profile.csv", |w| {
                    ProfileCsv::new(w, &phases)
                })?)
            }
        };
        let bed_profile = match (&obs.profile, case.sediment_phases()) {
            (Some(_), Some(_)) => Some(create_csv(dir, "bed_profile.csv", BedProfileCsv::new)?),
            _ => None,
        };
        let eroded = match &case.open_flume {
            Some(_) => Some(create_csv(dir, "eroded_mass.csv", ErodedMassCsv::new)?),
            None => None,
        };
        let budget = match SedimentBudget::new(case, initial) {
            Some(books) => {
                let edges = books.stretch_edges_m();
                let (path, csv) =
                    create_csv(dir, "sediment_budget.csv", |w| BudgetCsv::new(w, &edges))?;
                Some(Budget {
                    path,
                    csv,
                    books,
                    rows: Vec::new(),
                })
            }
            None => None,
        };
        Ok(OutputFiles {
            dir: dir.to_path_buf(),
            csv_path,
            csv,
            profile,
            bed_profile,
            eroded,
            budget,
            snapshot_every,
        })
    }

    /// Observes the state after output interval `k` and writes what is due.
    pub fn record(&mut self, sim: &Simulation, k: u64) -> Result<Observations> {
        let obs = sim
            .observe()
            .context("cannot read the observations back from the GPU")?;
        self.csv
            .row(&obs)
            .with_context(|| format!("cannot write {}", self.csv_path.display()))?;
        if let Some((path, csv)) = &mut self.profile {
            csv.rows(&obs)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some((path, csv)) = &mut self.bed_profile {
            csv.rows(&obs)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        if let Some((path, csv)) = &mut self.eroded {
            csv.row(&obs)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        let snapshot_due = self.snapshot_every.is_some_and(|n| k.is_multiple_of(n));
        if self.budget.is_none() && !snapshot_due {
            return Ok(obs);
        }
        // One read back serves the budget and the snapshot.
        let (particles, regions) = read_state(sim)?;
        if let Some(b) = &mut self.budget {
            let excluded = sim.flume().map_or(0, |f| f.excluded_sediment);
            let row = b.books.update(obs.time_s, &particles, &regions, excluded);
            b.csv
                .row(&row)
                .with_context(|| format!("cannot write {}", b.path.display()))?;
            b.rows.push(row);
        }
        if snapshot_due {
            let name = format!("particles_{k:04}.vtk");
            self.write_snapshot(sim, &name, &particles, &regions, &[])?;
        }
        Ok(obs)
    }

    /// The run starts again from its initial state (the twin's reset): the sediment budget
    /// forgets what the flow had moved, and its rows start again.
    pub fn restart(&mut self) {
        if let Some(b) = &mut self.budget {
            b.books.restart();
            b.rows.clear();
        }
    }

    /// The sediment budget's rows so far, for its plot; empty without a sediment.
    pub fn budget_rows(&self) -> &[BudgetRow] {
        self.budget.as_ref().map_or(&[], |b| &b.rows)
    }

    /// A snapshot of the state as it is now whose `culprit` field is 1 for the particles of
    /// ids `marked`.
    pub fn snapshot_marked(&self, sim: &Simulation, name: &str, marked: &[u32]) -> Result<()> {
        let (particles, regions) = read_state(sim)?;
        self.write_snapshot(sim, name, &particles, &regions, marked)
    }

    /// Writes to a temporary name first, so a crash never leaves a truncated snapshot behind.
    fn write_snapshot(
        &self,
        sim: &Simulation,
        name: &str,
        particles: &Particles,
        regions: &[u32],
        marked: &[u32],
    ) -> Result<()> {
        let path = self.dir.join(name);
        let tmp = self.dir.join(format!("{name}.part"));
        let title = format!(
            "flume-twin {} t = {} s step {}",
            sim.case().name,
            sim.time_s(),
            sim.steps()
        );
        let file =
            File::create(&tmp).with_context(|| format!("cannot create {}", tmp.display()))?;
        vtk::write_particles(BufWriter::new(file), &title, particles, regions, marked)
            .and_then(|()| fs::rename(&tmp, &path))
            .with_context(|| format!("cannot write {}", path.display()))
    }
}

/// The particles and their region words as they are now.
fn read_state(sim: &Simulation) -> Result<(Particles, Vec<u32>)> {
    let particles = sim
        .read_particles()
        .context("cannot read the particles back from the backend")?;
    let regions = sim
        .regions()
        .context("cannot read the particle regions back from the backend")?;
    Ok((particles, regions))
}

impl Recorder for OutputFiles {
    fn record(&mut self, sim: &Simulation, k: u64) -> Result<Observations> {
        OutputFiles::record(self, sim, k)
    }

    fn restart(&mut self) {
        OutputFiles::restart(self);
    }
}

/// The solver thread's opener of the output files in `dir` for its case, without particle
/// snapshots.
pub fn recorder_in(dir: std::path::PathBuf) -> Opener<dyn Recorder> {
    Box::new(move |sim: &Simulation| {
        let files = OutputFiles::create(&dir, sim.case(), sim.initial_particles(), None)?;
        Ok(Box::new(files) as Box<dyn Recorder>)
    })
}
