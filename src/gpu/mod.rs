//! wgpu drawing inside the viewer's egui window: the control-net overlay.
//! Built with the `viewer` feature; it depends on egui-wgpu, never on the viewer itself.

pub mod wireframe;
