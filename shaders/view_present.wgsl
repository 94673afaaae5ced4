// The `skycast view` present pass: the demo host's linear Rgba16Float frame copied onto the
// window's surface by one full-screen triangle. The surface view is an sRGB format, so the
// hardware encodes linear to sRGB exactly as `skycast render` does on the CPU for its PNG.
// Over it, top left, the overlay (src/cli/view/overlay.rs): text coverage in red, the box in
// green; `OverlayImage::composite` is this blend on the CPU, for screenshots: keep in sync.
// Driven by src/cli/view/present.rs.

@group(0) @binding(0) var frame_texture: texture_2d<f32>;
@group(0) @binding(1) var overlay_texture: texture_2d<f32>;

// Keep in sync with overlay.rs (MARGIN_PX, BOX_DIM).
const OVERLAY_MARGIN_PX: i32 = 8;
const BOX_DIM: f32 = 0.35;

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
    let pixel = vec2<i32>(in.position.xy);
    var colour = textureLoad(frame_texture, pixel, 0).rgb;
    let overlay_pixel = pixel - vec2<i32>(OVERLAY_MARGIN_PX);
    let overlay_size = vec2<i32>(textureDimensions(overlay_texture));
    if all(overlay_pixel >= vec2<i32>(0)) && all(overlay_pixel < overlay_size) {
        let overlay = textureLoad(overlay_texture, overlay_pixel, 0);
        let dimmed = colour * (1.0 - overlay.g * (1.0 - BOX_DIM));
        colour = dimmed + (1.0 - dimmed) * overlay.r;
    }
    return vec4<f32>(clamp(colour, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
