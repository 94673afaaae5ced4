// Pass `far_field.layers` (inside the sky pass, before the impostor ring): the clouds beyond the
// ring and the sprites, out to the horizon, as two curved layers of the cloud map
// (src/clouds/far_map.rs): each pixel's ray meets the sphere of a layer's height (the round
// Earth of `earth_curved`), the map there gives the layer's cover, base, top and kind, and a
// world-anchored noise thresholded by the cover cuts it into clouds (heaped: small lumps; sheets:
// broad patches). Faded in over the band where the sprites and the ring fade out, faded into the
// altitude haze, softly cut by the host's depth. Shared: shared/frame.wgsl.

@group(1) @binding(0) var far_map: texture_2d_array<f32>;
@group(1) @binding(1) var far_sampler: sampler;
// Storage, not uniform: lavapipe would specialise this shader on every camera height its
// branches see (src/render/far_field/mod.rs).
@group(1) @binding(2) var<storage, read> ff: FarField;

// Keep in sync with `GpuFarField` in src/render/far_field/mod.rs.
struct FarField {
    // xy: the map's centre relative to the camera, metres; z: the map's side, metres; w: cells
    // per side.
    centre_rel_size: vec4<f32>,
    // xy: the map's centre in the noise's period, metres; z, w: the hand-over band (horizontal
    // metres from the camera where the far field fades in).
    noise_fade: vec4<f32>,
    // rgb: a cloud top's colour in the sun; w: the camera's height above sea level, metres.
    lit_rgb: vec4<f32>,
    // rgb: a cloud base's colour; w: the heaped layers' noise scale, metres.
    shade_rgb: vec4<f32>,
    // x, y: the low and high layers' mean middle height above sea level, metres; z: the
    // sheets' noise scale, metres; w: the noise's period, metres.
    heights: vec4<f32>,
    // x: how far the map has faded in, 0..1 (a first map, new weather).
    fade: vec4<f32>,
    // The heaped layers' clouds one by one (`heaped_puffs`): x, y: their smallest and largest
    // diameter, metres; z: their greatest height over their diameter; w: the share of the
    // layer they cover when every cell holds one.
    puffs: vec4<f32>,
    // rgb: a sheet's top's ambient light, in the near decks' textures' hue (times its type's
    // top level's grey, from the map's looks).
    sheet_ambient_rgb: vec4<f32>,
    // rgb: a sheet's top's sunlight, in that hue.
    sheet_sun_rgb: vec4<f32>,
};

struct FarOut {
    @builtin(position) position: vec4<f32>,
    // The pixel's direction from the camera (not unit: a point of the band's quad on its ray).
    @location(0) dir: vec3<f32>,
};

// Quads of the band around the horizon (keep in sync with `BAND_SEGMENTS` in
// src/render/far_field/mod.rs).
const BAND_SEGMENTS: u32 = 64u;

// Vertex `vi` of the band of elevations `ff.fade.y..ff.fade.z` where the far field's clouds can
// show (src/render/far_field/mod.rs `band_elevations`): two triangles a segment, directions at
// infinity. Only the pixels of that band run the fragment shader, not the whole screen. Its
// depth is held inside the clip volume in front of the camera (no depth test reads it); the
// clipper cuts the band's far side at a twentieth of the view axis, off any screen.
@vertex
fn vs_far_field(@builtin(vertex_index) vi: u32) -> FarOut {
    let corner = vi % 6u;
    let next = corner == 1u || corner == 2u || corner == 4u;
    let upper = corner == 2u || corner == 4u || corner == 5u;
    let azimuth = f32(vi / 6u + select(0u, 1u, next)) * (6.2831853 / f32(BAND_SEGMENTS));
    let e = select(ff.fade.y, ff.fade.z, upper);
    let dir = vec3<f32>(cos(e) * cos(azimuth), cos(e) * sin(azimuth), sin(e));
    var clip = frame.view_proj * vec4<f32>(dir, 0.0);
    clip.z = clip.w - 0.05;
    var o: FarOut;
    o.position = clip;
    o.dir = dir;
    return o;
}

