//! The compute stages, each named as its WGSL file and entry point in `shaders/stages/`,
//! with the bindings it declares (checked against the WGSL by `tests/shaders_validate.rs`).
//! The CPU oracle of each physical stage lives in `physics`.

use crate::gpu::stage::{Access::*, StageSpec};

const COMMON: &[&str] = &[
    "common/params.wgsl",
    "common/kernel.wgsl",
    "common/eos.wgsl",
    "common/grid.wgsl",
];
const WITH_NEIGHBOURS: &[&str] = &[
    "common/params.wgsl",
    "common/kernel.wgsl",
    "common/eos.wgsl",
    "common/grid.wgsl",
    "common/neighbours.wgsl",
    "common/particle_texture.wgsl",
    "common/step_state.wgsl",
];
/// The neighbour passes that run inside a step: they skip the steps past a chunk's end.
const NEIGHBOUR_PASS: &[&str] = &[
    "common/params.wgsl",
    "common/kernel.wgsl",
    "common/eos.wgsl",
    "common/grid.wgsl",
    "common/neighbours.wgsl",
    "common/particle_texture.wgsl",
    "common/step_state.wgsl",
    "common/chunk_idle.wgsl",
    "common/sediment.wgsl",
    "common/flume.wgsl",
];
const WITH_STATE: &[&str] = &["common/params.wgsl", "common/step_state.wgsl"];
const HALF_STEP: &[&str] = &[
    "common/params.wgsl",
    "common/particle_texture.wgsl",
    "common/step_state.wgsl",
    "common/flume.wgsl",
];
const FULL_STEP: &[&str] = &[
    "common/params.wgsl",
    "common/particle_texture.wgsl",
    "common/step_state.wgsl",
    "common/flume.wgsl",
    "common/store_rule.wgsl",
    "common/store_state.wgsl",
];

pub const GRID_CLEAR: StageSpec = StageSpec {
    name: "grid_clear",
    shader: "stages/grid_clear.wgsl",
    imports: &["common/params.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("cell_starts", 1, ReadWrite),
        ("cell_cursor", 2, ReadWrite),
    ],
    entry_points: &["grid_clear"],
    workgroup: 128,
};

pub const GRID_COUNT: StageSpec = StageSpec {
    name: "grid_count",
    shader: "stages/grid_count.wgsl",
    imports: COMMON,
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Read),
        ("cell_of", 2, ReadWrite),
        ("cell_counts", 3, ReadWrite),
    ],
    entry_points: &["grid_count"],
    workgroup: 128,
};

pub const PREFIX_SUM: StageSpec = StageSpec {
    name: "prefix_sum",
    shader: "stages/prefix_sum.wgsl",
    imports: &[],
    bindings: &[
        ("scan", 0, Uniform),
        ("data", 1, ReadWrite),
        ("block_sums", 2, ReadWrite),
    ],
    entry_points: &["prefix_sum_block", "prefix_sum_add"],
    workgroup: 256,
};
/// Elements one `prefix_sum_block` workgroup scans.
pub const PREFIX_SUM_BLOCK: u32 = 512;

pub const GRID_SCATTER: StageSpec = StageSpec {
    name: "grid_scatter",
    shader: "stages/grid_scatter.wgsl",
    imports: &["common/params.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("cell_of", 1, Read),
        ("cell_starts", 2, Read),
        ("cell_cursor", 3, ReadWrite),
        ("sorted_index", 4, ReadWrite),
    ],
    entry_points: &["grid_scatter"],
    workgroup: 128,
};

pub const CELL_SORT: StageSpec = StageSpec {
    name: "cell_sort",
    shader: "stages/cell_sort.wgsl",
    imports: &["common/params.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("cell_starts", 1, Read),
        ("ids", 2, Read),
        ("sorted_index", 3, ReadWrite),
    ],
    entry_points: &["cell_sort"],
    workgroup: 128,
};

/// Indirect dispatch arguments from the active count; see `pipeline::Indirect`.
pub const ACTIVE_DISPATCH: StageSpec = StageSpec {
    name: "active_dispatch",
    shader: "stages/active_dispatch.wgsl",
    imports: &["common/params.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("cell_starts", 1, Read),
        ("dispatch", 2, ReadWrite),
    ],
    entry_points: &["active_dispatch"],
    workgroup: 1,
};

