// The control-net overlay: screen-space thick segments and square point markers, both drawn as
// instanced quads (six vertices each) so their width in pixels is the same on every backend
// (line primitives are one pixel wide on most). Geometry is in world space; `clip_from_world`
// is the render camera's projection composed with where the image sits in the view, so the net
// lies on the rendered surfaces and follows zoom and pan.

struct Uniforms {
    clip_from_world: mat4x4<f32>,
    // Size of the view (the callback's viewport) in physical pixels.
    viewport_px: vec2<f32>,
    // Clip-space w below which geometry is behind the eye (a near plane).
    near_w: f32,
    pixels_per_point: f32,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

struct Out {
    @builtin(position) position: vec4<f32>,
    @location(0) color: vec4<f32>,
};

// Corner `i` of a quad made of two triangles: x in {0, 1}, y in {-1, 1}.
fn corner(i: u32) -> vec2<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    return corners[i];
}

// A vertex outside the clip volume (nothing is drawn).
fn culled() -> Out {
    var out: Out;
    out.position = vec4<f32>(0.0, 0.0, 2.0, 1.0);
    out.color = vec4<f32>(0.0);
    return out;
}

// Clip position to pixels from the view centre (y up).
fn to_px(c: vec4<f32>) -> vec2<f32> {
    return c.xy / c.w * 0.5 * u.viewport_px;
}

fn from_px(p: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(p / (0.5 * u.viewport_px), 0.5, 1.0);
}

@vertex
fn vs_segment(
    @builtin(vertex_index) vi: u32,
    @location(0) a: vec3<f32>,
    @location(1) b: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) width_pt: f32,
) -> Out {
    var ca = u.clip_from_world * vec4<f32>(a, 1.0);
    var cb = u.clip_from_world * vec4<f32>(b, 1.0);
    if (ca.w < u.near_w && cb.w < u.near_w) {
        return culled();
    }
    // Cut the segment at the near plane (homogeneous interpolation is exact).
    if (ca.w < u.near_w) {
        ca = mix(ca, cb, (u.near_w - ca.w) / (cb.w - ca.w));
    }
    if (cb.w < u.near_w) {
        cb = mix(cb, ca, (u.near_w - cb.w) / (ca.w - cb.w));
    }
    let pa = to_px(ca);
    let pb = to_px(cb);
    let d = pb - pa;
    let len = length(d);
    var along = vec2<f32>(1.0, 0.0);
    if (len > 1e-6) {
        along = d / len;
    }
    let across = vec2<f32>(-along.y, along.x);
    let k = corner(vi);
    let p = mix(pa, pb, k.x) + across * (k.y * 0.5 * width_pt * u.pixels_per_point);
    var out: Out;
    out.position = from_px(p);
    out.color = color;
    return out;
}

@vertex
fn vs_marker(
    @builtin(vertex_index) vi: u32,
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
    @location(2) size_pt: f32,
) -> Out {
    let c = u.clip_from_world * vec4<f32>(position, 1.0);
    if (c.w < u.near_w) {
        return culled();
    }
    let k = corner(vi);
    let offset = vec2<f32>(2.0 * k.x - 1.0, k.y) * (0.5 * size_pt * u.pixels_per_point);
    var out: Out;
    out.position = from_px(to_px(c) + offset);
    out.color = color;
    return out;
}

// Colours arrive straight (not premultiplied); egui's target blends premultiplied alpha.
@fragment
fn fs_main(in: Out) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color.rgb * in.color.a, in.color.a);
}