// Where the ray `dir` (unit, from the camera) meets the layer `height_msl` metres above sea
// level: the distance along it, or -1 where it does not (above the layer's horizon, or away
// from a level layer). The sphere of `ray_to_shell` when the Earth is round, the plane at that
// height when it is flat (which has no far side). Chosen by `select`, never by a branch on
// `rc`: lavapipe specialises a shader on the values of the uniforms its branches test and keeps
// every copy, and `rc` (the camera's distance from the Earth's centre) is new every frame of a
// climb or a descent: the process grew 3.4 MB a drawn frame (tests/memory.rs).
fn ray_to_layer(dir: vec3<f32>, height_msl: f32, far_side: bool) -> f32 {
    let rc = frame.sky_horizon_rgb.w;
    let above = ff.lit_rgb.w - height_msl;
    let t_flat = -above / dir.z;
    let flat = select(-1.0, t_flat, t_flat > 0.0 && abs(dir.z) > 1e-6 && !far_side);
    return select(ray_to_shell(dir, max(rc, 1.0), above, far_side), flat, rc <= 0.0);
}

// Where the ray `dir` meets the sphere of radius `rc - above` about the Earth's centre
// (0, 0, -rc), `above` metres below the camera (negative: above it), or -1. From above a ray
// that goes down through a round layer comes up through it again beyond its horizon (past
// 330 km for a layer 8.7 km below: where a pilot sees far clouds' undersides through the gaps
// of nearer ones, out to `sqrt(2 R h) + sqrt(2 R c)`); `far_side` asks for that crossing, unless
// the ray meets the sea first.
fn ray_to_shell(dir: vec3<f32>, rc: f32, above: f32, far_side: bool) -> f32 {
    let b = rc * dir.z;
    // rc^2 - r^2, with the difference of the radii exact.
    let k = above * (2.0 * rc - above);
    let disc = b * b - k;
    if (disc < 0.0) {
        return -1.0;
    }
    let root = sqrt(disc);
    if (above > 0.0 && far_side) {
        // The sea, if the ray meets it before it comes up through the layer again.
        let camera = ff.lit_rgb.w;
        let k_sea = camera * (2.0 * rc - camera);
        let disc_sea = b * b - k_sea;
        let t = -b + root;
        let sea = select(1.0e12, k_sea / (-b + sqrt(max(disc_sea, 0.0))), disc_sea >= 0.0);
        return select(-1.0, t, b < 0.0 && t < sea);
    }
    if (above > 0.0) {
        // From above: the nearer crossing, where the ray goes down.
        return select(-1.0, k / (-b + root), b < 0.0);
    }
    if (far_side) {
        return -1.0;
    }
    // From below: the way out through the shell above.
    return select(-b + root, -k / (b + root), b > 0.0);
}

// The flat frame's horizontal offset of a camera-relative point on the round Earth (the
// inverse of `earth_curved`'s horizontal part: the arc along the Earth). By `select`, as
// `ray_to_layer`.
fn flat_offset(p: vec3<f32>) -> vec2<f32> {
    let rc = frame.sky_horizon_rgb.w;
    let h = length(p.xy);
    let arc = p.xy * (rc * atan2(h, rc + p.z) / max(h, 1.0e-6));
    return select(arc, p.xy, rc <= 0.0 || h <= 0.0);
}

fn hash2(c: vec2<i32>) -> f32 {
    var h = u32(c.x) * 747796405u ^ u32(c.y) * 2891336453u;
    h = (h ^ (h >> 16u)) * 73244475u;
    h = h ^ (h >> 16u);
    return f32(h & 0xffffu) / 65535.0;
}

// Value noise with a period of `period` cells, a power of two (so the world-anchored pattern
// wraps exactly; the wrap a mask, not an integer division, which a software rasterizer's
// vector units do one lane at a time).
fn value_noise(p: vec2<f32>, period: i32) -> f32 {
    let i = vec2<i32>(floor(p));
    let f = fract(p);
    let u = f * f * (3.0 - 2.0 * f);
    let m = vec2<i32>(period - 1);
    let i0 = i & m;
    let i1 = (i + vec2<i32>(1)) & m;
    let a = hash2(i0);
    let b = hash2(vec2<i32>(i1.x, i0.y));
    let c = hash2(vec2<i32>(i0.x, i1.y));
    let d = hash2(i1);
    return mix(mix(a, b, u.x), mix(c, d, u.x), u.y);
}

