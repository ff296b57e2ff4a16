// The renderers, one line each: the variant of `RendererKind`, its name in scene files and on
// the command line, its label and tooltip in the viewer, whether it renders passes without end
// (`progressive`) or one frame per epoch (`single`), and its integrator: a file in
// src/render/integrator/ and the type there that implements `Integrator`.
//
// This list is read twice: by src/settings/renderer.rs, which makes `RendererKind` from the
// first five columns, and by src/render/integrator/mod.rs (beside it), which declares the
// modules and makes each kind's integrator. A new renderer is its file plus one line here.
renderers! {
    Whitted, "whitted", "Ray tracer", "Whitted ray tracer: one fast frame, direct light, mirrors and glass only", single, ray_tracer::RayTracer;
    Ppm, "ppm", "Photon mapping", "Progressive photon mapping: converges to caustics and indirect light", progressive, photon_mapping::PhotonMapping;
    Path, "path", "Path tracer", "Unidirectional path tracer with light sampling and MIS: an unbiased cross-check of photon mapping", progressive, path::PathTracer;
}
