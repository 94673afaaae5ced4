// Pass `sky.cloud_shadow`: the clouds drawn from the sun into the shadow map (R16Float), from
// the corners the build pass (`sprite_build.wgsl`) made facing an eye far up the sun's rays.
// Orthographic: clip space is the map across the rays. Each fragment adds the optical depth its
// opacity shows the eye, -ln(1 - alpha) (Beer's law), so the blending adds and needs no sort.
// A host multiplies its direct sunlight by exp(-tau) (src/render/shadow/mod.rs).

// Keep in sync with `MASK_RECTS` in src/render/shadow/mod.rs.
const MASK_RECTS: u32 = 32u;

// Keep in sync with `GpuCloudShadow` in src/render/shadow/mod.rs.
struct ShadowFrame {
    clip_from_eye: mat4x4<f32>,
    // x: optical depth per the optical depth of a fragment's opacity; y: the fraction of the
    // map across which its edge fades out.
    params: vec4<f32>,
    // x: how many of `rects` a masked draw keeps to.
    mask: vec4<u32>,
    // The rectangles of texels drawn again: first column, first row, one past the last.
    rects: array<vec4<u32>, MASK_RECTS>,
};

@group(0) @binding(0) var<uniform> shadow: ShadowFrame;
@group(1) @binding(0) var sheet: texture_2d<f32>;
@group(1) @binding(1) var sheet_sampler: sampler;

// Keep in sync with `GpuSpriteVertex` in src/render/gpu_types.rs.
struct VertexIn {
    @location(0) position_visible: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) colour: vec4<f32>,
    // x: how many sprites of its cloud this one stands for (far clouds are built sparser).
    @location(3) stands_for: vec2<f32>,
};

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    // xy: sheet texture coordinates; z: the corner's opacity (its fades included).
    @location(0) uv_alpha: vec3<f32>,
    // xy: the corner in clip space (the edge fade); z: how many sprites it stands for.
    @location(1) clip_stands_for: vec3<f32>,
    // 1: only the fragments in the rectangles drawn again are kept (instance 1 of the draw).
    @location(2) @interpolate(flat) masked: u32,
};

@vertex
fn vs_shadow(v: VertexIn, @builtin(instance_index) instance: u32) -> VertexOut {
    var o: VertexOut;
    o.masked = instance;
    if (v.position_visible.w < 0.5) {
        // Faded out: every corner outside the clip volume.
        o.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return o;
    }
    o.position = shadow.clip_from_eye * vec4<f32>(v.position_visible.xyz, 1.0);
    o.uv_alpha = vec3<f32>(v.uv, v.colour.a);
    o.clip_stands_for = vec3<f32>(o.position.xy, max(v.stands_for.x, 1.0));
    return o;
}

// Whether a texel is in one of the rectangles drawn again: a map patched adds a sprite to
// those alone (the rest of the map holds it already), once however the rectangles overlap.
fn in_rects(texel: vec2<u32>) -> bool {
    for (var k = 0u; k < min(shadow.mask.x, MASK_RECTS); k++) {
        let r = shadow.rects[k];
        if (all(texel >= r.xy) && all(texel < r.zw)) {
            return true;
        }
    }
    return false;
}

@fragment
fn fs_shadow(i: VertexOut) -> @location(0) vec4<f32> {
    if (i.masked != 0u && !in_rects(vec2<u32>(i.position.xy))) {
        discard;
    }
    let texel = textureSample(sheet, sheet_sampler, i.uv_alpha.xy);
    // Below 1: a fragment never stops all the light (its log would be infinite).
    let alpha = clamp(texel.a * i.uv_alpha.z, 0.0, 0.98);
    // The map's last texels fade out: a shadow ends softly at its edge, and the edge texels a
    // host's clamped lookup repeats beyond it hold nothing.
    let edge = max(abs(i.clip_stands_for.x), abs(i.clip_stands_for.y));
    let keep = 1.0 - smoothstep(1.0 - shadow.params.y, 1.0 - 0.25 * shadow.params.y, edge);
    let tau = -log(1.0 - alpha) * i.clip_stands_for.z;
    return vec4<f32>(tau * shadow.params.x * keep, 0.0, 0.0, 0.0);
}

// A rectangle of the map drawn again is cleared first: a triangle over the whole map writing 0
// (no blending), cut to the rectangle by the scissor (src/render/shadow/draw.rs).
@vertex
fn vs_clear(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_clear() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0, 0.0, 0.0, 0.0);
}