// One octave of value noise, cells of `cell_m` (a power of two times the noise's period over
// it), faded to its mean where a pixel's footprint on the layer, `footprint_m`, no longer
// resolves it (far out and at a slant), which saves its four hashes there and keeps it from
// shimmering. (A branch on the pixel's own footprint, not on a uniform.)
// `lo`, `hi`: the footprints, in cells, over which it fades (0.5 and 1 for the cover's noise).
fn octave(
    world: vec2<f32>,
    cell_m: f32,
    shift: vec2<f32>,
    footprint_m: f32,
    lo: f32,
    hi: f32,
) -> f32 {
    let keep = 1.0 - smoothstep(lo, hi, footprint_m / cell_m);
    var v = 0.5;
    if (keep > 0.0) {
        let cells = i32(round(ff.heights.w / cell_m));
        v = mix(0.5, value_noise(world / cell_m + shift, cells), keep);
    }
    return v;
}

// Three octaves at `scale_m`, over the world point `world` (metres in the noise's period), each
// faded where the pixel does not resolve it (`octave`: the finest beyond about 200 km from
// FL350 at full resolution for the heaped layers' lumps).
fn cloud_noise(world: vec2<f32>, scale_m: f32, footprint_m: f32) -> f32 {
    var n = 0.5 * octave(world, scale_m, vec2<f32>(0.0), footprint_m, 0.5, 1.0);
    n += 0.3 * octave(world, scale_m * 0.5, vec2<f32>(17.3, 5.1), footprint_m, 0.5, 1.0);
    return n + 0.2 * octave(world, scale_m * 0.25, vec2<f32>(3.7, 41.9), footprint_m, 0.5, 1.0);
}

// The share of `cloud_noise`'s spread a pixel of `footprint_m` still resolves: 1 where every
// octave is kept, less as `octave` fades them to their mean (the octaves' weights 0.5, 0.3, 0.2
// added in quadrature).
fn noise_spread(scale_m: f32, footprint_m: f32) -> f32 {
    let cells = footprint_m / (scale_m * vec3<f32>(1.0, 0.5, 0.25));
    let kept = vec3<f32>(1.0) - smoothstep(vec3<f32>(0.5), vec3<f32>(1.0), cells);
    return length(vec3<f32>(0.5, 0.3, 0.2) * kept) / length(vec3<f32>(0.5, 0.3, 0.2));
}

// How much of a layer of cover `cover` the noise `n` (`cloud_noise`, whose spread a pixel
// resolves `spread` of) makes cloud, over its soft edge `soft`: the noise above `threshold`
// (`cover_threshold`), which leaves `cover` of it (its three octaves are near normal, of 0.133 spread; a logistic of
// 0.087 fits their quantiles from 5% to 95% within 0.02 of cover), the threshold and the edge
// closer to the mean as octaves fade, and the cover itself where a pixel resolves none: a
// fixed threshold made a layer of three quarters cover 0.86 of it, and made any layer over
// half cover whole once its noise faded far out.
fn cover_cut(n: f32, cover: f32, threshold: f32, spread: f32, soft: f32) -> f32 {
    let s = max(spread, 0.05);
    let cut = smoothstep(threshold - soft * s, threshold + soft * s, n);
    return select(mix(cover, cut, smoothstep(0.1, 0.4, spread)), 1.0, cover > 0.97);
}

// The threshold of `cover_cut` for `cover` where a pixel resolves `spread` of the noise.
fn cover_threshold(cover: f32, spread: f32) -> f32 {
    let c = clamp(cover, 0.02, 0.98);
    return 0.5 - 0.087 * max(spread, 0.05) * log(c / (1.0 - c));
}

// 32 random bits of a lattice cell (and a salt), for four 8-bit values of one puff.
fn hash_u32(c: vec2<i32>, salt: u32) -> u32 {
    var h = (u32(c.x) * 747796405u) ^ (u32(c.y) * 2891336453u) ^ (salt * 2246822519u);
    h = (h ^ (h >> 16u)) * 73244475u;
    h = (h ^ (h >> 16u)) * 73244475u;
    return h ^ (h >> 16u);
}

