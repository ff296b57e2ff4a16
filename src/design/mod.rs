//! Designing a caustic: moving a surface's control points until the light it sends draws a
//! target image on a receiver (`caustic design`). The photons ([`photons`]) are traced with
//! the derivative of where they land with respect to the control points ([`landing`], in
//! forward mode with sparse gradients, [`dual`]), and the loss against the target
//! ([`target`]) is descended by Adam ([`optimize`]), on a surface split finer first
//! ([`refine`]).

pub mod dual;
pub mod landing;
pub mod optimize;
pub mod photons;
pub mod refine;
pub mod setup;
pub mod target;
