//! Designing a caustic: moving a surface's control points until the light it sends draws a
//! target. Today: the derivative of where photons land with respect to the control points
//! ([`landing`]), in forward mode with sparse gradients ([`dual`]).

pub mod dual;
pub mod landing;
