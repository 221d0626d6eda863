//! Buffer creation and readback.

use super::context::{GpuContext, GpuError};
use wgpu::util::DeviceExt;

pub fn storage(gpu: &GpuContext, label: &str, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A storage buffer a stage writes indirect dispatch arguments into.
pub fn indirect(gpu: &GpuContext, label: &str, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
        mapped_at_creation: false,
    })
}

pub fn storage_init<T: bytemuck::Pod>(gpu: &GpuContext, label: &str, data: &[T]) -> wgpu::Buffer {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    if bytes.len() < 16 {
        let mut padded = bytes.to_vec();
        padded.resize(16, 0);
        return init(gpu, label, &padded, wgpu::BufferUsages::STORAGE);
    }
    init(gpu, label, bytes, wgpu::BufferUsages::STORAGE)
}

pub fn uniform_init<T: bytemuck::Pod>(gpu: &GpuContext, label: &str, value: &T) -> wgpu::Buffer {
    init(
        gpu,
        label,
        bytemuck::bytes_of(value),
        wgpu::BufferUsages::UNIFORM,
    )
}

fn init(gpu: &GpuContext, label: &str, bytes: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: usage | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        })
}

/// An rgba32float texture of one texel per particle, rows of `1 << row_shift` texels, that
/// stages write as storage and neighbour loops read with `textureLoad`.
pub fn particle_texture(
    gpu: &GpuContext,
    label: &str,
    n: u64,
    row_shift: u32,
) -> wgpu::TextureView {
    let width = 1u32 << row_shift;
    let height = (n.div_ceil(u64::from(width)) as u32).max(1);
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        })
        .create_view(&wgpu::TextureViewDescriptor::default())
}

/// Copies `bytes` from the start of each buffer and waits for the result; one submission.
pub fn read_buffers(
    gpu: &GpuContext,
    sources: &[(&wgpu::Buffer, u64)],
) -> Result<Vec<Vec<u8>>, GpuError> {
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("readback"),
        });
    let staging: Vec<wgpu::Buffer> = sources
        .iter()
        .map(|(src, bytes)| {
            let size = bytes.div_ceil(4) * 4;
            let dst = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("readback staging"),
                size: size.max(4),
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            if size > 0 {
                encoder.copy_buffer_to_buffer(src, 0, &dst, 0, size);
            }
            dst
        })
        .collect();
    gpu.queue.submit([encoder.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    for (k, buf) in staging.iter().enumerate() {
        let tx = tx.clone();
        buf.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send((k, r));
        });
    }
    drop(tx);
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    for (_, r) in rx.iter() {
        r.map_err(|e| GpuError::Readback(e.to_string()))?;
    }
    let mut out = Vec::with_capacity(sources.len());
    for (buf, (_, bytes)) in staging.iter().zip(sources) {
        let view = buf
            .get_mapped_range(..)
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        out.push(view[..*bytes as usize].to_vec());
        drop(view);
        buf.unmap();
    }
    Ok(out)
}

/// Reinterprets readback bytes (which may be unaligned) as a vector of `T`.
pub fn cast_vec<T: bytemuck::Pod>(bytes: &[u8]) -> Vec<T> {
    bytemuck::pod_collect_to_vec(bytes)
}
