// Pass `host.terrain` of the demo host: a height-field mesh with sun light and distance fog,
// writing colour and depth, its sunlight dimmed by the clouds' shadows (the sky's shadow map).
// Not part of the sky; any host draws its own ground.

// Keep in sync with `GpuTerrainFrame` in src/render/gpu_types.rs.
struct TerrainFrame {
    view_proj: mat4x4<f32>,
    origin_rel: vec4<f32>,
    sun_dir: vec4<f32>,
    sun_rgb: vec4<f32>,
    // w: the camera's distance from the Earth's centre, metres (0: flat).
    fog_rgb: vec4<f32>,
    // The altitude haze (shared/frame.wgsl `haze`); origin_rel.w: the camera's height above its
    // base.
    haze: vec4<f32>,
    // Camera-relative position to the cloud shadow map's texture coordinates.
    shadow_uv: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> terrain: TerrainFrame;
// The sky's cloud shadow map: optical depth along the sun's ray (src/render/shadow/mod.rs).
@group(0) @binding(1) var shadow_map: texture_2d<f32>;
@group(0) @binding(2) var shadow_sampler: sampler;

// Keep in sync with `GpuTerrainVertex` in src/render/gpu_types.rs.
struct TerrainVertex {
    @location(0) position_m: vec3<f32>,
    @location(1) height_m: f32,
    @location(2) normal: vec4<f32>,
};

struct TerrainOut {
    @builtin(position) position: vec4<f32>,
    @location(0) rel_m: vec3<f32>,
    @location(1) height_m: f32,
    @location(2) normal: vec3<f32>,
    // Metres from the mesh origin, horizontal: where the ground's patterns are anchored.
    @location(3) ground_xy: vec2<f32>,
    // The ground's height above the camera, metres (the flat frame's: the true one).
    @location(4) dz_m: f32,
};

// The round Earth (shared/frame.wgsl `earth_curved`, src/render/earth.rs `curved_rel`: keep
// in sync): the ground drops below the camera's level plane as the clouds do.
fn earth_curved(rel: vec3<f32>) -> vec3<f32> {
    let rc = terrain.fog_rgb.w;
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

// The altitude haze (shared/frame.wgsl `haze_mean`: keep in sync).
fn haze_mean(per_m: f32, scale_m: f32, h0: f32, h1: f32) -> f32 {
    let low = max(min(h0, h1), 0.0);
    let x = abs(h1 - h0) / scale_m;
    let spread = select((1.0 - exp(-x)) / max(x, 1.0e-3), 1.0 - 0.5 * x, x < 1.0e-3);
    return per_m * exp(-low / scale_m) * spread;
}

@vertex
fn vs_terrain(v: TerrainVertex) -> TerrainOut {
    var o: TerrainOut;
    let flat = v.position_m + terrain.origin_rel.xyz;
    let rel = earth_curved(flat);
    o.position = terrain.view_proj * vec4<f32>(rel, 1.0);
    o.rel_m = rel;
    o.dz_m = flat.z;
    o.height_m = v.height_m;
    o.normal = v.normal.xyz;
    o.ground_xy = v.position_m.xy;
    return o;
}

fn hash2(p: vec2<f32>) -> f32 {
    let q = fract(p * vec2<f32>(0.1031, 0.1030));
    let r = q + dot(q, q.yx + 33.33);
    return fract((r.x + r.y) * r.x);
}

// Smooth value noise, 0..1, one cell a unit.
fn value_noise(p: vec2<f32>) -> f32 {
    let i = floor(p);
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let a = hash2(i);
    let b = hash2(i + vec2<f32>(1.0, 0.0));
    let c = hash2(i + vec2<f32>(0.0, 1.0));
    let d = hash2(i + vec2<f32>(1.0, 1.0));
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// What the ground is made of from the air, before light: a patchwork of fields (each a few
// hundred metres, its own crop) with hedges between them, woods and towns in regions a few
// kilometres across, rock on slopes, bare and then snowy high up, a shore and water below sea
// level. `footprint_m`: the metres one pixel covers, so detail finer than a pixel fades out
// instead of shimmering.
fn ground_albedo(xy: vec2<f32>, height_m: f32, slope: f32, footprint_m: f32) -> vec3<f32> {
    let crops = array<vec3<f32>, 4>(
        vec3<f32>(0.09, 0.15, 0.05),
        vec3<f32>(0.12, 0.16, 0.06),
        vec3<f32>(0.18, 0.17, 0.09),
        vec3<f32>(0.15, 0.12, 0.08),
    );
    // Fields in rows 440 m deep, each row shifted, each field ~320 m wide and some split in two
    // at a random point, the whole grid turned off the map's axes.
    let turned = vec2<f32>(0.956 * xy.x - 0.292 * xy.y, 0.292 * xy.x + 0.956 * xy.y);
    let row = floor(turned.y / 440.0);
    let along = turned.x / 320.0 + hash2(vec2<f32>(row, 5.0)) * 7.0;
    let column = floor(along);
    let split_at = 0.25 + 0.5 * hash2(vec2<f32>(column, row) + 11.0);
    let split = hash2(vec2<f32>(column, row) + 3.0) > 0.45;
    let part = select(0.0, step(split_at, fract(along)), split);
    var albedo = crops[u32(hash2(vec2<f32>(column + part * 0.5, row)) * 3.999)];
    // Hedges and tracks along the field edges, where a pixel can still see them.
    let edge_x = min(min(fract(along), 1.0 - fract(along)), select(1.0, abs(fract(along) - split_at), split)) * 320.0;
    let edge_y = min(fract(turned.y / 440.0), 1.0 - fract(turned.y / 440.0)) * 440.0;
    let hedge = 1.0 - smoothstep(3.0, 8.0, min(edge_x, edge_y));
    albedo *= 1.0 - 0.35 * hedge * (1.0 - smoothstep(8.0, 30.0, footprint_m));
    // Woods and towns by region (a few kilometres, edges warped so they are not round).
    let warp = vec2<f32>(value_noise(xy / 1300.0), value_noise(xy / 1100.0 + 17.0)) * 600.0;
    let region = value_noise((xy + warp) / 2600.0);
    albedo = mix(albedo, vec3<f32>(0.045, 0.08, 0.035), 1.0 - smoothstep(0.27, 0.3, region));
    let blocks = hash2(floor(xy / 90.0)) * 0.06;
    albedo = mix(albedo, vec3<f32>(0.15 + blocks, 0.15 + blocks, 0.14 + blocks), smoothstep(0.78, 0.8, region));
    // Within a field, texture ~40 m across, fading where a pixel covers more than it.
    let fine = value_noise(xy / 40.0) - 0.5;
    albedo *= 1.0 + 0.3 * fine * (1.0 - smoothstep(15.0, 45.0, footprint_m));
    albedo = mix(albedo, vec3<f32>(0.16, 0.14, 0.09), smoothstep(300.0, 1500.0, height_m));
    albedo = mix(albedo, vec3<f32>(0.18, 0.16, 0.14), smoothstep(0.15, 0.4, slope));
    albedo = mix(albedo, vec3<f32>(0.7, 0.72, 0.75), smoothstep(2600.0, 3000.0, height_m) * (1.0 - smoothstep(0.3, 0.5, slope)));
    albedo = mix(albedo, vec3<f32>(0.30, 0.27, 0.20), 1.0 - smoothstep(0.5, 3.0, height_m));
    return mix(albedo, vec3<f32>(0.02, 0.05, 0.08), 1.0 - smoothstep(-0.5, 0.5, height_m));
}

@fragment
fn fs_terrain(i: TerrainOut) -> @location(0) vec4<f32> {
    let water = 1.0 - smoothstep(-0.5, 0.5, i.height_m);
    // Water is flat whatever the mesh's relief says.
    let n = normalize(mix(normalize(i.normal), vec3<f32>(0.0, 0.0, 1.0), water));
    let slope = 1.0 - n.z;
    let footprint_m = length(fwidth(i.ground_xy));
    let albedo = ground_albedo(i.ground_xy, i.height_m, slope, footprint_m);
    // The clouds' shadow: their optical depth along the sun's ray through this point.
    let tau = textureSample(shadow_map, shadow_sampler, (terrain.shadow_uv * vec4<f32>(i.rel_m, 1.0)).xy).r;
    let sun = max(dot(n, terrain.sun_dir.xyz), 0.0) * exp(-tau);
    var lit = albedo * (terrain.sun_rgb.rgb * sun + vec3<f32>(terrain.sun_dir.w));
    // The water mirrors the sky a little, most at grazing angles (Schlick), and glints.
    let view = normalize(-i.rel_m);
    let fresnel = 0.02 + 0.98 * pow(1.0 - max(view.z, 0.0), 5.0);
    let glint = pow(max(dot(reflect(-terrain.sun_dir.xyz, n), view), 0.0), 200.0);
    lit += water * (terrain.fog_rgb.rgb * fresnel + terrain.sun_rgb.rgb * glint);
    // The altitude haze along the ray from the camera (src/shading/fog.rs `AltitudeHaze`).
    let dist = length(i.rel_m);
    let h0 = terrain.origin_rel.w;
    let h1 = h0 + i.dz_m;
    let k = terrain.haze;
    let fog = 1.0 - exp(-dist * (haze_mean(k.x, k.y, h0, h1) + haze_mean(k.z, k.w, h0, h1)));
    return vec4<f32>(mix(lit, terrain.fog_rgb.rgb, fog), 1.0);
}
