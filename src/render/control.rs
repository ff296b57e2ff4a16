//! How a render in progress is steered from outside: between batches of work a renderer asks
//! its caller whether to go on ([`Control`]), and deep inside a batch it polls an
//! [`Interrupt`] that a waiting restart sets.

use std::sync::Arc;

/// What the caller wants between two batches of a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Drop this pass.
    Abort,
}

/// Asked often during a pass (from any thread); returning true abandons the pass. The render
/// session sets one that turns true when a restart is waiting.
pub type Interrupt = Arc<dyn Fn() -> bool + Send + Sync>;
