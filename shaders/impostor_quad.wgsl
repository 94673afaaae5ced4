// Pass `ring.quads` (inside the sky pass): the far-cloud impostors of the ring (Wang 2003 6.2),
// one full-screen pass. Each pixel's ray is intersected with the octagon of world-fixed quads of
// the shown ring and, while crossfading, of the new ring; the two lookups are mixed in this one
// pass (premultiplied `mix(old, new, weight)`), so a crossfade never dips towards the background
// as two blended draws would. Each texel's stored alpha-weighted depth puts its clouds back where
// they were along the ray from the ring centre, so the host's scene hides them only where it is
// nearer than the clouds, not the quad (a mountain beyond the ring radius in front of some far
// clouds and behind others), with the sprites' soft fade. Shared: shared/frame.wgsl.

@group(1) @binding(0) var old_colour: texture_2d_array<f32>;
@group(1) @binding(1) var old_depth: texture_2d_array<f32>;
@group(1) @binding(2) var new_colour: texture_2d_array<f32>;
@group(1) @binding(3) var new_depth: texture_2d_array<f32>;
@group(1) @binding(4) var impostor_sampler: sampler;
@group(1) @binding(5) var<uniform> ring: Ring;

// Keep in sync with `GpuRing` in src/render/impostor/mod.rs.
struct Ring {
    // xyz: the old (shown) ring's centre relative to the camera, metres; w: crossfade weight.
    old_centre_weight: vec4<f32>,
    // xyz: the new ring's centre relative to the camera (the old one when not fading).
    new_centre: vec4<f32>,
    // x: ring radius, metres; y: half side of a quad, metres; z, w: the old and new rings'
    // first guess of their clouds' distance from the centre, metres.
    size: vec4<f32>,
};

struct RingOut {
    @builtin(position) position: vec4<f32>,
    @location(0) ndc: vec2<f32>,
    // The rings' centres (`Ring`'s xyz), handed on by the vertex stage rather than read from the
    // uniform here: while the steady pass's fragment shader read the shown ring's centre from
    // the uniform, lavapipe (Mesa 22) compiled it afresh at every draw, specialised on the
    // uniform, and kept every copy (about 0.55 MB a frame, tests/memory.rs). A flat input is no
    // uniform to specialise on.
    @location(1) @interpolate(flat) old_centre: vec3<f32>,
    @location(2) @interpolate(flat) new_centre: vec3<f32>,
};

@vertex
fn vs_impostor(@builtin(vertex_index) vi: u32) -> RingOut {
    var o: RingOut;
    o.position = fullscreen_position(vi);
    o.ndc = o.position.xy;
    o.old_centre = ring.old_centre_weight.xyz;
    o.new_centre = ring.new_centre.xyz;
    return o;
}

// Where `dir` (unit, from the camera) meets the sphere of `dist_m` around `centre` (the camera
// is inside it).
fn on_sphere(centre: vec3<f32>, dir: vec3<f32>, dist_m: f32) -> vec3<f32> {
    let b = dot(dir, centre);
    let t = b + sqrt(max(b * b - dot(centre, centre) + dist_m * dist_m, 0.0));
    return dir * t;
}

// An impostor's half height over its half width: tan(35 deg) / tan(22.5 deg)
// (`IMPOSTOR_FOV_Y_DEG` and `IMPOSTOR_FOV_DEG` in src/render/impostor/layout.rs).
const IMPOSTOR_TALL: f32 = 1.6904;

// The impostor (xyz: texture coordinates and layer) that sees `from_centre` (a direction from
// the ring centre), and how far along its axis a unit step in that direction goes (w);
// layer 8 when the direction leaves every impostor (above or below them).
fn impostor_at(from_centre: vec3<f32>) -> vec4<f32> {
    let bearing = atan2(from_centre.x, from_centre.y);
    let j = u32(round(bearing / 0.7853982) + 8.0) % 8u;
    let h = f32(j) * 0.7853982;
    let n = vec3<f32>(sin(h), cos(h), 0.0);
    let right = vec3<f32>(cos(h), -sin(h), 0.0);
    let facing = dot(from_centre, n);
    let q = from_centre * (ring.size.x / max(facing, 1e-6));
    let x = dot(q, right) / ring.size.y;
    let y = q.z / (ring.size.y * IMPOSTOR_TALL);
    var layer = f32(j);
    if (abs(x) > 1.0 || abs(y) > 1.0 || facing <= 1e-6) {
        layer = 8.0;
    }
    return vec4<f32>((x + 1.0) * 0.5, (1.0 - y) * 0.5, layer, facing);
}

// How little the reprojected cloud distance may move in a step for the ring pass to stop
// stepping, metres (the stored depth itself holds about 30 m at 60 km).
const CONVERGED_M: f32 = 1.0;

// What one ring shows along a ray: premultiplied colour, scene-depth faded, and the distance
// of its clouds from the camera plane, metres.
struct RingHit {
    colour: vec4<f32>,
    distance_m: f32,
};