// Cells of the walk along a pixel's ray in the heaped layer, at most (from FL350 about 4 at the
// hand-over band; where the slab is crossed at a shallower slant, the puffs are faded out
// before the walk would need more: `PUFF_PATH_CELLS`).
const PUFF_STEPS: i32 = 12;
// The longest path through the layer, in cells, on which the puffs are drawn whole: the walk
// crosses at most `sqrt(2)` times as many cells and two more.
const PUFF_PATH_CELLS: f32 = 6.0;
// The share of a puff's height below its widest.
const PUFF_WAIST: f32 = 0.3;

// The heaped layer's clouds one by one where a pixel resolves them, as the near cumulus' sprites
// show them: a lattice of cells of `cell_m` (`heaped_scale_m`) over the world, each cell with one
// puff or none, there with the chance that the cover `cover` asks, its diameter between the
// cumulus' smallest and largest (`ff.puffs`, from config/cloud_types.toml), larger with the cover
// where they cannot cover it at their own size, its centre anywhere in its cell (no row of the
// lattice shows: one point strewn a cell); each an ellipsoid cut flat below its middle on the
// layer's base, as tall as its diameter allows up to the layer's top. The ray `d` (unit, in the
// local frame at the point `o`: world metres in the noise's period, and metres above sea level)
// crosses the slab `base..top`; it is walked through the cells of the lattice offset by half a
// cell, whose corners are the primary cells' centres: a puff reaches no farther than half a cell
// from its centre, so the four primary cells about a walked cell hold every puff the ray can meet
// there, and each puff is taken in the one step where the ray passes nearest it (front to back,
// near enough). Each puff met is lit on its sunward side and on top, shaded on its flat underside,
// its outline and light lumpy with `bumps` (the pixel's cauliflowers, -0.5 to 0.5), its outline
// softened over `edge_m` (a pixel's width there). Premultiplied colour (before the haze) and alpha.
fn heaped_puffs(
    o: vec3<f32>,
    d: vec3<f32>,
    base: f32,
    top: f32,
    cover: f32,
    cell_m: f32,
    edge_m: f32,
    bumps: f32,
) -> vec4<f32> {
    // Where the ray is in the slab: from its entry to its exit, both relative to `o`.
    let dz = select(min(d.z, -1.0e-4), max(d.z, 1.0e-4), d.z >= 0.0);
    let ta = (top - o.z) / dz;
    let tb = (base - o.z) / dz;
    let t0 = min(ta, tb);
    let length_m = max(ta, tb) - t0;
    let start = o + d * t0;
    // The walk (Amanatides and Woo) over the offset lattice, in cells.
    let q = start.xy / cell_m - vec2<f32>(0.5);
    let dq = d.xy / cell_m;
    var walked = vec2<i32>(floor(q));
    let step_c = vec2<i32>(select(vec2<f32>(-1.0), vec2<f32>(1.0), dq >= vec2<f32>(0.0)));
    let inv = 1.0 / max(abs(dq), vec2<f32>(1.0e-9));
    var next = (select(floor(q), floor(q) + vec2<f32>(1.0), dq >= vec2<f32>(0.0)) - q)
        * sign(dq) * inv;
    next = select(next, vec2<f32>(1.0e30), dq == vec2<f32>(0.0));
    let m = vec2<i32>(i32(round(ff.heights.w / cell_m)) - 1);
    // The chance a cell holds a puff, and the puffs' size, for this cover: the cumulus' own
    // sizes until every cell holds one, larger beyond, up to a cell (about 0.6 of the layer's
    // area; at a slant their sides close the rest).
    let share = ff.puffs.w;
    let chance = min(cover / share, 1.0);
    let grow = sqrt(max(cover / share, 1.0));
    let sun = frame.sun_dir.xyz;
    var acc = vec4<f32>(0.0);
    var t = 0.0;
    for (var k = 0; k < PUFF_STEPS; k++) {
        if (t > length_m || acc.a > 0.98) {
            break;
        }
        let t_out = min(next.x, next.y);
        for (var corner = 0; corner < 4; corner++) {
            let cell = walked + vec2<i32>(corner & 1, corner >> 1u);
            let h = hash_u32(cell & m, 1u);
            let u = vec4<f32>(
                f32(h & 255u),
                f32((h >> 8u) & 255u),
                f32((h >> 16u) & 255u),
                f32(h >> 24u),
            ) / 255.0;
            let size = min(mix(ff.puffs.x, ff.puffs.y, u.y) * grow, cell_m);
            let r = 0.5 * size;
            let height = max(min(top - base, size * ff.puffs.z), 0.2 * size);
            let centre = (vec2<f32>(cell) + u.zw) * cell_m;
            // The ray in the puff's frame, its height scaled so the puff is a sphere of `r`
            // (its outline `rb`, lumpy), widest a third of the way up (an ellipsoid cut below
            // its middle: a cumulus' steep sides over its flat base, not a dome's); `cut`: the
            // base in the scaled frame.
            let squash = r / ((1.0 - PUFF_WAIST) * height);
            let cut = -r * PUFF_WAIST / (1.0 - PUFF_WAIST);
            let rb = min(r * (1.0 + 0.4 * bumps), 0.5 * cell_m);
            let p = vec3<f32>(start.xy - centre, (start.z - base - PUFF_WAIST * height) * squash);
            let v = vec3<f32>(d.xy, d.z * squash);
            let vv = dot(v, v);
            let tc = -dot(p, v) / vv;
            // Taken in the step the ray passes nearest it.
            let mine = clamp(tc, 0.0, length_m);
            let here = mine >= t && mine < t_out && u.x < chance;
            let closest = p + v * tc;
            let miss = length(closest);
            let inside = rb * rb - miss * miss;
            let half_chord = sqrt(max(inside, 0.0) / vv);
            let enter = p + v * (tc - half_chord);
            let leave = p + v * (tc + half_chord);
            // Above the base somewhere along the chord, softly.
            let highest = (select(closest.z, max(enter.z, leave.z), inside > 0.0) - cut) / squash;
            let a = smoothstep(rb + 0.5 * edge_m, rb - 0.5 * edge_m, miss)
                * smoothstep(-0.5 * edge_m, 0.5 * edge_m, highest)
                * select(0.0, 1.0, here);
            // Lit where the ray meets it: on its body by the normal (sunward and upward
            // brighter), through the flat base from below shaded.
            let at = select(closest, enter, inside > 0.0);
            let n = normalize(vec3<f32>(at.xy, at.z * squash) + vec3<f32>(0.0, 0.0, 1.0e-3));
            let up = clamp((at.z - cut) / (rb - cut), 0.0, 1.0);
            let lit = clamp(0.5 * up + 0.6 * max(dot(n, sun), 0.0) + 0.5 * bumps - 0.2, 0.0, 1.0);
            let light = select(lit, 0.0, at.z < cut && d.z > 0.0);
            let rgb = mix(ff.shade_rgb.rgb, ff.lit_rgb.rgb, light);
            acc += vec4<f32>(rgb, 1.0) * (a * (1.0 - acc.a));
        }
        // On to the next cell of the walk.
        let x_next = next.x < next.y;
        t = t_out;
        walked += select(vec2<i32>(0, step_c.y), vec2<i32>(step_c.x, 0), x_next);
        next += select(vec2<f32>(0.0, inv.y), vec2<f32>(inv.x, 0.0), x_next);
    }
    return acc;
}

