// The rendered image: one opaque textured quad. egui's own image path blends every pixel and
// runs its general shader; a software rasteriser (lavapipe) pays for each covered pixel, and
// this quad covers most of the window, so it gets a pipeline with no blending and a bare fetch.

struct Uniforms {
    // The image's corners in the view's clip space: (left, top, right, bottom).
    rect: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;
@group(0) @binding(1) var image: texture_2d<f32>;
@group(0) @binding(2) var image_sampler: sampler;

struct Out {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> Out {
    // Two triangles over the unit square; uv (0, 0) is the image's top left.
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    let c = corners[vi];
    var out: Out;
    out.position = vec4<f32>(mix(u.rect.xy, u.rect.zw, c), 0.5, 1.0);
    out.uv = c;
    return out;
}

@fragment
fn fs_main(in: Out) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSample(image, image_sampler, in.uv).rgb, 1.0);
}