// The premultiplied colour of one ring along `dir` (unit, from the camera), scene-depth faded.
// Beyond Wang: the impostor was seen from the ring centre, not from the camera, so the ray is
// reprojected with the stored cloud depth: start with the clouds `guess_m` from the centre,
// look up their stored distance there, and repeat; the clouds then sit where they are, not on
// the quad, and move with the right parallax as the camera leaves the centre.
fn ring_sample(
    colour: texture_2d_array<f32>,
    depth: texture_2d_array<f32>,
    centre: vec3<f32>,
    guess_m: f32,
    dir: vec3<f32>,
    frag_xy: vec2<f32>,
) -> RingHit {
    var dist = guess_m;
    var at = vec4<f32>(0.0, 0.0, 8.0, 1.0);
    var texel = vec4<f32>(0.0);
    var depth_km = 0.0;
    for (var k = 0; k < 4; k++) {
        let from_centre = normalize(on_sphere(centre, dir, dist) - centre);
        at = impostor_at(from_centre);
        if (at.z > 7.5) {
            return RingHit(vec4<f32>(0.0), 0.0);
        }
        texel = textureSampleLevel(colour, impostor_sampler, at.xy, u32(at.z), 0.0);
        depth_km = textureSampleLevel(depth, impostor_sampler, at.xy, u32(at.z), 0.0).r;
        // The alpha-weighted depth around here (premultiplied depth over alpha, both summed
        // over a few texels): smooth, and defined at silhouettes too.
        var a = texel.a;
        var d = depth_km;
        let step = 3.0 / f32(textureDimensions(depth).x);
        for (var n = 0; n < 4; n++) {
            let ang = (f32(n) + 0.5) * 1.5707964;
            let uv = at.xy + vec2<f32>(cos(ang), sin(ang)) * step;
            a += textureSampleLevel(colour, impostor_sampler, uv, u32(at.z), 0.0).a;
            d += textureSampleLevel(depth, impostor_sampler, uv, u32(at.z), 0.0).r;
        }
        if (a <= 0.002) {
            break;
        }
        // Stored: distance along the impostor's axis; the sphere wants it from the centre.
        let next = max(d * 1000.0 / a, ring.size.x) / max(at.w, 1e-3);
        let moved_m = abs(next - dist);
        dist = next;
        // Settled: another lookup would land within a ten-thousandth of a texel of this one
        // (the camera is at most a few kilometres from the centre; the clouds 20 km and more).
        // Near the centre that is the second step; the loop ends once a block of pixels has
        // settled, where lavapipe paid for all four.
        if (moved_m < CONVERGED_M) {
            break;
        }
    }
    let cloud = on_sphere(centre, dir, dist);
    let cloud_m = (frame.view_proj * vec4<f32>(cloud, 1.0)).w;
    let scene_m = scene_m_at(frag_xy);
    let soft = clamp((scene_m - cloud_m) * frame.params.y, 0.0, 1.0);
    return RingHit(texel * soft, cloud_m);
}

@fragment
fn fs_impostor(i: RingOut) -> @location(0) vec4<f32> {
    return ring_hit(i).colour;
}

// Into the cloud target (`cloud_target.rs`): the colour and the distance of its clouds.
@fragment
fn fs_impostor_offscreen(i: RingOut) -> CloudOut {
    let hit = ring_hit(i);
    return cloud_out(hit.colour, hit.distance_m);
}

// The steady frames' ring pass, nothing fading in (`ring_pass.rs` picks it on the CPU): the
// shown ring's lookup alone. Lavapipe runs both sides of `ring_hit`'s branch on the crossfade
// weight, so there every steady pixel paid for a second lookup it did not show.
@fragment
fn fs_impostor_shown(i: RingOut) -> @location(0) vec4<f32> {
    return shown_hit(i).colour;
}

@fragment
fn fs_impostor_shown_offscreen(i: RingOut) -> CloudOut {
    let hit = shown_hit(i);
    return cloud_out(hit.colour, hit.distance_m);
}

// The unit view ray of a ring pass pixel.
fn ray_dir(i: RingOut) -> vec3<f32> {
    let far = far_point(i.ndc);
    return normalize(far.xyz / far.w);
}

// What the shown ring shows along the pixel's ray.
fn shown_hit(i: RingOut) -> RingHit {
    return ring_sample(
        old_colour, old_depth, i.old_centre, ring.size.z, ray_dir(i), i.position.xy
    );
}

fn ring_hit(i: RingOut) -> RingHit {
    let dir = ray_dir(i);
    let w = ring.old_centre_weight.w;
    let before = shown_hit(i);
    if (w <= 0.0) {
        return before;
    }
    let after = ring_sample(
        new_colour, new_depth, i.new_centre, ring.size.w, dir, i.position.xy
    );
    // The distance of the mix: each ring's weighted by what it shows.
    let a = mix(before.colour.a * before.distance_m, after.colour.a * after.distance_m, w);
    let colour = mix(before.colour, after.colour, w);
    return RingHit(colour, a / max(colour.a, 1e-6));
}
