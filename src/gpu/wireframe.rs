//! The control-net overlay drawn with wgpu inside an egui paint callback, after egui's
//! `custom3d_wgpu` demo: the pipelines, the uniform buffer and its bind group are created
//! once by [`install`] and kept in egui-wgpu's `callback_resources`; each frame's
//! [`WireframeCallback`] carries the projection and the view's size, plus a shared handle on
//! the overlay's geometry that is uploaded again only when its `generation` changes.
//!
//! Segments and point markers are instanced screen-space quads (`shaders/wireframe.wgsl`),
//! so they keep their width in points on every backend. Nothing here knows the viewer: it
//! draws what [`WireframeGeometry`] holds with the matrix it is given.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use eframe::egui_wgpu::{self, wgpu};

use super::target::{uniform_buffer, Target};

/// The overlay's shader, validated by a naga test.
pub const SHADER: &str = include_str!("../../shaders/wireframe.wgsl");

/// One segment of the overlay: world-space end points, straight RGBA colour, width in points.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Segment {
    /// First end point (world space).
    pub a: [f32; 3],
    /// Second end point (world space).
    pub b: [f32; 3],
    /// Straight (not premultiplied) RGBA in 0..1.
    pub color: [f32; 4],
    /// Width in points.
    pub width: f32,
}

/// One square point marker: world-space centre, straight RGBA colour, size in points.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Marker {
    /// Centre (world space).
    pub position: [f32; 3],
    /// Straight (not premultiplied) RGBA in 0..1.
    pub color: [f32; 4],
    /// Side length in points.
    pub size: f32,
}

/// What the overlay draws.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WireframeGeometry {
    /// Lines of the control nets and boundary curves.
    pub segments: Vec<Segment>,
    /// Control points.
    pub markers: Vec<Marker>,
}

/// The uniform block of `wireframe.wgsl`, laid out to WGSL's rules (a `mat4x4<f32>` then a
/// `vec2<f32>` and two `f32`: 80 bytes, 16-byte aligned, no implicit padding).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Uniforms {
    /// Column-major clip-from-world matrix (glam's `to_cols_array_2d`).
    pub clip_from_world: [[f32; 4]; 4],
    /// The view's size in physical pixels.
    pub viewport_px: [f32; 2],
    /// Clip-space `w` below which geometry counts as behind the eye.
    pub near_w: f32,
    /// Physical pixels per point.
    pub pixels_per_point: f32,
}

/// GPU objects made once per renderer and kept in `callback_resources`.
pub struct WireframeResources {
    segment_pipeline: wgpu::RenderPipeline,
    marker_pipeline: wgpu::RenderPipeline,
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    segments: Option<wgpu::Buffer>,
    markers: Option<wgpu::Buffer>,
    segment_count: u32,
    marker_count: u32,
    /// The geometry generation last uploaded.
    generation: Option<u64>,
}

/// Creates the overlay's pipelines for `render_state`'s target and stores them in its
/// callback resources. `depth_format` must match the render pass egui draws into (eframe with
/// `NativeOptions::depth_buffer` set has one; egui_kittest's has none); `msaa_samples` too.
pub fn install(
    render_state: &egui_wgpu::RenderState,
    depth_format: Option<wgpu::TextureFormat>,
    msaa_samples: u32,
) {
    let device = &render_state.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("caustic wireframe shader"),
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let (uniforms, layout, bind_group) = uniform_binding(device);
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("caustic wireframe pipeline layout"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let target = Target {
        format: render_state.target_format,
        depth_format,
        msaa_samples,
    };
    let pipeline = |label: &str, entry: &str, stride: usize, attributes: &[wgpu::VertexAttribute]| {
        let shaders = (&module, &pipeline_layout);
        instanced_pipeline(device, shaders, &target, (label, entry), (stride, attributes))
    };
    let segment_pipeline = pipeline(
        "caustic wireframe segments",
        "vs_segment",
        std::mem::size_of::<Segment>(),
        &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32],
    );
    let marker_pipeline = pipeline(
        "caustic wireframe markers",
        "vs_marker",
        std::mem::size_of::<Marker>(),
        &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4, 2 => Float32],
    );
    render_state
        .renderer
        .write()
        .callback_resources
        .insert(WireframeResources {
            segment_pipeline,
            marker_pipeline,
            uniforms,
            bind_group,
            segments: None,
            markers: None,
            segment_count: 0,
            marker_count: 0,
            generation: None,
        });
}