pub const REORDER: StageSpec = StageSpec {
    name: "reorder",
    shader: "stages/reorder.wgsl",
    imports: &["common/params.wgsl", "common/particle_texture.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("sorted_index", 1, Read),
        ("positions", 2, Read),
        ("vel_rho", 3, Read),
        ("ids", 4, Read),
        ("sorted_positions", 5, TextureWrite),
        ("sorted_vel_rho", 6, TextureWrite),
        ("sorted_ids", 7, ReadWrite),
        ("vel_rho_prev", 8, Read),
        ("sorted_vel_rho_prev", 9, ReadWrite),
    ],
    entry_points: &["reorder"],
    workgroup: 128,
};

pub const PARKED_COPY: StageSpec = StageSpec {
    name: "parked_copy",
    shader: "stages/parked_copy.wgsl",
    imports: &[
        "common/params.wgsl",
        "common/particle_texture.wgsl",
        "common/step_state.wgsl",
    ],
    bindings: &[
        ("params", 0, Uniform),
        ("state", 1, ReadWrite),
        ("cell_starts", 2, Read),
        ("positions_n", 3, Texture),
        ("vel_rho_n", 4, Texture),
        ("ids_n", 5, Read),
        ("positions_out", 6, ReadWrite),
        ("vel_rho_out", 7, ReadWrite),
        ("ids_out", 8, ReadWrite),
        ("vel_rho_prev_out", 9, ReadWrite),
        ("regions", 10, ReadWrite),
    ],
    entry_points: &["parked_copy"],
    workgroup: 128,
};

pub const INTERACTION: StageSpec = StageSpec {
    name: "interaction",
    shader: "stages/interaction.wgsl",
    imports: NEIGHBOUR_PASS,
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Texture),
        ("vel_rho", 2, Texture),
        ("cell_starts", 3, Read),
        ("forces", 4, ReadWrite),
        ("state", 5, ReadWrite),
        ("stress_a", 6, Texture),
        ("stress_b", 7, Texture),
    ],
    entry_points: &["interaction"],
    workgroup: 64,
};

pub const RHEOLOGY: StageSpec = StageSpec {
    name: "rheology",
    shader: "stages/rheology.wgsl",
    imports: NEIGHBOUR_PASS,
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Texture),
        ("vel_rho", 2, Texture),
        ("cell_starts", 3, Read),
        ("state", 4, ReadWrite),
        ("stress_a", 5, TextureWrite),
        ("stress_b", 6, TextureWrite),
        ("regions", 7, ReadWrite),
        ("ids", 8, Read),
    ],
    entry_points: &["rheology"],
    workgroup: 64,
};

pub const HOLD: StageSpec = StageSpec {
    name: "hold",
    shader: "stages/hold.wgsl",
    imports: NEIGHBOUR_PASS,
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Texture),
        ("vel_rho", 2, Texture),
        ("cell_starts", 3, Read),
        ("state", 4, ReadWrite),
        ("stress_a", 5, Texture),
        ("stress_b", 6, Texture),
        ("regions", 7, ReadWrite),
        ("ids", 8, Read),
    ],
    entry_points: &["hold"],
    workgroup: 64,
};

pub const DT_UPDATE: StageSpec = StageSpec {
    name: "dt_update",
    shader: "stages/dt_update.wgsl",
    imports: WITH_STATE,
    bindings: &[("params", 0, Uniform), ("state", 1, ReadWrite)],
    entry_points: &["dt_update"],
    workgroup: 1,
};

pub const SYMPLECTIC_PREDICTOR: StageSpec = StageSpec {
    name: "symplectic_predictor",
    shader: "stages/symplectic_predictor.wgsl",
    imports: HALF_STEP,
    bindings: &[
        ("params", 0, Uniform),
        ("state", 1, ReadWrite),
        ("forces", 2, Read),
        ("positions_n", 3, Texture),
        ("vel_rho_n", 4, Texture),
        ("positions_half", 5, TextureWrite),
        ("vel_rho_half", 6, TextureWrite),
        ("regions", 7, Read),
        ("ids_n", 8, Read),
        ("cell_starts", 9, Read),
    ],
    entry_points: &["symplectic_predictor"],
    workgroup: 128,
};