// How much the grain (`far_layer`) lights and shades a sheet's and a heaped layer's tops. (A
// sheet's 1 km grain mottles it at 4 km too: at 0.12 the band from FL350 over San Antonio was
// twice as blotchy as the deck's sprites beside it, docs/src/horizon.md.)
const GRAIN_SHEET: f32 = 0.06;
const GRAIN_HEAPED: f32 = 0.5;
// A sheet's top in the sun, over its light: a broken sheet's, and a closed one's (a deck's
// sprites seen at a slant are lit tops only; measured against San Antonio's stratus deck from
// FL350 and FL450, docs/src/horizon.md), and how much its broad patches (`cloud_noise`) light
// and shade it.
const SHEET_TOP: f32 = 0.64;
const SHEET_TOP_CLOSED: f32 = 0.69;
const SHEET_RELIEF: f32 = 0.03;

// The look of layer `layer` (0 low, 1 high) from the map's texture layer of looks: the grey and
// the alpha of the top colour level of its most covering type (src/clouds/far_map.rs).
fn layer_look(looks: vec4<f32>, layer: i32) -> vec2<f32> {
    return select(looks.xy, looks.zw, layer == 1);
}

// One layer along the ray: premultiplied colour and the distance of its clouds.
struct FarHit {
    colour: vec4<f32>,
    distance_m: f32,
};

