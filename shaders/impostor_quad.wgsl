// Pass `ring.quads` (inside the sky pass): the far-cloud impostors of the ring (Wang 2003 6.2) as
// world-fixed quads, premultiplied alpha scaled by the crossfade weight. Hidden where the host
// drew something nearer than the quad (terrain inside the ring radius). Shared: shared/frame.wgsl.

@group(1) @binding(0) var impostor: texture_2d<f32>;
@group(1) @binding(1) var impostor_sampler: sampler;

// Keep in sync with `QuadVertex` in src/render/impostor.rs.
struct QuadIn {
    @location(0) position_m: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) weight: f32,
};

struct QuadOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) weight: f32,
    @location(2) view_depth_m: f32,
};

@vertex
fn vs_impostor(v: QuadIn) -> QuadOut {
    var o: QuadOut;
    o.position = frame.view_proj * vec4<f32>(v.position_m, 1.0);
    o.uv = v.uv;
    o.weight = v.weight;
    o.view_depth_m = o.position.w;
    return o;
}

@fragment
fn fs_impostor(i: QuadOut) -> @location(0) vec4<f32> {
    let texel = textureSample(impostor, impostor_sampler, i.uv);
    let scene_m = linear_depth_m(scene_depth_at(i.position.xy));
    if (scene_m < i.view_depth_m) {
        discard;
    }
    return texel * i.weight;
}
