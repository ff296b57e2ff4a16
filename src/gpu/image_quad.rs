//! The rendered image drawn with wgpu inside an egui paint callback, as one opaque quad
//! (`shaders/image.wgsl`). egui's own image path runs its general shader with alpha blending on
//! every covered pixel; under a software rasteriser (lavapipe) that cost as much as the rest of
//! the window together (`caustic view --bench`, teapot, renderer paused: 23 fps with it, 33
//! without). The pipeline, sampler and uniform buffer are made once by [`install`] and kept in
//! egui-wgpu's `callback_resources`; each frame's [`ImageCallback`] carries where the image
//! lies in the view and a shared handle on its pixels, written to the texture only when their
//! `generation` changes.
//!
//! Filtering follows the egui path it replaces: linear when the image is shrunk, nearest when
//! it is magnified (zoomed-in pixels stay crisp for the probe).

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use eframe::egui_wgpu::{self, wgpu};

use super::target::{uniform_buffer, Target};

/// The image's shader, validated by a naga test.
pub const SHADER: &str = include_str!("../../shaders/image.wgsl");

/// The uniform block of `image.wgsl`: the image's corners in the view's clip space.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ImageUniforms {
    /// Left, top, right, bottom, in clip space (x right, y up, -1..1 across the view).
    pub rect: [f32; 4],
}

impl ImageUniforms {
    /// The uniforms of an image occupying `image` in a view `view` (both in the same units,
    /// y down, as egui's rectangles).
    pub fn new(image: egui::Rect, view: egui::Rect) -> Self {
        let x = |v: f32| 2.0 * (v - view.min.x) / view.width().max(f32::MIN_POSITIVE) - 1.0;
        let y = |v: f32| 1.0 - 2.0 * (v - view.min.y) / view.height().max(f32::MIN_POSITIVE);
        Self {
            rect: [x(image.min.x), y(image.min.y), x(image.max.x), y(image.max.y)],
        }
    }
}

/// An image's pixels: 8-bit sRGB RGBA rows, top first.
#[derive(Clone, Debug, PartialEq)]
pub struct ImagePixels {
    /// Width and height in pixels.
    pub size: [u32; 2],
    /// `4 · width · height` bytes.
    pub rgba: Vec<u8>,
}

/// The texture of the image last written, with the bind group that samples it.
struct Texture {
    texture: wgpu::Texture,
    bind_group: wgpu::BindGroup,
    size: [u32; 2],
}

/// GPU objects made once per renderer and kept in `callback_resources`.
pub struct ImageResources {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    uniforms: wgpu::Buffer,
    /// The texture's format: sRGB when the target is, so the bytes come out as they went in.
    format: wgpu::TextureFormat,
    texture: Option<Texture>,
    /// The pixels' generation last written.
    generation: Option<u64>,
}

/// Creates the image's pipeline for `render_state`'s target and stores it in its callback
/// resources. `depth_format` and `msaa_samples` must match the render pass egui draws into.
pub fn install(
    render_state: &egui_wgpu::RenderState,
    depth_format: Option<wgpu::TextureFormat>,
    msaa_samples: u32,
) {
    let device = &render_state.device;
    let target = Target {
        format: render_state.target_format,
        depth_format,
        msaa_samples,
    };
    let layout = bind_group_layout(device);
    let pipeline = pipeline(device, &layout, &target);
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("caustic image sampler"),
        mag_filter: wgpu::FilterMode::Nearest,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let uniforms = uniform_buffer(
        device,
        "caustic image uniforms",
        std::mem::size_of::<ImageUniforms>(),
    );
    let format = if target.format.is_srgb() {
        wgpu::TextureFormat::Rgba8UnormSrgb
    } else {
        wgpu::TextureFormat::Rgba8Unorm
    };
    render_state
        .renderer
        .write()
        .callback_resources
        .insert(ImageResources {
            pipeline,
            layout,
            sampler,
            uniforms,
            format,
            texture: None,
            generation: None,
        });
}

/// The bind group layout: the uniforms (vertex), the texture and its sampler (fragment).
fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("caustic image bind group layout"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: std::num::NonZeroU64::new(std::mem::size_of::<ImageUniforms>() as u64),
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    })
}

/// The opaque pipeline: no blending, never depth tested.
fn pipeline(device: &wgpu::Device, layout: &wgpu::BindGroupLayout, target: &Target) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("caustic image shader"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("caustic image pipeline layout"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("caustic image"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: target.depth_stencil(),
        multisample: target.multisample(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(target.color(None))],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl ImageResources {
    /// Writes `pixels` into the texture, making a new one (and its bind group) when the size
    /// changed.
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, pixels: &ImagePixels) {
        let [width, height] = pixels.size;
        if width == 0 || height == 0 || pixels.rgba.len() != 4 * width as usize * height as usize {
            self.texture = None;
            return;
        }
        if self.texture.as_ref().is_none_or(|t| t.size != pixels.size) {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("caustic image"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("caustic image bind group"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.uniforms.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            self.texture = Some(Texture {
                texture,
                bind_group,
                size: pixels.size,
            });
        }
        if let Some(t) = &self.texture {
            queue.write_texture(
                t.texture.as_image_copy(),
                &pixels.rgba,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * width),
                    rows_per_image: Some(height),
                },
                wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
            );
        }
    }
}

/// One frame's image: where it lies in the view, and its pixels (written to the texture only
/// when `generation` differs from the last write).
pub struct ImageCallback {
    /// The uniforms for this frame.
    pub uniforms: ImageUniforms,
    /// What to draw.
    pub pixels: Arc<ImagePixels>,
    /// Changes whenever `pixels` does.
    pub generation: u64,
}

impl egui_wgpu::CallbackTrait for ImageCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        // Without `install` nothing is drawn.
        let Some(r) = resources.get_mut::<ImageResources>() else {
            return Vec::new();
        };
        queue.write_buffer(&r.uniforms, 0, bytemuck::bytes_of(&self.uniforms));
        if r.generation != Some(self.generation) {
            r.write(device, queue, &self.pixels);
            r.generation = Some(self.generation);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        let Some(r) = resources.get::<ImageResources>() else {
            return;
        };
        if let Some(t) = &r.texture {
            pass.set_pipeline(&r.pipeline);
            pass.set_bind_group(0, &t.bind_group, &[]);
            pass.draw(0..6, 0..1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_uniforms_place_the_image_in_the_views_clip_space() {
        let view = egui::Rect::from_min_size(egui::pos2(100.0, 50.0), egui::vec2(200.0, 100.0));
        // The whole view.
        assert_eq!(ImageUniforms::new(view, view).rect, [-1.0, 1.0, 1.0, -1.0]);
        // The view's right half, and its bottom half: y is up in clip space.
        let right = egui::Rect::from_min_max(egui::pos2(200.0, 50.0), egui::pos2(300.0, 150.0));
        assert_eq!(ImageUniforms::new(right, view).rect, [0.0, 1.0, 1.0, -1.0]);
        let bottom = egui::Rect::from_min_max(egui::pos2(100.0, 100.0), egui::pos2(300.0, 150.0));
        assert_eq!(ImageUniforms::new(bottom, view).rect, [-1.0, 0.0, 1.0, -1.0]);
    }

    #[test]
    fn the_uniforms_have_the_size_the_shader_expects() {
        assert_eq!(std::mem::size_of::<ImageUniforms>(), 16);
    }
}