// `pixel`: the angle a pixel spans, radians.
fn far_layer(dir: vec3<f32>, pixel: f32, layer: i32, frag_xy: vec2<f32>, far_side: bool) -> FarHit {
    var none: FarHit;
    none.colour = vec4<f32>(0.0);
    none.distance_m = 0.0;
    var height = select(ff.heights.x, ff.heights.y, layer == 1);
    var t = -1.0;
    var cell = vec4<f32>(0.0);
    var ground_xy = vec2<f32>(0.0);
    // How much of a crossfade's cell shows (below).
    var presence = 1.0;
    // The layer's type's top level's grey and alpha (`layer_look`).
    var look = vec2<f32>(1.0);
    // Meet the layer at its mean height, read the map there, meet it again at the height the
    // map gives (twice: the layer's height varies slowly across the map). Rays that meet it
    // short of the hand-over band (the sprites' clouds), off the map, or where the map has no
    // cloud stop at once: the pass's cost is the band beyond.
    for (var k = 0; k < 2; k++) {
        t = ray_to_layer(dir, height, far_side);
        if (t <= 0.0) {
            return none;
        }
        ground_xy = flat_offset(dir * t);
        if (dot(ground_xy, ground_xy) < 0.8 * ff.noise_fade.z * ff.noise_fade.z) {
            return none;
        }
        let uv = (ground_xy - ff.centre_rel_size.xy) / ff.centre_rel_size.z + vec2<f32>(0.5);
        if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0))) {
            return none;
        }
        cell = textureSampleLevel(far_map, far_sampler, uv, layer, 0.0);
        look = layer_look(textureSampleLevel(far_map, far_sampler, uv, 4, 0.0), layer);
        // A new weather crossfades from the map before it (texture layers 2 and 3): where both
        // have cloud the cell goes from the one to the other; where one alone has, its clouds
        // fade in or out whole (seen this far off, a layer of any cover shows as one, so a
        // falling cover alone would keep them until it reached nothing).
        presence = 1.0;
        if (ff.fade.w < 1.0) {
            let before = textureSampleLevel(far_map, far_sampler, uv, layer + 2, 0.0);
            let look_before =
                layer_look(textureSampleLevel(far_map, far_sampler, uv, 5, 0.0), layer);
            let had = before.x > 0.01;
            if (had && cell.x > 0.01) {
                cell = mix(before, cell, ff.fade.w);
                look = mix(look_before, look, ff.fade.w);
            } else if (had) {
                cell = before;
                look = look_before;
                presence = 1.0 - ff.fade.w;
            } else {
                presence = ff.fade.w;
            }
        }
        if (cell.x <= 0.01) {
            return none;
        }
        let mid = 0.5 * (cell.y + cell.z);
        if (abs(mid - height) < 30.0) {
            break;
        }
        height = mid;
    }
    // The hand-over: in over the band where the sprites and the ring fade out; out over the
    // map's last two cells. Over a closed layer the sprites' deck hides what lies behind it
    // until it is gone, so the far field comes in under it over the band's first fifth: the
    // two crossfaded alike, each half faded in the band's middle, let a quarter of the ground
    // through there (a darker ring around the aircraft over an overcast, from FL350 and FL450).
    // Over a scattered layer the crossfade stays even, or the far field's clouds would show in
    // the sprites' gaps as well as theirs.
    let s = length(ground_xy);
    let start = ff.noise_fade.z;
    let end = ff.noise_fade.w;
    let closed = smoothstep(0.5, 1.0, cell.x);
    let band = mix(
        smoothstep(start, end, s),
        smoothstep(start, start + 0.2 * (end - start), s),
        closed,
    );
    let uv = (ground_xy - ff.centre_rel_size.xy) / ff.centre_rel_size.z + vec2<f32>(0.5);
    let edge = min(min(uv.x, uv.y), min(1.0 - uv.x, 1.0 - uv.y)) * ff.centre_rel_size.w;
    let weight = band * smoothstep(0.5, 2.0, edge) * ff.fade.x * presence;
    if (weight <= 0.0) {
        return none;
    }
    // The clouds: the noise over the threshold the cover sets (cover 1: all of it).
    let heaped = cell.w > 0.5;
    let scale = select(ff.heights.z, ff.shade_rgb.w, heaped);
    let world = ff.noise_fade.xy + (ground_xy - ff.centre_rel_size.xy);
    let sin_e = max(abs(dir.z), 0.01);
    // A pixel's footprint on the layer: the mean of its widths across and along the ray.
    let footprint = pixel * t / sqrt(sin_e);
    let n = cloud_noise(world, scale, footprint);
    // The grain of the near clouds' sprites in the light, not in the cover: a kilometre, the
    // finest the far field resolves at the hand-over band from FL350 in the half-resolution
    // cloud target, so that a sheet is not smooth where the deck's sprites were granular, nor a
    // heaped layer's lumps flat where the cumulus were cauliflowers.
    // (The footprint is `fwidth`'s, wider than a pixel: the grain, in the light only, fades a
    // little later than the cover's noise.)
    let grain_m = ff.shade_rgb.w * 0.5;
    let grain = octave(world, grain_m, vec2<f32>(29.1, 7.7), footprint, 1.0, 2.0) - 0.5;
    // Seen at a slant, heaped clouds' sides fill the gaps between them (a cumulus field runs
    // together towards the horizon): the cover of a slab `top - base` thick seen at the ray's
    // elevation, as if the sides hid the gaps at random (`1 - (1 - c)^k`).
    let sides = select(0.0, 0.5 * (cell.z - cell.y) / (ff.shade_rgb.w * sin_e), heaped);
    let cover = 1.0 - pow(1.0 - clamp(cell.x, 0.0, 1.0), 1.0 + min(sides, 8.0));
    // Heaped clouds' edges crisp (the near cumulus' are), sheets' soft.
    let soft = select(0.12, 0.03, heaped);
    let spread = noise_spread(scale, footprint);
    let threshold = cover_threshold(cover, spread);
    let density = cover_cut(n, cover, threshold, spread, soft);
    // Seen from above its top the sunlit side, from below its base the shade, in between mixed;
    // the lumps of a heaped layer lit on their tops and shaded at their edges, also where
    // their sides close the gaps at a slant (the threshold low: lit by the noise about its
    // middle, not white all over), with the grain's cauliflowers on them.
    let camera = ff.lit_rgb.w;
    // The far side of a layer below is seen from under it.
    let from_above = select(smoothstep(cell.y, cell.z, camera), 0.0, far_side);
    let relief = select(
        mix(SHEET_TOP, SHEET_TOP_CLOSED, smoothstep(0.9, 1.0, cell.x))
            + SHEET_RELIEF * (n - 0.5)
            + GRAIN_SHEET * grain,
        0.66 + 0.8 * (n - max(threshold, 0.4)) + GRAIN_HEAPED * grain,
        heaped,
    );
    // A sheet in its type's top level's grey, as its near sprites are drawn.
    let sheet_rgb = ff.sheet_ambient_rgb.rgb * look.x + ff.sheet_sun_rgb.rgb;
    let top_rgb = select(sheet_rgb, ff.lit_rgb.rgb, heaped);
    var rgb = mix(ff.shade_rgb.rgb, top_rgb * clamp(relief, 0.5, 1.1), from_above);
    // Where a pixel resolves them, a heaped layer's clouds one by one (`heaped_puffs`), as the
    // sprites draw them nearer: they take over from the noise as the puffs grow to a few
    // pixels (their width, or their height seen at the ray's slant, whichever is less).
    let size_m = 0.5 * (ff.puffs.x + ff.puffs.y);
    let tall_m = min(cell.z - cell.y, size_m * ff.puffs.z);
    let seen_m = min(size_m, size_m * sin_e + tall_m * sqrt(1.0 - sin_e * sin_e));
    // The ray in the layer's local frame at the point met (the round Earth's up there), and the
    // cells of the puffs' lattice it crosses in the layer: where that is more than the walk
    // takes (`PUFF_STEPS`, at a shallow slant), the noise again, so that no puff comes and goes
    // where the walk ends.
    let rc = frame.sky_horizon_rgb.w;
    let up = select(
        normalize(dir * t + vec3<f32>(0.0, 0.0, rc)),
        vec3<f32>(0.0, 0.0, 1.0),
        rc <= 0.0,
    );
    let sin_l = clamp(dot(dir, up), -1.0, 1.0);
    let cos_l = sqrt(1.0 - sin_l * sin_l);
    let path_cells = (cell.z - cell.y) * cos_l / (max(abs(sin_l), 1.0e-3) * ff.shade_rgb.w);
    let resolve = select(0.0, 1.0, heaped)
        * (1.0 - smoothstep(0.4, 0.8, pixel * t / seen_m))
        * (1.0 - smoothstep(PUFF_PATH_CELLS - 2.0, PUFF_PATH_CELLS, path_cells));
    var body = vec4<f32>(rgb * density, density);
    if (resolve > 0.0) {
        let along = dir.xy / max(length(dir.xy), 1.0e-6);
        let local = vec3<f32>(along * cos_l, sin_l);
        let puffs = heaped_puffs(
            vec3<f32>(world, height),
            local,
            cell.y,
            cell.z,
            clamp(cell.x, 0.0, 1.0),
            ff.shade_rgb.w,
            0.6 * pixel * t,
            octave(world, 0.2 * ff.shade_rgb.w, vec2<f32>(11.3, 2.9), pixel * t, 0.8, 1.6) - 0.5,
        );
        body = mix(body, puffs, resolve);
    }
    // As translucent as its type's near sprites' tops (an altostratus deck shows the ground
    // through it).
    var alpha = body.a * weight * look.y;
    rgb = body.rgb / max(body.a, 1.0e-6);
    // The altitude haze between the camera and the clouds (the flat frame's height: the true).
    let haze = haze_transmittance(t, height - camera);
    rgb = mix(frame.sky_horizon_rgb.rgb, rgb, haze);
    // Behind the host's scene: softly cut, as the sprites are.
    let p = dir * t;
    let cloud_m = (frame.view_proj * vec4<f32>(p, 1.0)).w;
    // Where the host drew nothing, nothing is in front, however far the clouds (its far plane
    // may be nearer than the horizon: 160 km in the shipped settings).
    var scene_m = scene_m_at(frag_xy);
    if (!SCENE_IN_METRES && is_background(scene_depth_at(frag_xy))) {
        scene_m = 1.0e9;
    }
    alpha *= clamp((scene_m - cloud_m) * frame.params.y, 0.0, 1.0);
    var hit: FarHit;
    hit.colour = vec4<f32>(rgb * alpha, alpha);
    hit.distance_m = cloud_m;
    return hit;
}