/// A pipeline drawing one screen-space quad per instance (a segment or a marker) with the
/// vertex entry point `entry`, premultiplied-alpha blended, never depth tested.
fn instanced_pipeline(
    device: &wgpu::Device,
    (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
    target: &Target,
    (label, entry): (&str, &str),
    (stride, attributes): (usize, &[wgpu::VertexAttribute]),
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: stride as u64,
                step_mode: wgpu::VertexStepMode::Instance,
                attributes,
            })],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: target.depth_stencil(),
        multisample: target.multisample(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(
                target.color(Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING)),
            )],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// The uniform buffer, its bind group layout and its bind group.
fn uniform_binding(device: &wgpu::Device) -> (wgpu::Buffer, wgpu::BindGroupLayout, wgpu::BindGroup) {
    let uniforms = uniform_buffer(
        device,
        "caustic wireframe uniforms",
        std::mem::size_of::<Uniforms>(),
    );
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("caustic wireframe bind group layout"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: std::num::NonZeroU64::new(std::mem::size_of::<Uniforms>() as u64),
            },
            count: None,
        }],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("caustic wireframe bind group"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: uniforms.as_entire_binding(),
        }],
    });
    (uniforms, layout, bind_group)
}

/// One frame's overlay: the projection and view size, and the geometry (uploaded only when
/// `generation` differs from the last upload).
pub struct WireframeCallback {
    /// The uniforms for this frame.
    pub uniforms: Uniforms,
    /// What to draw.
    pub geometry: Arc<WireframeGeometry>,
    /// Changes whenever `geometry` does.
    pub generation: u64,
}

/// Writes `data` into `buffer`, replacing it with a larger one when it does not fit.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &mut Option<wgpu::Buffer>,
    label: &str,
    data: &[u8],
) {
    if data.is_empty() {
        return;
    }
    if buffer.as_ref().is_none_or(|b| b.size() < data.len() as u64) {
        *buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (data.len() as u64).next_power_of_two(),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
    }
    if let Some(b) = buffer {
        queue.write_buffer(b, 0, data);
    }
}

impl egui_wgpu::CallbackTrait for WireframeCallback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        // Without `install` (a renderer that never set the overlay up) nothing is drawn.
        let Some(r) = resources.get_mut::<WireframeResources>() else {
            return Vec::new();
        };
        queue.write_buffer(&r.uniforms, 0, bytemuck::bytes_of(&self.uniforms));
        if r.generation != Some(self.generation) {
            let g = &self.geometry;
            upload(
                device,
                queue,
                &mut r.segments,
                "caustic wireframe segment instances",
                bytemuck::cast_slice(&g.segments),
            );
            upload(
                device,
                queue,
                &mut r.markers,
                "caustic wireframe marker instances",
                bytemuck::cast_slice(&g.markers),
            );
            r.segment_count = g.segments.len() as u32;
            r.marker_count = g.markers.len() as u32;
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
        let Some(r) = resources.get::<WireframeResources>() else {
            return;
        };
        pass.set_bind_group(0, &r.bind_group, &[]);
        if let (Some(buffer), n @ 1..) = (&r.segments, r.segment_count) {
            pass.set_pipeline(&r.segment_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..6, 0..n);
        }
        if let (Some(buffer), n @ 1..) = (&r.markers, r.marker_count) {
            pass.set_pipeline(&r.marker_pipeline);
            pass.set_vertex_buffer(0, buffer.slice(..));
            pass.draw(0..6, 0..n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gpu_types_have_the_sizes_the_shader_expects() {
        assert_eq!(std::mem::size_of::<Uniforms>(), 80);
        assert_eq!(std::mem::size_of::<Segment>(), 44);
        assert_eq!(std::mem::size_of::<Marker>(), 32);
    }
}
