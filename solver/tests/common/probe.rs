//! A harness that runs a WGSL function over a grid of inputs on the adapter (lavapipe in CI),
//! for comparison with its Rust twin (`tests/wgsl_functions.rs`, `tests/wgsl_store.rs`).

use super::{gpu, reference_params, reference_sediment};
use flume_solver::contract::SimParams;
use flume_solver::gpu::{buffers, shader};
use flume_solver::physics::Params;
use flume_solver::physics::sediment::pass::SedimentModel;
use flume_solver::{Backend, Case, GpuContext, Simulation};

/// One invocation's inputs, `a` and `b` in the probe.
pub type Input = [[f32; 4]; 2];

pub const SHARED: &[&str] = &[
    "common/params.wgsl",
    "common/kernel.wgsl",
    "common/eos.wgsl",
    "common/step_state.wgsl",
    "common/sediment.wgsl",
];

/// The Louvain dam break (Drucker-Prager with Shields, HBP m = 100, n = 1.2) at dp = 1 cm, its
/// sand picked up at van Rijn's rate (the case releases it at once, which leaves the rate 0):
/// its uniform block, and the physics the oracle reads from the case file.
pub struct Probe {
    pub gpu: std::sync::Arc<GpuContext>,
    pub uniform: SimParams,
    pub params: Params,
    pub model: SedimentModel,
}

pub fn probe() -> Option<Probe> {
    let mut case = Case::from_path(&super::case_path("../launch_configs/louvain_dambreak.yaml"))
        .expect("case parses");
    case.numerics.dp_m = 0.01;
    for phase in &mut case.phases {
        if let Some(sediment) = &mut phase.sediment {
            sediment.erosion = flume_solver::config::Erosion::VanRijnPickup;
        }
    }
    probe_of(&case)
}

/// The probe of `case`: its uniform block, and the physics the oracle reads from it.
pub fn probe_of(case: &Case) -> Option<Probe> {
    let gpu = gpu()?;
    let sim = Simulation::new(Backend::cpu(1), case).expect("the case runs");
    Some(Probe {
        gpu,
        uniform: *sim.params(),
        params: reference_params(&sim),
        model: reference_sediment(&sim),
    })
}

impl Probe {
    /// `body`, a WGSL expression of the invocation's inputs `a` and `b` giving a `vec4<f32>`,
    /// evaluated for each input after the shared modules.
    pub fn run(&self, body: &str, inputs: &[Input]) -> Vec<[f32; 4]> {
        self.run_with("", body, inputs)
    }

    /// [`Probe::run`] with WGSL `helpers` composed before the probe.
    pub fn run_with(&self, helpers: &str, body: &str, inputs: &[Input]) -> Vec<[f32; 4]> {
        let mut source = String::new();
        for path in SHARED {
            source.push_str(shader::source(path));
            source.push('\n');
        }
        source.push_str(helpers);
        source.push_str(&format!(
            "@group(0) @binding(100) var<storage, read> probe_in: array<vec4<f32>>;
@group(0) @binding(101) var<storage, read_write> probe_out: array<vec4<f32>>;
@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) gid: vec3<u32>) {{
    // Every probe binds the uniform, whether its function reads it or not.
    _ = params.h;
    let i = gid.x;
    if (i >= arrayLength(&probe_out)) {{
        return;
    }}
    let a = probe_in[2u * i];
    let b = probe_in[2u * i + 1u];
    probe_out[i] = {body};
}}
"
        ));
        let device = &self.gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("probe"),
            layout: None,
            module: &module,
            entry_point: Some("probe"),
            compilation_options: Default::default(),
            cache: None,
        });
        let flat: Vec<[f32; 4]> = inputs.iter().flatten().copied().collect();
        let uniform = buffers::uniform_init(&self.gpu, "params", &self.uniform);
        let input = buffers::storage_init(&self.gpu, "probe_in", &flat);
        let bytes = (inputs.len() * 16) as u64;
        let output = buffers::storage(&self.gpu, "probe_out", bytes);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 100,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 101,
                    resource: output.as_entire_binding(),
                },
            ],
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((inputs.len() as u32).div_ceil(64), 1, 1);
        }
        self.gpu.queue.submit([encoder.finish()]);
        let read = buffers::read_buffers(&self.gpu, &[(&output, bytes)]).expect("readback");
        buffers::cast_vec(&read[0])
    }

    /// Runs `body` over `inputs` and asserts its first `n` components against `rust`'s.
    pub fn agree(
        &self,
        what: &str,
        body: &str,
        inputs: &[Input],
        n: usize,
        rust: impl Fn(&Input) -> [f32; 4],
    ) {
        self.agree_within(what, body, inputs, n, 0.0, rust);
    }

    /// [`Probe::agree`], with `abs` more absolute difference allowed.
    pub fn agree_within(
        &self,
        what: &str,
        body: &str,
        inputs: &[Input],
        n: usize,
        abs: f32,
        rust: impl Fn(&Input) -> [f32; 4],
    ) {
        let gpu = self.run(body, inputs);
        for (input, got) in inputs.iter().zip(&gpu) {
            let want = rust(input);
            for k in 0..n {
                assert!(
                    same(got[k], want[k], abs),
                    "{what} at {input:?}: WGSL {} against Rust {} (component {k})",
                    got[k],
                    want[k]
                );
            }
        }
    }
}

/// The most a Vulkan implementation's f32 division may be off, relatively: 2.5 ulp for a divisor
/// of normal size (Vulkan specification, appendix A, precision of `OpFDiv`), an ulp being at most
/// 2^-23 of the value. lavapipe divides exactly; NVIDIA's driver (580) does not.
pub const VULKAN_DIVISION: f32 = 2.5 * f32::EPSILON;

/// Within 2e-6 relatively (16 ulp) and `abs` absolutely; the WGSL's HUGE stands for
/// infinity.
pub fn same(gpu: f32, rust: f32, abs: f32) -> bool {
    const HUGE: f32 = 1e37;
    if gpu >= HUGE || rust >= HUGE {
        return gpu >= HUGE && rust >= HUGE;
    }
    (gpu - rust).abs() <= 2e-6 * rust.abs().max(gpu.abs()) + abs.max(1e-30)
}
