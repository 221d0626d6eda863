//! WGSL sources, embedded in the binary, and their composition.
//!
//! A stage (`shaders/stages/*.wgsl`) lists the import-only modules it needs in its
//! `StageSpec::imports` (`stages.rs`); composition prepends them in the order given. Nothing is substituted
//! inside any source, so each composed module is the plain concatenation of files on disk.

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        &[$(($path, include_str!(concat!("../../../shaders/", $path)))),*]
    };
}

/// Every WGSL file of the solver, by its path under `shaders/`.
pub const SOURCES: &[(&str, &str)] = embed![
    "common/params.wgsl",
    "common/kernel.wgsl",
    "common/eos.wgsl",
    "common/grid.wgsl",
    "common/neighbours.wgsl",
    "common/particle_texture.wgsl",
    "common/step_state.wgsl",
    "common/store_rule.wgsl",
    "common/store_state.wgsl",
    "common/sediment.wgsl",
    "common/chunk_idle.wgsl",
    "common/flume.wgsl",
    "stages/grid_clear.wgsl",
    "stages/grid_count.wgsl",
    "stages/prefix_sum.wgsl",
    "stages/grid_scatter.wgsl",
    "stages/cell_sort.wgsl",
    "stages/active_dispatch.wgsl",
    "stages/reorder.wgsl",
    "stages/parked_copy.wgsl",
    "stages/interaction.wgsl",
    "stages/rheology.wgsl",
    "stages/hold.wgsl",
    "stages/dt_update.wgsl",
    "stages/symplectic_predictor.wgsl",
    "stages/symplectic_corrector.wgsl",
    "stages/verlet_update.wgsl",
    "stages/probe_interpolate.wgsl",
    "stages/observe_reduce.wgsl",
    "stages/inlet_scan.wgsl",
];

pub fn source(path: &str) -> &'static str {
    SOURCES
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .unwrap_or_else(|| panic!("shader {path} is not embedded in gpu::shader::SOURCES"))
}

/// The composed WGSL of a stage: its imports in order, then the stage itself.
pub fn compose(imports: &[&str], stage: &str) -> String {
    let mut out = String::new();
    for path in imports.iter().chain(std::iter::once(&stage)) {
        out.push_str("// ---- ");
        out.push_str(path);
        out.push('\n');
        out.push_str(source(path));
        out.push('\n');
    }
    out
}
