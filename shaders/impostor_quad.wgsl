// Pass `ring.quads` (inside the sky pass): the far-cloud impostors of the ring (Wang 2003 6.2) as
// world-fixed quads, premultiplied alpha scaled by the crossfade weight. Each texel's stored
// alpha-weighted depth puts its clouds back where they were along the ray from the ring centre,
// so the host's scene hides them only where it is nearer than the clouds, not the quad (a
// mountain beyond the ring radius in front of some far clouds and behind others), with the
// sprites' soft fade. Shared: shared/frame.wgsl.

@group(1) @binding(0) var impostor: texture_2d<f32>;
@group(1) @binding(1) var impostor_sampler: sampler;
@group(1) @binding(2) var impostor_depth: texture_2d<f32>;

// Keep in sync with `QuadVertex` in src/render/impostor.rs.
struct QuadIn {
    @location(0) position_m: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) weight: f32,
    @location(3) centre_m: vec3<f32>,
    @location(4) radius_m: f32,
};

struct QuadOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) weight: f32,
    @location(2) position_m: vec3<f32>,
    @location(3) centre_m: vec3<f32>,
    @location(4) radius_m: f32,
};

@vertex
fn vs_impostor(v: QuadIn) -> QuadOut {
    var o: QuadOut;
    o.position = frame.view_proj * vec4<f32>(v.position_m, 1.0);
    o.uv = v.uv;
    o.weight = v.weight;
    o.position_m = v.position_m;
    o.centre_m = v.centre_m;
    o.radius_m = v.radius_m;
    return o;
}

@fragment
fn fs_impostor(i: QuadOut) -> @location(0) vec4<f32> {
    let texel = textureSample(impostor, impostor_sampler, i.uv);
    let depth_km = textureSample(impostor_depth, impostor_sampler, i.uv).r;
    // The quad lies at radius_m along the impostor's axis; the clouds at depth / alpha.
    var along = 1.0;
    if (texel.a > 0.002) {
        along = max(depth_km * 1000.0 / texel.a / i.radius_m, 1.0);
    }
    let cloud = i.centre_m + (i.position_m - i.centre_m) * along;
    let cloud_m = (frame.view_proj * vec4<f32>(cloud, 1.0)).w;
    let scene_m = linear_depth_m(scene_depth_at(i.position.xy));
    let soft = clamp((scene_m - cloud_m) / frame.params.z, 0.0, 1.0);
    return texel * (i.weight * soft);
}
