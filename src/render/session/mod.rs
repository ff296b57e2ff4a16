//! The render session: photon-mapping passes (or one ray-traced frame) on a
//! thread of their own, steered by [`Command`]s over an unbounded channel and reporting a
//! [`Frame`] after each pass over a `bounded(1)` channel with `try_send` — the renderer never
//! waits for whoever watches; a frame nobody took is simply replaced by a newer one.
//!
//! The render parameters arrive whole ([`Command::SetParams`]). Commands are looked at between
//! photon batches, so a slider takes effect within one batch. α and photons per pass change
//! the coming update/pass without discarding anything; every other parameter, the camera and
//! the geometry restart accumulation under a new `epoch`; pause and resume lose nothing (a
//! paused pass continues where it stopped, so the image is the one an uninterrupted run gives).
//!
//! The rules live in [`SessionState`], free of threads (`apply(Command) -> Effect`, `next`);
//! the thread's loop only carries out what it says. The command line's `render` and `bench`
//! run on this session too (headless, [`SessionOptions::every_frame`]).
//!
//! A panic on the render thread is caught and kept as [`RenderSession::failure`], so a viewer
//! can show it and stay up.

//!
//! Files: [`command`] (the protocol: what may be asked, what restarts, what is valid),
//! [`state`] (the rules), `integrator` (the epoch's renderer as the session drives it: the plan
//! of a pass, the preview) and `thread` (the thread that
//! carries the rules out, and the handle to it).

pub mod command;
mod integrator;
pub mod state;
mod thread;

pub use crate::render::frame::{Frame, FrameStats};
pub use command::Command;
pub use state::{Effect, Next, SessionOptions, SessionState};
pub use thread::{RenderSession, Waker};
