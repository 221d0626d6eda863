//! What `bench --levels` reads off the bed at a run's end: the cushion of water under the flow,
//! the held sand's push against it, and the sand standing out of the bed uncollected.

use crate::adapters::table::Table;
use flume_solver::bed_contact::bed_contact;
use flume_solver::hydraulics::Channel;
use flume_solver::{Case, ParticleRegion, Particles, Simulation};

/// The cushion under the flow and the held bed's push, column by column, at the run's end
/// (`flume_solver::bed_contact`).
pub(super) fn print_bed(sim: &Simulation, case: &Case, particles: &Particles, regions: &[u32]) {
    let Some(contact) = bed_contact(case, sim.derived(), particles, regions) else {
        return;
    };
    let mut table = Table::new([
        "x (m)",
        "bed top (m)",
        "water p5 - bed (dp)",
        "surface (m)",
        "bed p / water weight",
    ]);
    for c in &contact.columns {
        let (gap, surface, ratio) = match &c.wet {
            None => ("dry".to_string(), "-".to_string(), None),
            Some(w) => (
                format!("{:.2}", w.gap_dp),
                format!("{:.4}", w.surface_m),
                w.tait_over_load,
            ),
        };
        table.row([
            format!("{:.1}", c.x_min_m),
            format!("{:.4}", c.bed_top_m),
            gap,
            surface,
            ratio.map_or("-".to_string(), |r| format!("{r:.2}")),
        ]);
    }
    print!("{table}");
    // Water can leave only over the weir: any below the floor went through a wall.
    let dp = case.numerics.dp_m;
    let floor = case.domain.min_m[1] - f64::from(case.walls.layers) * dp;
    let water = super::water_code(case);
    let lost = (0..particles.len())
        .filter(|&i| particles.phase(i) == water && f64::from(particles.positions[i][1]) < floor)
        .count();
    println!("water particles below the floor's outer layer (through a wall): {lost}");
    let push = match (contact.median_tait_over_load(), contact.felt_over_load()) {
        (Some(tait), Some(felt)) => format!(
            "; the top sand's Tait pressure over the water's weight: median {tait:.2}, as the \
             water feels it (x {:.3}: a wall's is felt whole, a dynamic boundary's as \
             rho_w / rho_s) {felt:.2} (goal 0.75-1.25)",
            contact.felt_factor
        ),
        _ => String::new(),
    };
    println!(
        "water over the bed: largest 5th-percentile gap {} dp (the goal: at most 1.2 dp){push}",
        contact
            .largest_gap_dp()
            .map_or("-".to_string(), |g| format!("{g:.2}"))
    );
}

/// The sand the collector has not taken that stands out of the bed, by x: its centre over the
/// bed's surface, or past the bed's end (the sill's downstream face); whether each is held. A
/// held grain there is a wall as high as a third of the flow at dp = 1 cm.
pub(super) fn loose_sand(
    case: &Case,
    channel: &Channel,
    particles: &Particles,
    regions: &[u32],
) -> Vec<(f32, f32, bool)> {
    let Some((sand, _)) = case.sediment_phases() else {
        return Vec::new();
    };
    let out_of_bed =
        |x: [f32; 4]| f64::from(x[1]) > channel.bed_m || f64::from(x[0]) > channel.x_bed_end_m;
    let mut loose: Vec<(f32, f32, bool)> = (0..particles.len())
        // Phase codes are the case's indices plus one (`Particles::phase`).
        .filter(|&i| particles.phase(i) == sand as u32 + 1)
        .filter(|&i| out_of_bed(particles.positions[i]))
        .map(|i| {
            let held = regions
                .get(i)
                .is_some_and(|&w| ParticleRegion::from_word(w).held);
            (particles.positions[i][0], particles.positions[i][1], held)
        })
        .collect();
    loose.sort_by(|a, b| a.0.total_cmp(&b.0));
    loose
}

pub(super) fn print_loose_sand(
    case: &Case,
    channel: &Channel,
    particles: &Particles,
    regions: &[u32],
) {
    let loose = loose_sand(case, channel, particles, regions);
    let listed: Vec<String> = loose
        .iter()
        .map(|(x, y, held)| {
            let how = if *held { "held" } else { "moving" };
            format!("({x:.3}, {y:.3}) m {how}")
        })
        .collect();
    let tail = if listed.is_empty() {
        String::new()
    } else {
        format!(": {}", listed.join(", "))
    };
    println!(
        "sand out of the bed (its centre over the surface at {:.3} m, or past the bed's end at \
         {:.2} m), not collected: {}{tail}",
        channel.bed_m,
        channel.x_bed_end_m,
        loose.len(),
    );
}
