//! What a pipeline drawn inside egui's render pass must match: the pass's colour format, its
//! depth attachment (if any) and its sample count; and the uniform buffer each callback
//! writes once a frame. Shared by the image's and the overlay's pipelines.

use eframe::egui_wgpu::wgpu;

/// egui's render pass, as a pipeline drawing into it sees it.
pub struct Target {
    /// The colour attachment's format.
    pub format: wgpu::TextureFormat,
    /// The depth attachment's format: eframe with `NativeOptions::depth_buffer` set has one,
    /// egui_kittest's pass has none.
    pub depth_format: Option<wgpu::TextureFormat>,
    /// Samples per pixel.
    pub msaa_samples: u32,
}

impl Target {
    /// Depth state for a pipeline that is never depth tested and writes no depth, where the
    /// pass has a depth attachment.
    pub fn depth_stencil(&self) -> Option<wgpu::DepthStencilState> {
        self.depth_format.map(|format| wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: Default::default(),
            bias: Default::default(),
        })
    }

    /// The pass's sample count.
    pub fn multisample(&self) -> wgpu::MultisampleState {
        wgpu::MultisampleState {
            count: self.msaa_samples.max(1),
            ..Default::default()
        }
    }

    /// The colour attachment, written with `blend` (`None`: opaque).
    pub fn color(&self, blend: Option<wgpu::BlendState>) -> wgpu::ColorTargetState {
        wgpu::ColorTargetState {
            format: self.format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        }
    }
}

/// A uniform buffer of `size` bytes that the queue writes.
pub fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
