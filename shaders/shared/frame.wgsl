// Shared by the sky passes. Keep in sync with `GpuFrame` in src/render/gpu_types.rs.
struct Frame {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    sun_dir: vec4<f32>,
    sun_rgb: vec4<f32>,
    // w: the camera's height above the haze's base (the ground under it), metres.
    sky_zenith_rgb: vec4<f32>,
    // w: the camera's distance from the Earth's centre, metres (0: the flat frame).
    sky_horizon_rgb: vec4<f32>,
    in_cloud_rgba: vec4<f32>,
    // x: the host's background depth (1 standard Z, 0 reversed), y: 1 / soft_depth_fade_m (the
    // soft fades multiply by it: a division per fragment spared), z: soft_depth_fade_m,
    // w: in_cloud_visibility_m
    params: vec4<f32>,
    // The altitude haze (src/shading/fog.rs `AltitudeHaze::to_gpu`): x: the boundary layer's
    // extinction at the ground, per metre; y: its scale height, metres; z, w: clear air's.
    haze: vec4<f32>,
    // The host projection's depth to metres: -(a d + b) / (c d + e) for (a, b, c, e).
    depth_to_view: vec4<f32>,
    // A lightning flash lighting its cell from inside: xyz its centre, camera-relative metres;
    // w the light it adds at the centre (0: none).
    flash: vec4<f32>,
    // x: the reach of `flash` (its Gaussian's 1/e distance), metres; yzw unused.
    flash_reach: vec4<f32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
// The host's depth, read only. Bound as an unfilterable float texture (works on Vulkan and GL).
@group(0) @binding(1) var scene_depth: texture_2d<f32>;

// Metres from the camera plane of a depth value of the host's projection (standard or
// reversed Z, finite or infinite far plane).
fn linear_depth_m(d: f32) -> f32 {
    let k = frame.depth_to_view;
    let w = k.z * d + k.w;
    return select(1.0e9, -(k.x * d + k.y) / w, abs(w) > 1.0e-12);
}

// Whether the host drew nothing at a pixel (its depth is still the cleared far value).
fn is_background(d: f32) -> bool {
    return d == frame.params.x;
}

// The farther of two depths of the host's convention (standard Z: larger, reversed: smaller).
fn farther_depth(a: f32, b: f32) -> f32 {
    return select(min(a, b), max(a, b), frame.params.x > 0.5);
}

fn scene_depth_at(frag_xy: vec2<f32>) -> f32 {
    return textureLoad(scene_depth, vec2<i32>(frag_xy), 0).r;
}

// Whether `scene_depth` already holds metres from the camera plane instead of the host's depth:
// set for the passes into the off-screen cloud target, which read the farthest distance of each
// block of host pixels (`cloud_downsample.wgsl`), converted once a texel there instead of once a
// fragment here (the conversion's division was a tenth of the sprites' fill cost on lavapipe).
override SCENE_IN_METRES: bool = false;

// Metres from the camera plane to what the host drew at a pixel (`linear_depth_m` of its depth).
fn scene_m_at(frag_xy: vec2<f32>) -> f32 {
    let stored = scene_depth_at(frag_xy);
    if (SCENE_IN_METRES) {
        return stored;
    }
    return linear_depth_m(stored);
}

// The round Earth: a camera-relative point of the flat frame placed on the sphere the camera
// flies over (src/render/earth.rs `curved_rel`, keep in sync; also in terrain.wgsl).
fn earth_curved(rel: vec3<f32>) -> vec3<f32> {
    let rc = frame.sky_horizon_rgb.w;
    let s = length(rel.xy);
    // By select, not a branch on `rc`, which changes with the camera's height: lavapipe keeps a
    // copy of a shader for each value of a uniform that a branch tests (far_field.wgsl).
    let theta = s / max(rc, 1.0);
    let sin_half = sin(0.5 * theta);
    let drop = 2.0 * sin_half * sin_half;
    let along = (rc + rel.z) * sin(theta) / max(s, 1.0e-6);
    let curved = vec3<f32>(rel.xy * along, rel.z * (1.0 - drop) - rc * drop);
    return select(curved, rel, rc <= 0.0 || s <= 0.0);
}

// The mean of `per_m exp(-h / scale_m)` along a straight ray between heights `h0` and `h1`
// above the haze's base (src/shading/fog.rs `mean_extinction`, keep in sync).
fn haze_mean(per_m: f32, scale_m: f32, h0: f32, h1: f32) -> f32 {
    let low = max(min(h0, h1), 0.0);
    let x = abs(h1 - h0) / scale_m;
    let spread = select((1.0 - exp(-x)) / max(x, 1.0e-3), 1.0 - 0.5 * x, x < 1.0e-3);
    return per_m * exp(-low / scale_m) * spread;
}

// How much of what lies `dist_m` from the camera, `dz_m` above it (the flat frame's height
// difference: the true one), shows through the altitude haze, 0..1
// (`AltitudeHaze::transmittance`).
fn haze_transmittance(dist_m: f32, dz_m: f32) -> f32 {
    let h0 = frame.sky_zenith_rgb.w;
    let h1 = h0 + dz_m;
    let k = frame.haze;
    return exp(-dist_m * (haze_mean(k.x, k.y, h0, h1) + haze_mean(k.z, k.w, h0, h1)));
}

// Full-screen triangle.
fn fullscreen_position(vi: u32) -> vec4<f32> {
    let x = f32((vi << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(vi & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

// The sine of a unit direction's elevation above the geometric horizon, which on the round
// Earth lies below the camera's level plane by the dip: sin(dip) = sqrt(h (2 rc - h)) / rc, h the
// camera's height above the ground under it, rc its distance from the Earth's centre (0: the
// flat frame, no dip). From FL350 the dip is 3.3 degrees: between the level plane and the
// horizon a pilot sees sky, brightest where it meets the Earth's rim, not a flat band of the
// horizon's haze (src/render/earth.rs `horizon_dip_rad`, keep in sync).
fn above_horizon(dir: vec3<f32>) -> f32 {
    let rc = frame.sky_horizon_rgb.w;
    let h = clamp(frame.sky_zenith_rgb.w, 0.0, max(rc, 0.0));
    let sin_dip = select(sqrt(h * (2.0 * rc - h)) / max(rc, 1.0), 0.0, rc <= 0.0);
    let cos_dip = sqrt(max(1.0 - sin_dip * sin_dip, 0.0));
    let z = clamp(dir.z, -1.0, 1.0);
    return z * cos_dip + sqrt(max(1.0 - z * z, 0.0)) * sin_dip;
}

// Sky colour seen along a unit direction (east, north, up); also the horizon haze for fog.
fn sky_colour(dir: vec3<f32>) -> vec3<f32> {
    let up = above_horizon(dir);
    let t = pow(clamp(up, 0.0, 1.0), 0.45);
    var c = mix(frame.sky_horizon_rgb.rgb, frame.sky_zenith_rgb.rgb, t);
    // Below the horizon: the haze darkens a little towards the ground.
    c = select(c, frame.sky_horizon_rgb.rgb * (1.0 + 0.6 * up), up < 0.0);
    let cos_sun = dot(dir, frame.sun_dir.xyz);
    let glow = smoothstep(frame.sun_rgb.w, 1.0, cos_sun);
    c += frame.sun_rgb.rgb * glow * glow * 0.35;
    return c;
}

// The sky behind everything along a view ray: the gradient and the sun disc (`sky.wgsl`, and the
// cloud composite below full resolution). `far` is a point of the ray in homogeneous world
// coordinates (`far_point` of the pixel): the full-screen passes compute it per vertex and let
// it be interpolated (exact: it is linear across the screen), which spares each pixel a matrix
// product.
fn background_along(far: vec4<f32>) -> vec3<f32> {
    let dir = normalize(far.xyz / far.w);
    let c = sky_colour(dir);
    let cos_sun = dot(dir, frame.sun_dir.xyz);
    let disc = smoothstep(frame.sun_dir.w - 0.00002, frame.sun_dir.w + 0.00002, cos_sun);
    return mix(c, frame.sun_rgb.rgb * 4.0, disc * step(-0.01, above_horizon(dir)));
}

// A point of the view ray (homogeneous world coordinates) at normalised device coordinates
// `ndc`: at depth 0.5, finite under any projection (a far plane at infinity, reversed Z).
fn far_point(ndc: vec2<f32>) -> vec4<f32> {
    return frame.inv_view_proj * vec4<f32>(ndc, 0.5, 1.0);
}

// The vertex of a full-screen pass over the host's background (`sky.wgsl`, the cloud composite).
struct BackgroundOut {
    // Invariant: the passes' depth tests compare it with the host's depth exactly.
    @invariant @builtin(position) position: vec4<f32>,
    // The far-plane point of the pixel, homogeneous (see `background_along`).
    @location(0) far: vec4<f32>,
};

// Full-screen triangle vertex `vi` at the host's background depth: with the host's depth
// attached, an `Equal` test keeps the pixels where the host drew nothing, `NotEqual` its scene.
fn background_vertex(vi: u32) -> BackgroundOut {
    var o: BackgroundOut;
    o.position = fullscreen_position(vi);
    o.far = far_point(o.position.xy);
    o.position.z = frame.params.x;
    return o;
}

// What a cloud pass writes into the off-screen cloud target (src/render/cloud_target.rs):
// premultiplied colour, and the clouds' distance in kilometres times alpha (R16Float), both
// blended "over", so distance / alpha is the distance of what shows in the texel.
struct CloudOut {
    @location(0) colour: vec4<f32>,
    @location(1) distance: vec4<f32>,
};

fn cloud_out(colour: vec4<f32>, distance_m: f32) -> CloudOut {
    var o: CloudOut;
    o.colour = colour;
    o.distance = vec4<f32>(distance_m * 0.001 * colour.a, 0.0, 0.0, colour.a);
    return o;
}
