// The `skycast view` present pass: the demo host's linear Rgba16Float frame copied onto the
// window's surface by one full-screen triangle. The surface view is an sRGB format, so the
// hardware encodes linear to sRGB exactly as `skycast render` does on the CPU for its PNG.
// Driven by src/cli/view/present.rs.

@group(0) @binding(0) var frame_texture: texture_2d<f32>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
};

@vertex
fn vs_present(@builtin(vertex_index) index: u32) -> VertexOut {
    // One triangle covering the screen: (-1,-1), (3,-1), (-1,3).
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: VertexOut;
    out.position = vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
    return out;
}

@fragment
fn fs_present(in: VertexOut) -> @location(0) vec4<f32> {
    // Same size as the surface: one texel per pixel, no filtering.
    let texel = textureLoad(frame_texture, vec2<i32>(in.position.xy), 0);
    return vec4<f32>(clamp(texel.rgb, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
