//! The random stream ids of photon mapping: every random number of a render comes from a
//! stream `(seed, id, index)` ([`crate::render::rng::stream_rng`]), so that what a photon or a
//! pixel draws depends on its own number alone, not on the thread that traces it.

/// Eye rays: `(pass · pixels + pixel)`.
pub const EYE: u64 = 10;
/// Photons: the photon's number in the render.
pub const PHOTON: u64 = 11;
/// Each pixel's fixed offsets of its eye-ray sequences (12 is the area lights' offsets, in
/// [`super::direct`]).
pub const EYE_OFFSETS: u64 = 13;
/// The extra eye rays of pixels whose light seen is supersampled ([`super::seen`]).
pub const SEEN: u64 = 14;
/// Each such pixel's fixed offsets of its extra rays' sequences.
pub const SEEN_OFFSETS: u64 = 15;
/// The digital shift of stratified photons' sequence.
pub const PHOTON_SHIFT: u64 = 16;
