//! wgpu drawing inside the viewer's egui window: the rendered image and the control-net overlay.
//! Built with the `viewer` feature; it depends on egui-wgpu, never on the viewer itself.

pub mod image_quad;
pub mod target;
pub mod wireframe;