pub const SYMPLECTIC_CORRECTOR: StageSpec = StageSpec {
    name: "symplectic_corrector",
    shader: "stages/symplectic_corrector.wgsl",
    imports: FULL_STEP,
    bindings: &[
        ("params", 0, Uniform),
        ("state", 1, ReadWrite),
        ("forces", 2, Read),
        ("positions_n", 3, Texture),
        ("vel_rho_n", 4, Texture),
        ("ids_n", 5, Read),
        ("vel_rho_half", 6, Texture),
        ("positions_out", 7, ReadWrite),
        ("vel_rho_out", 8, ReadWrite),
        ("ids_out", 9, ReadWrite),
        ("regions", 10, Read),
        ("cell_starts", 11, Read),
    ],
    entry_points: &["symplectic_corrector"],
    workgroup: 128,
};

pub const VERLET_UPDATE: StageSpec = StageSpec {
    name: "verlet_update",
    shader: "stages/verlet_update.wgsl",
    imports: FULL_STEP,
    bindings: &[
        ("params", 0, Uniform),
        ("state", 1, ReadWrite),
        ("forces", 2, Read),
        ("positions_n", 3, Texture),
        ("vel_rho_n", 4, Texture),
        ("ids_n", 5, Read),
        ("vel_rho_before", 6, Read),
        ("positions_out", 7, ReadWrite),
        ("vel_rho_out", 8, ReadWrite),
        ("ids_out", 9, ReadWrite),
        ("vel_rho_prev_out", 10, ReadWrite),
        ("regions", 11, Read),
        ("cell_starts", 12, Read),
    ],
    entry_points: &["verlet_update"],
    workgroup: 128,
};

pub const PROBE_INTERPOLATE: StageSpec = StageSpec {
    name: "probe_interpolate",
    shader: "stages/probe_interpolate.wgsl",
    imports: WITH_NEIGHBOURS,
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Texture),
        ("vel_rho", 2, Texture),
        ("cell_starts", 3, Read),
        ("probe_points", 4, Read),
        ("probe_sums", 5, ReadWrite),
        ("ids", 6, Read),
        ("regions", 7, Read),
    ],
    entry_points: &["probe_interpolate"],
    workgroup: 64,
};

pub const OBSERVE_REDUCE: StageSpec = StageSpec {
    name: "observe_reduce",
    shader: "stages/observe_reduce.wgsl",
    imports: &["common/params.wgsl", "common/particle_texture.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("positions", 1, Texture),
        ("vel_rho", 2, Texture),
        ("extremes", 3, ReadWrite),
        ("cell_starts", 4, Read),
    ],
    entry_points: &["observe_reduce"],
    workgroup: 128,
};

/// The open flume's inlet: occupied spots and parked slots (`Engine::inlet_scan`).
pub const INLET_SCAN: StageSpec = StageSpec {
    name: "inlet_scan",
    shader: "stages/inlet_scan.wgsl",
    imports: &["common/params.wgsl"],
    bindings: &[
        ("params", 0, Uniform),
        ("query", 1, Uniform),
        ("positions", 2, Read),
        ("ids", 3, Read),
        ("spots", 4, Read),
        ("occupied", 5, ReadWrite),
        ("parked_bits", 6, ReadWrite),
        ("slot_of", 7, ReadWrite),
        ("picks", 8, ReadWrite),
    ],
    entry_points: &["inlet_mark", "inlet_pick"],
    workgroup: 128,
};

/// Every stage, for validation.
pub const ALL: &[&StageSpec] = &[
    &GRID_CLEAR,
    &GRID_COUNT,
    &PREFIX_SUM,
    &GRID_SCATTER,
    &CELL_SORT,
    &ACTIVE_DISPATCH,
    &REORDER,
    &PARKED_COPY,
    &INTERACTION,
    &RHEOLOGY,
    &HOLD,
    &DT_UPDATE,
    &SYMPLECTIC_PREDICTOR,
    &SYMPLECTIC_CORRECTOR,
    &VERLET_UPDATE,
    &PROBE_INTERPOLATE,
    &OBSERVE_REDUCE,
    &INLET_SCAN,
];