fn far_hit(i: FarOut) -> FarHit {
    let dir = normalize(i.dir);
    // In uniform control flow (the layers return early per pixel).
    let pixel = length(fwidth(dir));
    // The low layer's far side (beyond its horizon, seen through the gaps) behind its near side.
    let near_low = far_layer(dir, pixel, 0, i.position.xy, false);
    var beyond: FarHit;
    beyond.colour = vec4<f32>(0.0);
    beyond.distance_m = 0.0;
    if (near_low.colour.a < 0.99) {
        beyond = far_layer(dir, pixel, 0, i.position.xy, true);
    }
    var low = near_low;
    low.colour = near_low.colour + beyond.colour * (1.0 - near_low.colour.a);
    let low_weighted = near_low.distance_m * near_low.colour.a
        + beyond.distance_m * beyond.colour.a * (1.0 - near_low.colour.a);
    low.distance_m = low_weighted / max(low.colour.a, 1e-6);
    let high = far_layer(dir, pixel, 1, i.position.xy, false);
    // The nearer layer over the farther one.
    var front = low;
    var back = high;
    if (high.colour.a > 0.0 && (low.colour.a <= 0.0 || high.distance_m < low.distance_m)) {
        front = high;
        back = low;
    }
    var hit: FarHit;
    hit.colour = front.colour + back.colour * (1.0 - front.colour.a);
    let weighted = front.distance_m * front.colour.a
        + back.distance_m * back.colour.a * (1.0 - front.colour.a);
    hit.distance_m = weighted / max(hit.colour.a, 1e-6);
    return hit;
}

@fragment
fn fs_far_field(i: FarOut) -> @location(0) vec4<f32> {
    return far_hit(i).colour;
}

// Into the cloud target (`cloud_target.rs`): the colour and the distance of its clouds.
@fragment
fn fs_far_field_offscreen(i: FarOut) -> CloudOut {
    let hit = far_hit(i);
    return cloud_out(hit.colour, hit.distance_m);
}
