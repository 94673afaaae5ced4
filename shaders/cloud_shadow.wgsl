// Pass `sky.cloud_shadow`: the clouds drawn from the sun into the shadow map (R16Float), from
// the corners the build pass made of their sprites' dense cores (`build_core` in
// `sprite_build.wgsl`), facing an eye far up the sun's rays. Orthographic: clip space is the map
// across the rays. Each fragment adds the optical depth of its ray inside one core: the
// extinction inside a cloud (3 / the in-cloud visibility, Koschmieder, as the probes' lines of
// sight) times the length inside the core above the cloud's base, times the core's fade (Beer's
// law; additive, so no sort is needed). The cloud is what every probe asks (src/clouds/core.rs),
// so `World::sun_occlusion` at a ground point reads what the map shows there. A host multiplies
// its direct sunlight by exp(-tau) (src/render/shadow/mod.rs).

// Keep in sync with `MASK_RECTS` in src/render/shadow/mod.rs.
const MASK_RECTS: u32 = 32u;

// Keep in sync with `GpuCloudShadow` in src/render/shadow/mod.rs.
struct ShadowFrame {
    clip_from_eye: mat4x4<f32>,
    // x: optical depth per metre of cloud core along the ray (the extinction times the
    // settings' `opacity_scale`, less as the sun nears the horizon); y: the fraction of the map
    // across which its edge fades out; zw unused.
    params: vec4<f32>,
    // x: how many of `rects` a masked draw keeps to.
    mask: vec4<u32>,
    // The rectangles of texels drawn again: first column, first row, one past the last.
    rects: array<vec4<u32>, MASK_RECTS>,
};

@group(0) @binding(0) var<uniform> shadow: ShadowFrame;

// Keep in sync with `GpuSpriteVertex` in src/render/gpu_types.rs, as `build_core` fills it.
struct VertexIn {
    @location(0) position_visible: vec4<f32>,
    // The ray's direction in the core's unit sphere, x and y.
    @location(1) ray_xy: vec2<f32>,
    // xyz: the corner in the core's unit sphere; w: the cloud's base in its z.
    @location(2) corner_floor: vec4<f32>,
    // x: the optical depth's weight (fade x type's optical density x sprites stood for), negative
    // for a base sprite (its column down to the base); y: the ray's direction's z.
    @location(3) weight_ray_z: vec2<f32>,
};

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    // The fragment's ray through the core's unit sphere: a point of it (metres along the ray
    // are units of t), and its direction.
    @location(0) point: vec3<f32>,
    @location(1) @interpolate(flat) ray: vec3<f32>,
    // x: the weight, as `VertexIn`; y: the cloud's base in the unit sphere's z.
    @location(2) @interpolate(flat) weight_floor: vec2<f32>,
    // The corner in clip space (the edge fade).
    @location(3) clip: vec2<f32>,
    // 1: only the fragments in the rectangles drawn again are kept (instance 1 of the draw).
    @location(4) @interpolate(flat) masked: u32,
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
    o.point = v.corner_floor.xyz;
    o.ray = vec3<f32>(v.ray_xy, v.weight_ray_z.y);
    o.weight_floor = vec2<f32>(v.weight_ray_z.x, v.corner_floor.w);
    o.clip = o.position.xy;
    return o;
}

// Where the line `o + t d` is inside the unit circle (`xy`) or sphere: (t in, t out), empty
// (in > out) where it misses.
fn unit_chord(o: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    let dd = max(dot(d, d), 1e-12);
    let half_b = dot(o, d);
    let disc = half_b * half_b - dd * (dot(o, o) - 1.0);
    if (disc <= 0.0) {
        return vec2<f32>(1.0, -1.0);
    }
    let root = sqrt(disc);
    return vec2<f32>(-half_b - root, -half_b + root) / dd;
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
    let o = i.point;
    let d = i.ray;
    let floor = i.weight_floor.y;
    // Above the base: t past where the ray (going up, towards the sun) crosses it.
    let above = (floor - o.z) / max(d.z, 1e-9);
    var core = unit_chord(o, d);
    core.x = max(core.x, above);
    var length_m = max(core.y - core.x, 0.0);
    if (i.weight_floor.x < 0.0) {
        // A base sprite's column: inside its outline across, between the base and its middle;
        // the part of it not in the ellipsoid too (each stretch counted once, as the probes'
        // union of a cloud's cores).
        var column = unit_chord(vec3<f32>(o.xy, 0.0), vec3<f32>(d.xy, 0.0));
        column.x = max(column.x, above);
        column.y = min(column.y, -o.z / max(d.z, 1e-9));
        let both = max(min(core.y, column.y) - max(core.x, column.x), 0.0);
        length_m += max(column.y - column.x, 0.0) - select(0.0, both, length_m > 0.0);
    }
    // The map's last texels fade out: a shadow ends softly at its edge, and the edge texels a
    // host's clamped lookup repeats beyond it hold nothing.
    let edge = max(abs(i.clip.x), abs(i.clip.y));
    let keep = 1.0 - smoothstep(1.0 - shadow.params.y, 1.0 - 0.25 * shadow.params.y, edge);
    let tau = length_m * abs(i.weight_floor.x) * shadow.params.x;
    return vec4<f32>(tau * keep, 0.0, 0.0, 0.0);
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
