//! How a pass's parallel sweeps over pixels, slots and visible points divide their items.

/// Items (pixels, slots, visible points) a task of a pass's parallel sweeps over them takes:
/// large enough that handing out the tasks, or a frame's block finding its first slot
/// ([`super::layers`]), costs nothing beside them (with one thread a sweep is as fast as a
/// plain loop), small enough that two threads share a 320×240 image evenly.
pub const SWEEP_BLOCK: usize = 4096;
