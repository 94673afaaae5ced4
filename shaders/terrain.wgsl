// Pass `host.terrain` of the demo host: a height-field mesh with sun light and distance fog,
// writing colour and depth. Not part of the sky; any host draws its own ground.

// Keep in sync with `GpuTerrainFrame` in src/render/gpu_types.rs.
struct TerrainFrame {
    view_proj: mat4x4<f32>,
    origin_rel: vec4<f32>,
    sun_dir: vec4<f32>,
    sun_rgb: vec4<f32>,
    fog_rgb: vec4<f32>,
};

@group(0) @binding(0) var<uniform> terrain: TerrainFrame;

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
};

@vertex
fn vs_terrain(v: TerrainVertex) -> TerrainOut {
    var o: TerrainOut;
    let rel = v.position_m + terrain.origin_rel.xyz;
    o.position = terrain.view_proj * vec4<f32>(rel, 1.0);
    o.rel_m = rel;
    o.height_m = v.height_m;
    o.normal = v.normal.xyz;
    return o;
}

@fragment
fn fs_terrain(i: TerrainOut) -> @location(0) vec4<f32> {
    let n = normalize(i.normal);
    let slope = 1.0 - n.z;
    var albedo = mix(vec3<f32>(0.09, 0.16, 0.05), vec3<f32>(0.16, 0.14, 0.09), smoothstep(300.0, 1500.0, i.height_m));
    albedo = mix(albedo, vec3<f32>(0.18, 0.16, 0.14), smoothstep(0.15, 0.4, slope));
    albedo = mix(albedo, vec3<f32>(0.7, 0.72, 0.75), smoothstep(2600.0, 3000.0, i.height_m) * (1.0 - smoothstep(0.3, 0.5, slope)));
    let sun = max(dot(n, terrain.sun_dir.xyz), 0.0);
    let lit = albedo * (terrain.sun_rgb.rgb * sun + vec3<f32>(terrain.sun_dir.w));
    let dist = length(i.rel_m);
    let fog = 1.0 - exp(-dist * 3.0 / max(terrain.fog_rgb.w, 1.0));
    return vec4<f32>(mix(lit, terrain.fog_rgb.rgb, fog), 1.0);
}
