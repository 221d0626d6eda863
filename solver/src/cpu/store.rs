//! The end of a step on the CPU backend (`store_rule.wgsl`, held to it input by input by
//! `tests/wgsl_store.rs`, and the open flume's branches of
//! the symplectic predictor): walls, held sediment, free particles with their health check,
//! and in an open flume the outlet, the collector, the inlet buffer, a bottom outlet's duct,
//! the parked reservoir and the exclusion of a particle whose density left the range.

use crate::contract::{BOUNDARY_GENERALISED, ExcludedParticle, FlumeGpu, SimParams};
use crate::health::Health;
use crate::physics::integrate::Particle;
use crate::physics::{Params, Phase};

/// What storing one particle did, for the step state's counters.
#[derive(Clone, Copy, Debug, Default)]
pub struct Event {
    pub flags: u32,
    pub parked: bool,
    pub eroded: bool,
    pub excluded: Option<ExcludedParticle>,
    pub excluded_sediment: bool,
    /// A held grain was parked: its mass left its neighbours' kernels while they slept
    /// (`multiphase::deep`).
    pub held_parked: bool,
}

impl Event {
    /// Whether storing the particle did anything the counters see.
    pub fn happened(&self) -> bool {
        self.flags != 0
            || self.parked
            || self.eroded
            || self.excluded.is_some()
            || self.excluded_sediment
    }
}

pub struct Store<'a> {
    params: &'a SimParams,
    phases: &'a [Phase],
    clamp: bool,
    /// The open flume's block, None for a closed tank.
    flume: Option<&'a FlumeGpu>,
}

