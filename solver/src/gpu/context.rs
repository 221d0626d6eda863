//! The wgpu adapter, device and queue the solver runs on.
//!
//! The best adapter available is taken (a discrete or integrated GPU before a software one),
//! unless `FLUME_TWIN_ADAPTER` names one: any adapter whose name contains that text
//! (case-insensitive) is preferred. Without any adapter the error says how to get lavapipe.

use std::fmt;

pub const ADAPTER_ENV: &str = "FLUME_TWIN_ADAPTER";

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (wgpu saw none on Vulkan, GL or Metal). On Debian/Ubuntu install \
         the software Vulkan driver: `sudo apt-get install mesa-vulkan-drivers`"
    )]
    NoAdapter,
    #[error("no adapter matches {ADAPTER_ENV}={wanted:?}; available: {available}")]
    NoMatchingAdapter { wanted: String, available: String },
    #[error("adapter {adapter} refused to open a device: {reason}")]
    Device { adapter: String, reason: String },
    #[error(
        "the case needs {needed_mib:.1} MiB in GPU buffer `{buffer}` but adapter {adapter} allows \
         {limit_mib:.1} MiB per storage buffer; use a coarser dp or a smaller domain"
    )]
    TooLarge {
        buffer: String,
        needed_mib: f64,
        limit_mib: f64,
        adapter: String,
    },
    #[error("GPU readback failed: {0}")]
    Readback(String),
}

/// A summary of the adapter, printed at start and reported by `bench`.
#[derive(Debug, Clone)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}, {}, {})",
            self.name, self.backend, self.device_type, self.driver
        )
    }
}

pub struct GpuContext {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub adapter: AdapterSummary,
    pub limits: wgpu::Limits,
}

fn rank(info: &wgpu::AdapterInfo) -> u32 {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    // Vulkan before GL: lavapipe's Vulkan is much faster than llvmpipe's GL for compute.
    let backend = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        _ => 1,
    };
    kind * 2 + backend
}

impl GpuContext {
    /// Opens the adapter chosen by `FLUME_TWIN_ADAPTER`, or the best one.
    pub fn new() -> Result<GpuContext, GpuError> {
        let wanted = std::env::var(ADAPTER_ENV).ok().filter(|s| !s.is_empty());
        Self::with_adapter(wanted.as_deref())
    }

    pub fn with_adapter(wanted: Option<&str>) -> Result<GpuContext, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        adapters.retain(|a| {
            a.get_downlevel_capabilities()
                .flags
                .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
        });
        if adapters.is_empty() {
            return Err(GpuError::NoAdapter);
        }
        adapters.sort_by_key(|a| rank(&a.get_info()));
        let adapter = match wanted {
            None => adapters.swap_remove(0),
            Some(w) => {
                let needle = w.to_lowercase();
                match adapters
                    .iter()
                    .position(|a| a.get_info().name.to_lowercase().contains(&needle))
                {
                    Some(i) => adapters.swap_remove(i),
                    None => {
                        let available = adapters
                            .iter()
                            .map(|a| {
                                let i = a.get_info();
                                format!("{} ({:?})", i.name, i.backend)
                            })
                            .collect::<Vec<_>>()
                            .join(", ");
                        return Err(GpuError::NoMatchingAdapter {
                            wanted: w.to_string(),
                            available,
                        });
                    }
                }
            }
        };
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info)
                .trim()
                .to_string(),
        };
        // Ask for everything the adapter offers: buffer sizes are the binding constraint.
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("flume-solver"),
            required_features: wgpu::Features::empty(),
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device {
            adapter: summary.name.clone(),
            reason: e.to_string(),
        })?;
        Ok(GpuContext {
            device,
            queue,
            adapter: summary,
            limits,
        })
    }

    /// Whether the adapter is a software rasteriser on the CPU (lavapipe, llvmpipe).
    pub fn is_software(&self) -> bool {
        self.adapter.device_type == format!("{:?}", wgpu::DeviceType::Cpu)
    }

    /// Fails with `TooLarge` if a storage buffer of `bytes` would exceed the adapter's limits.
    pub fn check_storage_size(&self, buffer: &str, bytes: u64) -> Result<(), GpuError> {
        let limit = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        if bytes > limit {
            return Err(GpuError::TooLarge {
                buffer: buffer.to_string(),
                needed_mib: bytes as f64 / 1048576.0,
                limit_mib: limit as f64 / 1048576.0,
                adapter: self.adapter.name.clone(),
            });
        }
        Ok(())
    }
}
