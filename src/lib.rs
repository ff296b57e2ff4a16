//! # caustic
//!
//! Exact ray tracing of bicubic Bézier patches and progressive photon mapping, with a live
//! viewer. This crate is the render core: it never depends on the GUI.
//!
//! * [`geometry`]: rays, bounds, Bézier patch maths, exact ray/patch intersection (prepared
//!   sub-patches + Newton, and the seed's per-ray subdivision as a reference), spheres, quads,
//!   planes, triangle meshes and the SAH BVH holding them.
//! * [`settings`]: the render settings and their ranges, below both scene and render;
//!   [`color`]: the sRGB transfer pair.
//! * [`scene`]: the TOML scene format, validation, camera, materials, textures, lights.
//! * [`render`]: the Whitted ray tracer, the film and its PNG/EXR output, random streams.
//! * [`assets`]: the data the binary carries built in (Newell's teapot).
//! * [`mod@bench`]: every benchmark of `caustic bench`, and the harnesses `view --bench`
//!   shares with them; [`run`]: a scene from a file or built in, a render session followed
//!   to its end, a progress bar; [`args`]: flag groups the commands share.
//! * [`farm`]: the Slurm script and Kubernetes manifest of a sharded render, every value
//!   quoted by one function.
//! * [`tev`]: streaming frames to a running tev viewer.
//! * `app` and `gpu` (feature `viewer`, on by default): the eframe viewer and the wgpu
//!   control-net overlay it draws; the render core does not depend on them.
//!
//! README.md describes the program and where each part lives; module docs name the paper or
//! source of every algorithm they implement.

#![forbid(unsafe_code)]

#[cfg(feature = "viewer")]
pub mod app;
pub mod args;
pub mod assets;
pub mod bench;
pub mod color;
pub mod design;
pub mod farm;
pub mod files;
pub mod geometry;
#[cfg(feature = "viewer")]
pub mod gpu;
pub mod input_file;
pub mod render;
pub mod run;
pub mod scene;
pub mod settings;
pub mod tev;