impl<'a> Store<'a> {
    pub fn new(params: &'a SimParams, model: &'a Params) -> Store<'a> {
        Store {
            params,
            phases: &model.phases,
            clamp: model.clamp_negative_pressure,
            flume: (params.flume.enabled != 0).then_some(&params.flume),
        }
    }

    pub fn phase(&self, x: &[f32; 4]) -> &'a Phase {
        &self.phases[x[3].to_bits() as usize]
    }

    /// Whether the inlet carries `x` out at its velocity: water, or sediment, in its buffer.
    /// Sand the jet lifts from a bed under the orifice came to rest held in the opening, where
    /// the inlet places no particle over another: two grains held there from t = 50 s drained
    /// 150 of the CI flume's 950 stored particles in 10 s (docs/scour/README.md). No grain
    /// rests in an orifice's jet.
    fn carried_by_inlet(&self, f: &FlumeGpu, x: &[f32; 4]) -> bool {
        let kind = x[3].to_bits();
        let sediment = self.params.sediment.phase;
        (kind == f.water_phase || (sediment != 0 && kind == sediment)) && f.in_inlet(x)
    }

    fn in_duct(f: &FlumeGpu, x: &[f32; 4]) -> bool {
        x[0] >= f.duct_x_min && x[1] > f.duct_y_min && x[1] <= f.duct_y_max
    }

    /// Whether a particle at `x` moves at an imposed velocity (inlet buffer, duct): its
    /// acceleration means nothing and does not bound the step.
    pub fn velocity_imposed(&self, x: &[f32; 4]) -> bool {
        self.flume.is_some_and(|f| {
            self.carried_by_inlet(f, x) || (x[3].to_bits() == f.water_phase && Self::in_duct(f, x))
        })
    }

    /// Whether `x` is a parked particle of an open flume.
    pub fn parked(&self, x: &[f32; 4]) -> bool {
        self.flume.is_some_and(|f| x[3].to_bits() == f.parked_phase)
    }

    /// An inlet buffer particle's density: the one it entered with, or under the generalised
    /// wall condition its own by continuity (`integrated`, no tension): at rest density the
    /// buffer pushes on the water it meets with no pressure, and the water it squeezes out ran
    /// into the apron under it and through it (`physics::boundary`). `inlet_density` of
    /// params.wgsl, compared by `tests/wgsl_store.rs`.
    fn inlet_density(&self, phase: &Phase, entered: f32, integrated: f32) -> f32 {
        if self.params.boundary_mode == BOUNDARY_GENERALISED {
            integrated.max(phase.rho0)
        } else {
            entered
        }
    }

    fn clamped(&self, phase: &Phase, rho: f32) -> f32 {
        if self.clamp { rho.max(phase.rho0) } else { rho }
    }

    /// The predictor's half step (`symplectic_predictor.wgsl`) for particle `p`, `vr`, held or
    /// not, whose free half step by `physics::integrate::predict` is `free`.
    pub fn half_step(
        &self,
        p: &[f32; 4],
        vr: &[f32; 4],
        held: bool,
        half_dt: f32,
        free: Particle,
    ) -> Particle {
        let phase = self.phase(p);
        if let Some(f) = self.flume {
            if p[3].to_bits() == f.parked_phase {
                return (*p, *vr);
            }
            if self.carried_by_inlet(f, p) {
                let moved = [p[0] + half_dt * f.inlet_u, p[1], p[2], p[3]];
                let rho = self.inlet_density(phase, vr[3], free.1[3]);
                return (moved, [f.inlet_u, 0.0, 0.0, rho]);
            }
        }
        let (x, mut v) = free;
        if !phase.mobile {
            return (x, v);
        }
        if held {
            return (*p, [0.0, 0.0, 0.0, v[3]]);
        }
        v[3] = self.clamped(phase, v[3]);
        (x, v)
    }

    /// Particle `id` stored after a step of `dt` from `p`, `vr`, its free new state by the
    /// integrator being `moved`.
    pub fn apply(
        &self,
        id: u32,
        p: &[f32; 4],
        vr: &[f32; 4],
        held: bool,
        dt: f32,
        moved: Particle,
    ) -> (Particle, Event) {
        let phase = self.phase(p);
        let (x, v) = moved;
        if let (Some(f), true) = (self.flume, phase.mobile)
            && let Some((stored, mut event)) = self.flume_zones(f, id, (p, vr), dt, (x, v))
        {
            event.held_parked = held && event.parked;
            return (stored, event);
        }
        if !phase.mobile {
            // Walls keep position and velocity and rho >= rho0 (the integrator saw to it);
            // parked particles stay as they are.
            return if self.parked(p) {
                ((*p, *vr), Event::default())
            } else {
                ((x, v), Event::default())
            };
        }
        let rho = self.clamped(phase, v[3]);
        if held {
            return self.checked(phase, *p, [0.0, 0.0, 0.0, rho]);
        }
        let finite =
            (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                .abs()
                <= 3.0e38;
        if let Some(f) = self.flume
            && (rho / phase.rho0 - 1.0).abs() > self.params.rho_ratio_max
            && finite
        {
            let kind = p[3].to_bits();
            let (parked, mut event) = self.park(f, id, false);
            event.excluded = Some(ExcludedParticle {
                id,
                phase: kind,
                x: x[0],
                y: x[1],
                u: v[0],
                v: v[1],
                rho,
                pad: 0,
            });
            event.excluded_sediment =
                self.params.sediment.phase != 0 && kind == self.params.sediment.phase;
            return (parked, event);
        }
        self.checked(phase, x, [v[0], v[1], v[2], rho])
    }

    /// Particle `id` of a mobile phase stored where the open flume `f` treats it apart: past the
    /// outlet, sediment in the collector, water or sediment in the inlet buffer, water in a
    /// duct; None elsewhere.
    fn flume_zones(
        &self,
        f: &FlumeGpu,
        id: u32,
        (p, vr): (&[f32; 4], &[f32; 4]),
        dt: f32,
        (x, v): Particle,
    ) -> Option<(Particle, Event)> {
        let phase = self.phase(p);
        let kind = p[3].to_bits();
        let sediment = self.params.sediment.phase;
        let is_sediment = sediment != 0 && kind == sediment;
        if x[0] > f.outlet_x {
            return Some(self.park(f, id, is_sediment));
        }
        if is_sediment
            && x[0] >= f.collector_x_min
            && x[0] <= f.collector_x_max
            && x[1] < f.collector_y_max
        {
            return Some(self.park(f, id, true));
        }
        if self.carried_by_inlet(f, p) {
            // Imposed velocity, at the density it entered with (or its own, see below).
            let rho = self.inlet_density(phase, vr[3], v[3]);
            return Some(self.checked(
                phase,
                [p[0] + dt * f.inlet_u, p[1], p[2], p[3]],
                [f.inlet_u, 0.0, 0.0, rho],
            ));
        }
        if kind == f.water_phase && Self::in_duct(f, p) {
            let rho = self.clamped(phase, v[3]);
            return Some(self.checked(
                phase,
                [p[0] + dt * f.duct_u, p[1], p[2], p[3]],
                [f.duct_u, 0.0, 0.0, rho],
            ));
        }
        None
    }

    /// Parks particle `id` at its spot as water; eroded when it was sediment.
    fn park(&self, f: &FlumeGpu, id: u32, eroded: bool) -> (Particle, Event) {
        let spot = f.parking_spot(id);
        let rho = self.phases[f.parked_phase as usize].rho0;
        let event = Event {
            parked: true,
            eroded,
            ..Event::default()
        };
        ((spot, [0.0, 0.0, 0.0, rho]), event)
    }

    /// The state as stored, with the health flags it raises.
    fn checked(&self, phase: &Phase, x: [f32; 4], v: [f32; 4]) -> (Particle, Event) {
        let s = x[0] * x[0]
            + x[1] * x[1]
            + x[2] * x[2]
            + v[0] * v[0]
            + v[1] * v[1]
            + v[2] * v[2]
            + v[3];
        // Infinities (and sums near them) exceed the bound of store_rule.wgsl; NaN fails it.
        let flags = if s.is_nan() || s.abs() > 3.0e38 {
            Health::NON_FINITE
        } else if (v[3] / phase.rho0 - 1.0).abs() > self.params.rho_ratio_max {
            Health::DENSITY_RUNAWAY
        } else {
            0
        };
        (
            (x, v),
            Event {
                flags,
                ..Event::default()
            },
        )
    }
}

/// Adds a step's events, in sorted order, to the step state's flags and counters; the first
/// exclusions of the chunk are logged.
pub fn tally(st: &mut crate::contract::StepState, events: &[Event]) {
    for e in events {
        st.status |= e.flags;
        st.parked += u32::from(e.parked);
        st.eroded += u32::from(e.eroded);
        if let Some(log) = e.excluded {
            if let Some(slot) = st.excluded_log.get_mut(st.excluded as usize) {
                *slot = log;
            }
            st.excluded += 1;
            st.excluded_sediment += u32::from(e.excluded_sediment);
        }
    }
}
