//! Observations on the CPU backend: kernel sums at probe points (`physics::probe`'s formula
//! over the cell list, as `probe_interpolate.wgsl`) and the whole-state extremes of
//! `observe_reduce.wgsl`.

use super::State;
use super::grid::Grid;
use crate::contract::{Extremes, order_key};
use crate::physics::Params;
use crate::physics::interaction::phase_index;
use crate::physics::probe::{ProbeSums, add_particle};

/// The sums at `point` in the GPU's layout: pressure sum, then the fullness of phases 1-3;
/// with a sediment (two fluid phases) the last is the fullness of the un-yielded sediment,
/// `unyielded(k)` for sorted slot k of `b`.
pub fn probe_sums(
    model: &Params,
    grid: &Grid,
    point: [f32; 3],
    b: &State,
    unyielded: &dyn Fn(usize) -> bool,
) -> [f32; 4] {
    let mut sums = ProbeSums::default();
    let mut bed = 0.0;
    grid.rows(grid.coords(&point), |range| {
        for j in range {
            let vw = add_particle(model, point, &b.positions[j], &b.vel_rho[j], &mut sums);
            if vw > 0.0 && unyielded(j) {
                bed += vw;
            }
        }
    });
    let f = sums.phase_fullness;
    [sums.pressure_sum, f[1], f[2], f[3] + bed]
}

/// The surge front (largest x of a mobile particle), the largest speed and relative density
/// error, and the number of mobile particles.
pub fn extremes(model: &Params, positions: &[[f32; 4]], vel_rho: &[[f32; 4]]) -> Extremes {
    let mut e = Extremes {
        front_key: 0,
        max_speed_bits: 0,
        max_rho_err_bits: 0,
        fluid_count: 0,
    };
    for (x, v) in positions.iter().zip(vel_rho) {
        let phase = &model.phases[phase_index(x)];
        if !phase.mobile {
            continue;
        }
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        e.front_key = e.front_key.max(order_key(x[0]));
        e.max_speed_bits = e.max_speed_bits.max(speed.to_bits());
        e.max_rho_err_bits = e
            .max_rho_err_bits
            .max((v[3] / phase.rho0 - 1.0).abs().to_bits());
        e.fluid_count += 1;
    }
    e
}
