//! Deterministic random streams: every random number derives from (seed, stream, index) — a
//! pixel, a photon, a pass — so a render is identical for any thread count.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The generator for item `index` of `stream` under `seed`.
pub fn stream_rng(seed: u64, stream: u64, index: u64) -> Pcg64Mcg {
    let key = mix64(seed ^ mix64(stream.wrapping_add(0x9e37_79b9_7f4a_7c15) ^ mix64(index)));
    Pcg64Mcg::seed_from_u64(key)
}

/// Named streams, so different uses of one pixel never share numbers.
pub mod streams {
    /// Ray tracer: lens and pixel samples.
    pub const WHITTED_PIXEL: u64 = 1;
    /// Ray tracer: area-light shadow samples of the edge pass.
    pub const WHITTED_EDGE: u64 = 2;
}
