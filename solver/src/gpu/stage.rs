//! The shape every compute stage shares: a composed shader, an explicit bind-group layout
//! built from a declared list of bindings, and a pipeline per entry point.

use super::shader::compose;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    Uniform,
    Read,
    ReadWrite,
    /// A `texture_2d<f32>` of rgba32float particle data, read with `textureLoad`.
    Texture,
    /// A `texture_storage_2d<rgba32float, write>`.
    TextureWrite,
}

/// Something a bind group entry can hold: a buffer or a texture view.
pub trait AsBinding {
    fn resource(&self) -> wgpu::BindingResource<'_>;
}

impl AsBinding for wgpu::Buffer {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        self.as_entire_binding()
    }
}

impl AsBinding for wgpu::TextureView {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::TextureView(self)
    }
}

/// One binding of a stage: the WGSL global's name, its index in group 0 and its access.
pub type Binding = (&'static str, u32, Access);

/// What a stage declares about itself; `shaders_validate` checks it against the WGSL.
pub struct StageSpec {
    pub name: &'static str,
    pub shader: &'static str,
    pub imports: &'static [&'static str],
    pub bindings: &'static [Binding],
    pub entry_points: &'static [&'static str],
    /// Invocations per workgroup, as in the WGSL `@workgroup_size`.
    pub workgroup: u32,
}

impl StageSpec {
    pub fn source(&self) -> String {
        compose(self.imports, self.shader)
    }
}

pub struct Stage {
    pub spec: &'static StageSpec,
    layout: wgpu::BindGroupLayout,
    pipelines: Vec<wgpu::ComputePipeline>,
}

impl Stage {
    /// Compiles every entry point of the stage with the given override constants.
    pub fn new(
        device: &wgpu::Device,
        spec: &'static StageSpec,
        constants: &[(&str, f64)],
    ) -> Stage {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(spec.name),
            source: wgpu::ShaderSource::Wgsl(spec.source().into()),
        });
        let entries: Vec<wgpu::BindGroupLayoutEntry> = spec
            .bindings
            .iter()
            .map(|(_, index, access)| wgpu::BindGroupLayoutEntry {
                binding: *index,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: binding_type(*access),
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(spec.name),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(spec.name),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipelines = spec
            .entry_points
            .iter()
            .map(|entry| {
                // Only the constants this module declares may be passed to it.
                let declared: Vec<(&str, f64)> = constants
                    .iter()
                    .filter(|(name, _)| declares_override(&spec.source(), name))
                    .copied()
                    .collect();
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&pipeline_layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: wgpu::PipelineCompilationOptions {
                        constants: &declared,
                        zero_initialize_workgroup_memory: true,
                    },
                    cache: None,
                })
            })
            .collect();
        Stage {
            spec,
            layout,
            pipelines,
        }
    }

    /// Builds a bind group; `buffers` are given in the order of the stage's declared bindings.
    pub fn bind(&self, device: &wgpu::Device, buffers: &[&dyn AsBinding]) -> wgpu::BindGroup {
        assert_eq!(
            buffers.len(),
            self.spec.bindings.len(),
            "stage {} takes {} buffers",
            self.spec.name,
            self.spec.bindings.len()
        );
        let entries: Vec<wgpu::BindGroupEntry> = self
            .spec
            .bindings
            .iter()
            .zip(buffers)
            .map(|((_, index, _), buffer)| wgpu::BindGroupEntry {
                binding: *index,
                resource: buffer.resource(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.spec.name),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Records one dispatch of entry point `entry` over `items` invocations, in workgroups of
    /// the stage's declared size.
    pub fn record_items(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        entry: usize,
        bind: &wgpu::BindGroup,
        items: u32,
    ) {
        self.record(pass, entry, bind, groups(items, self.spec.workgroup));
    }

    /// Records one dispatch of entry point `entry` (index into `entry_points`) over `groups`.
    pub fn record(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        entry: usize,
        bind: &wgpu::BindGroup,
        groups: u32,
    ) {
        if groups == 0 {
            return;
        }
        pass.set_pipeline(&self.pipelines[entry]);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(groups, 1, 1);
    }

    /// Records one dispatch of entry point `entry` whose workgroup counts a stage wrote into
    /// `args` at byte `offset` (three u32: x, y, z).
    pub fn record_indirect(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        entry: usize,
        bind: &wgpu::BindGroup,
        args: &wgpu::Buffer,
        offset: u64,
    ) {
        pass.set_pipeline(&self.pipelines[entry]);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups_indirect(args, offset);
    }
}

fn binding_type(access: Access) -> wgpu::BindingType {
    let buffer = |ty| wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    match access {
        Access::Uniform => buffer(wgpu::BufferBindingType::Uniform),
        Access::Read => buffer(wgpu::BufferBindingType::Storage { read_only: true }),
        Access::ReadWrite => buffer(wgpu::BufferBindingType::Storage { read_only: false }),
        Access::Texture => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        Access::TextureWrite => wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::Rgba32Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        },
    }
}

fn declares_override(source: &str, name: &str) -> bool {
    source
        .lines()
        .any(|l| l.trim_start().starts_with("override ") && l.contains(&format!("override {name}")))
}

/// Workgroups needed to cover `n` items with `size` invocations each.
pub fn groups(n: u32, size: u32) -> u32 {
    n.div_ceil(size)
}
