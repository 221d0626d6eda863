//! The pick-up's WGSL functions against `physics::sediment::pickup`: the draw, the rate, the
//! choice, and the two ways a pick-up is spent (worn away, and Exner's balance).

use super::common::gpu_lock;
use super::common::probe::{Input, Probe, probe};
use flume_solver::physics::sediment::pickup::{
    EXNER_SPENT, EXNER_WHOLE, PICKUP_WHOLE, exner_exchange, exner_pickup, integrated_pickup,
    picked_up, pickup_draw, pickup_rate,
};

/// The pick-up: the draw's bits for ids and steps from 0 to past 2^31, the rate from below the
/// threshold to T = 100, and whether a particle is picked up at chances from none to certain.
#[test]
fn the_pickup() {
    let _lock = gpu_lock();
    let Some(p) = probe() else { return };
    let ids = [0u32, 1, 7, 4096, 65_535, 1 << 20, 0x8000_0001, u32::MAX];
    let steps = [0u32, 1, 2, 999, 1 << 16, 0xdead_beef, u32::MAX];
    let mut pairs = Vec::new();
    for &id in &ids {
        for &step in &steps {
            pairs.push((id, step));
        }
    }
    // The 32-bit values travel as halves, each exact in an f32.
    let halves = |v: u32| [(v >> 16) as f32, (v & 0xffff) as f32];
    let packed: Vec<Input> = pairs
        .iter()
        .map(|&(id, step)| {
            let [i1, i0] = halves(id);
            let [s1, s0] = halves(step);
            [[i1, i0, s1, s0], [0.0; 4]]
        })
        .collect();
    let helper = "fn draw_probe(a: vec4<f32>) -> vec4<f32> {
    let id = (u32(a.x) << 16u) | u32(a.y);
    let d = pickup_draw(id, (u32(a.z) << 16u) | u32(a.w));
    return vec4<f32>(f32(d >> 16u), f32(d & 0xffffu), 0.0, 0.0);
}
";
    let draws = p.run_with(helper, "draw_probe(a)", &packed);
    for (&(id, step), got) in pairs.iter().zip(&draws) {
        let want = halves(pickup_draw(id, step));
        assert_eq!([got[0], got[1]], want, "the draw of id {id} at step {step}");
    }

    let per_s = p.model.pickup_per_s;
    assert!(per_s > 0.0, "the probe's sand is picked up");
    let rates: Vec<Input> = [0.0, 0.5, 1.0, 1.0001, 1.3, 2.0, 11.0, 101.0]
        .into_iter()
        .map(|tau_b| [[tau_b, 1.0, 0.0, 0.0], [0.0; 4]])
        .collect();
    p.agree(
        "pick-up rate",
        "vec4<f32>(pickup_rate(a.x, a.y), 0.0, 0.0, 0.0)",
        &rates,
        1,
        |i| [pickup_rate(per_s, i[0][0], i[0][1]), 0.0, 0.0, 0.0],
    );

    let mut chances = Vec::new();
    for &(id, step) in &pairs {
        for rate in [0.0, 1e-3, 0.3, 0.5, 0.9, 1.0, 5.0] {
            let [i1, i0] = halves(id);
            let [s1, s0] = halves(step);
            chances.push([[i1, i0, s1, s0], [rate, 1.0, 0.0, 0.0]]);
        }
    }
    let helper = "fn picked_probe(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let id = (u32(a.x) << 16u) | u32(a.y);
    let hit = picked_up(id, (u32(a.z) << 16u) | u32(a.w), b.x, b.y);
    return vec4<f32>(select(0.0, 1.0, hit), 0.0, 0.0, 0.0);
}
";
    let hits = p.run_with(helper, "picked_probe(a, b)", &chances);
    for (i, got) in chances.iter().zip(&hits) {
        let id = ((i[0][0] as u32) << 16) | i[0][1] as u32;
        let step = ((i[0][2] as u32) << 16) | i[0][3] as u32;
        let want = picked_up(id, step, i[1][0], i[1][1]);
        assert_eq!(
            got[0] > 0.5,
            want,
            "picked up: id {id}, step {step}, rate {}",
            i[1][0]
        );
    }
    // Not vacuous: some are picked up and some not.
    let picked = hits.iter().filter(|h| h[0] > 0.5).count();
    assert!(
        picked > chances.len() / 4 && picked < chances.len() * 3 / 4,
        "{picked}"
    );
    worn_away_alike(&p, &pairs, halves);
    exner_alike(&p, &pairs, halves);
}

/// `integrated_pickup` of both sides, to the unit: shares of a step from none through a
/// fraction of a unit (rounded by the draw) to a whole particle, from nothing worn to one unit
/// short of the whole.
fn worn_away_alike(p: &Probe, pairs: &[(u32, u32)], halves: impl Fn(u32) -> [f32; 2]) {
    let mut cases = Vec::new();
    for &(id, step) in pairs {
        for units in [0u32, 1, 4_194_304, PICKUP_WHOLE - 1] {
            for share in [0.0f32, 0.3 / PICKUP_WHOLE as f32, 2.7e-6, 0.25, 1.0, 3.0] {
                let [i1, i0] = halves(id);
                let [s1, s0] = halves(step);
                let [u1, u0] = halves(units);
                cases.push([[i1, i0, s1, s0], [share, 1.0, u1, u0]]);
            }
        }
    }
    let helper = "fn worn_probe(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let id = (u32(a.x) << 16u) | u32(a.y);
    let units = (u32(b.z) << 16u) | u32(b.w);
    let w = integrated_pickup(units, id, (u32(a.z) << 16u) | u32(a.w), b.x, b.y);
    return vec4<f32>(f32(w >> 16u), f32(w & 0xffffu), 0.0, 0.0);
}
";
    let got = p.run_with(helper, "worn_probe(a, b)", &cases);
    let (mut rounded_up, mut rounded_down) = (0, 0);
    for (i, got) in cases.iter().zip(&got) {
        let id = ((i[0][0] as u32) << 16) | i[0][1] as u32;
        let step = ((i[0][2] as u32) << 16) | i[0][3] as u32;
        let units = ((i[1][2] as u32) << 16) | i[1][3] as u32;
        let got = ((got[0] as u32) << 16) | got[1] as u32;
        let want = integrated_pickup(units, id, step, i[1][0], i[1][1]);
        assert_eq!(
            got < PICKUP_WHOLE,
            want.is_some(),
            "worn away: id {id}, step {step}, units {units}, share {}",
            i[1][0]
        );
        if let Some(want) = want {
            assert_eq!(
                got, want,
                "id {id}, step {step}, units {units}, share {}",
                i[1][0]
            );
        }
        if i[1][0] == 0.3 / PICKUP_WHOLE as f32 && units == 0 {
            rounded_up += usize::from(got == 1);
            rounded_down += usize::from(got == 0);
        }
    }
    // Not vacuous: a share of 0.3 units is rounded both ways.
    assert!(
        rounded_up > 0 && rounded_down > 0,
        "{rounded_up} / {rounded_down}"
    );
}

/// `exner_exchange` and `exner_pickup` of both sides: what a held particle passes on and keeps
/// where it is passed nothing, less than it carries, more, and more than it has room for, and
/// one worn nearly or wholly away; and its units to the unit from a whole particle's surplus to
/// its whole loss, for
/// losses and gains from none through a fraction of a unit to a whole particle.
fn exner_alike(p: &Probe, pairs: &[(u32, u32)], halves: impl Fn(u32) -> [f32; 2]) {
    let whole = EXNER_WHOLE as i32;
    let mut exchanges = Vec::new();
    for units in [
        -whole,
        1000 - whole,
        -1,
        0,
        whole / 2,
        EXNER_SPENT - 1000,
        EXNER_SPENT,
    ] {
        for (flux, upstream, rate) in [(0.09, 0.0, 0.05), (0.09, 0.05, 0.05), (0.02, 0.5, 0.05)] {
            for dt in [1e-4f32, 1.0] {
                exchanges.push([[flux, upstream, rate, dt], [units as f32, 0.0, 0.0, 0.0]]);
            }
        }
    }
    p.agree_within(
        "Exner's exchange",
        "vec4<f32>(exner_exchange(a.x, a.y, a.z, i32(b.x), a.w), 0.0, 0.0)",
        &exchanges,
        2,
        1e-6,
        |i| {
            let (out, net) = exner_exchange(i[0][0], i[0][1], i[0][2], i[1][0] as i32, i[0][3]);
            [out, net, 0.0, 0.0]
        },
    );
    let mut cases = Vec::new();
    for &(id, step) in pairs {
        for units in [
            -whole,
            5 - whole,
            -1,
            0,
            1,
            whole / 2,
            EXNER_SPENT - 1,
            EXNER_SPENT,
        ] {
            for net in [
                0.0f32,
                0.3 / EXNER_WHOLE as f32,
                -2.7e-6,
                0.25,
                -0.25,
                3.0,
                -3.0,
            ] {
                let [i1, i0] = halves(id);
                let [s1, s0] = halves(step);
                let [u1, u0] = halves(units as u32);
                cases.push([[i1, i0, s1, s0], [net, 1.0, u1, u0]]);
            }
        }
    }
    let helper = "fn exner_probe(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let id = (u32(a.x) << 16u) | u32(a.y);
    let units = bitcast<i32>((u32(b.z) << 16u) | u32(b.w));
    let w = bitcast<u32>(exner_pickup(units, id, (u32(a.z) << 16u) | u32(a.w), b.x, b.y));
    return vec4<f32>(f32(w >> 16u), f32(w & 0xffffu), 0.0, 0.0);
}
";
    let got = p.run_with(helper, "exner_probe(a, b)", &cases);
    let mut built = 0;
    for (i, got) in cases.iter().zip(&got) {
        let id = ((i[0][0] as u32) << 16) | i[0][1] as u32;
        let step = ((i[0][2] as u32) << 16) | i[0][3] as u32;
        let units = (((i[1][2] as u32) << 16) | i[1][3] as u32) as i32;
        let got = (((got[0] as u32) << 16) | got[1] as u32) as i32;
        let want = exner_pickup(units, id, step, i[1][0], i[1][1]);
        let what = format!("id {id}, step {step}, units {units}, net {}", i[1][0]);
        assert_eq!(got < EXNER_SPENT, want.is_some(), "worn away: {what}");
        if let Some(want) = want {
            assert_eq!(got, want, "{what}");
            built += usize::from(want < 0);
        }
    }
    // Not vacuous: some particles end the step built up beyond their own mass.
    assert!(built > pairs.len(), "{built}");
}
