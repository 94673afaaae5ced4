// Pass `sky.sprite_build` (compute): builds the corners of a frame's sprites from the
// GPU-resident sprites into a vertex buffer the draw reads (`sprites.wgsl`). The sprites live on
// the GPU (written once per block); each frame the CPU sends only the draw list (one entry per
// block, back to front, its centre relative to the camera) and the cloud lists and sprite orders
// that changed. Each invocation builds one corner: the sprite's facing (camera facing, upright
// cylindrical base sprites, flat cirrus, the facing lock of Wang 3.3 with its angle fade), its
// quad cut to the part of its sheet cell the texture covers, Wang's equation (3) shading (ambient
// colour levels by height, directional shading groups; a deck by its depth as one slab), the
// forward-scattering rim, the formation / dissipation fade of Wang 4, and the fade where the
// clouds end. Built in a compute pass, not in the vertex shader: on the software rasteriser
// storage buffers read by a vertex shader cost memory every draw, and a compute pass runs on
// every core.

// Keep in sync with `GpuSprite` in src/render/gpu_types.rs.
struct Sprite {
    offset: vec3<f32>,
    // Width and height, half floats.
    size: u32,
    // The shading group centre's x and y, half floats.
    group_xy: u32,
    // Low: the group centre's z (half float); high: the rotation, a turn in 65,536 steps.
    group_z_rotation: u32,
    // Low: alpha_morph; high: radius fraction (16-bit fractions).
    morph_radius: u32,
    bits: u32,
};

// Keep in sync with `GpuCloud`.
struct Cloud {
    // xyz: centre from the block's; w: a heap's shaded base, metres above its base (0: none).
    centre_block: vec4<f32>,
    level_rgba: array<vec4<f32>, 5>,
    level_height: vec4<f32>,
    level4_radius_flat: vec4<f32>,
    // x: its flat base, metres from its centre (`FLOOR_NONE_M` for none); y: the factor on the
    // extinction through its cores (its type's optical density); zw: padding.
    floor_pad: vec4<f32>,
};

// Keep in sync with `GpuDrawBlock`.
struct DrawBlock {
    origin_rel: vec3<f32>,
    first: u32,
    list_base: u32,
    list_len: u32,
    fade_kind: u32,
    fade_progress: f32,
};

// Keep in sync with `GpuListCloud`.
struct ListCloud {
    cloud: u32,
    first: u32,
    order_base: u32,
    // Every how many of its sprites are built (0 or 1: all; the shadow map's far clouds).
    stride: u32,
};

// Keep in sync with `GpuLock`.
struct Lock {
    right: vec4<f32>,
    up: vec4<f32>,
    normal: vec3<f32>,
    sprite: u32,
};

// Keep in sync with `GpuSpriteView` (MAX_LOCKS).
struct SpriteView {
    sun_dir_camera_z: vec4<f32>,
    directional_ambient: vec4<f32>,
    mapping_g: vec4<f32>,
    forward_lock: vec4<f32>,
    upright_lifecycle: vec4<f32>,
    hl_phase: vec4<f32>,
    hl_sky: vec4<f32>,
    hl_deck: vec4<f32>,
    far_fade_layer_turn: vec4<f32>,
    locks: array<Lock, 128>,
};

@group(0) @binding(0) var<uniform> view: SpriteView;
// The frame's counts (blocks, locks, sprites) and its blocks. The counts bound loops, so they
// live here and not in the uniform: a software rasteriser that folds uniforms used as loop
// bounds into the shader (lavapipe does) would compile the shader again every frame.
struct Draws {
    counts: vec4<u32>,
    blocks: array<DrawBlock>,
};

@group(0) @binding(1) var<storage, read> draws: Draws;
@group(0) @binding(2) var<storage, read> lists: array<ListCloud>;
@group(0) @binding(3) var<storage, read> orders: array<u32>;
@group(1) @binding(0) var<storage, read> sprites: array<Sprite>;
@group(1) @binding(1) var<storage, read> clouds: array<Cloud>;
// Per sprite slot its Harris and Lastra light (src/render/sprites/cloud_light.rs): bytes 0, 1, 2 the
// sun's direct and total light and the skylight that reach it, fractions.
@group(1) @binding(2) var<storage, read> lights: array<u32>;

// One built corner. Keep in sync with `GpuSpriteVertex` in src/render/gpu_types.rs.
struct BuiltCorner {
    // xyz: metres from the camera; w: 1 drawn, 0 not (faded out).
    position_visible: vec4<f32>,
    uv: vec2<f32>,
    // x: how many sprites of its cloud it stands for (1 but in the shadow map's far clouds).
    stands_for: vec2<f32>,
    colour: vec4<f32>,
};

@group(2) @binding(0) var<storage, read_write> built: array<BuiltCorner>;
// x: the chunk's first sprite (a chunk of at most CHUNK sprites is built, then drawn).
@group(2) @binding(1) var<uniform> chunk: vec4<u32>;

// Keep in sync with `CHUNK` in src/render/sprites/build.rs.
const CHUNK: u32 = 32768u;

struct Facing {
    right: vec3<f32>,
    up: vec3<f32>,
    normal: vec3<f32>,
};

fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    return select(fallback, v / l, l > 0.0);
}

// Right/up axes facing a viewer along `normal`, world up kept up (east when straight above).
// Same as `facing_towards` in src/render/sprites/draw_list.rs (the CPU's copy starts a lock).
fn facing_towards(normal: vec3<f32>) -> Facing {
    let r = cross(vec3<f32>(0.0, 0.0, 1.0), normal);
    let right = select(vec3<f32>(1.0, 0.0, 0.0), normalize(r), dot(r, r) > 1e-6);
    return Facing(right, normalize_or(cross(normal, right), vec3<f32>(0.0)), normal);
}

// An upright sprite turns only about the vertical, so its bottom edge stays level.
fn upright_facing(to_cam: vec3<f32>) -> Facing {
    let normal = normalize_or(vec3<f32>(to_cam.xy, 0.0), vec3<f32>(0.0, 1.0, 0.0));
    let right = normalize_or(cross(vec3<f32>(0.0, 0.0, 1.0), normal), vec3<f32>(1.0, 0.0, 0.0));
    return Facing(right, vec3<f32>(0.0, 0.0, 1.0), normal);
}

// Where the clouds end (the farthest the view draws any at), a layer seen above the horizon would
// end in a line across the sky (the cirrus theme's veil, 60 km out: 6 degrees up): seen above the
// horizon, sprites fade out over the last stretch of that distance instead. Below the horizon (a
// deck from above) they reach it whole, the deck running on to the haze. `to_cam`: from the
// sprite to the view's camera.
// While the far field is drawn (`hl_deck.z`), every sprite fades over its hand-over band, below
// the horizon too, as the far field fades in there (`shaders/far_field.wgsl`); a deck's sprites
// take the light of its side the camera sees as they fade (`build_sprite`).
fn far_fade(to_cam: vec3<f32>) -> f32 {
    let dist = length(to_cam);
    let above_horizon = max(smoothstep(0.0, 0.02, -to_cam.z / max(dist, 1.0)), view.hl_deck.z);
    let fade = view.far_fade_layer_turn;
    return 1.0 - above_horizon * smoothstep(fade.x, max(fade.y, fade.x + 1.0), dist);
}

// A layer sprite (not flat, wider than tall: the puffs of stratus, nimbostratus, altostratus,
// stratocumulus and fog) is a pancake, wide across and thin in height. Its quad's height and
// its turn about the view ray, seen from `to_cam` (from the sprite to the camera): from the side
// the short strip it was made as; from steeply above or below its outline rounds to its width
// (an oblate puff's silhouette), and its turn goes over to one of its own (hashed from its place
// in the cloud). A camera-facing quad turned by the camera alone lays every puff across the line
// to the nadir, and a deck seen from above showed rings around it. The turn is weighted by the
// view angle alone, so a sprite turns smoothly as the camera moves.
fn layer_quad(width: f32, height: f32, rotation: f32, offset: vec3<f32>, to_cam: vec3<f32>)
    -> vec2<f32> {
    let sin_e = abs(to_cam.z) / max(length(to_cam), 1e-3);
    let cos_e = sqrt(max(1.0 - sin_e * sin_e, 0.0));
    let quad_height = length(vec2<f32>(height * cos_e, width * sin_e));
    var h = bitcast<u32>(offset.x) * 747796405u ^ bitcast<u32>(offset.y) * 2891336453u;
    h = (h ^ (h >> 16u)) * 73244475u;
    // Within a quarter turn either way: enough to lay the puffs every way (a pancake's outline
    // is the same turned half round), and a puff passing overhead turns by at most that.
    let own_turn = (f32((h ^ (h >> 16u)) & 0xffffu) / 65536.0 - 0.5) * 3.141592654;
    let turn = view.far_fade_layer_turn;
    return vec2<f32>(quad_height, rotation + own_turn * smoothstep(turn.z, turn.w, sin_e));
}

// Wang 5.1: the ambient colour of the cloud's five levels at a height above mean sea level:
// piecewise linear between the levels (heights ascending), held beyond the first and the last.
// Written as a chain of mixes, each level's weight clamped, with no loop or indexed array: the
// software rasteriser runs it on every lane at once.
fn level_colour(c: Cloud, h: f32) -> vec4<f32> {
    let heights = vec4<f32>(c.level_height.yzw, c.level4_radius_flat.x);
    let lows = c.level_height;
    let spans = heights - lows;
    let t = select(vec4<f32>(1.0), clamp((h - lows) / spans, vec4<f32>(0.0), vec4<f32>(1.0)),
        spans > vec4<f32>(0.0));
    // A level is reached once h passes its height, even where a span is zero.
    let w = select(t, vec4<f32>(0.0), vec4<f32>(h) <= lows);
    var colour = mix(c.level_rgba[0], c.level_rgba[1], w.x);
    colour = mix(colour, c.level_rgba[2], w.y);
    colour = mix(colour, c.level_rgba[3], w.z);
    return mix(colour, c.level_rgba[4], w.w);
}

// Wang 5.2's biased mapping of dot(vertex - group centre, sun) to Cmin / Cmedian / Cmax.
fn directional_percent(dot_sun: f32) -> f32 {
    let d = clamp(dot_sun, -1.0, 1.0);
    let m = view.mapping_g;
    return select(m.y + (m.z - m.y) * d, m.y + (m.y - m.x) * d, d < 0.0);
}

// A deck seen from below gets the sun only diffused through its whole thickness: evenly, with
// none of the shading groups' sunlit and shaded sides. How much of Wang's directional shading
// gives way to its even median: 0 seen from above the deck's top, 1 - exp(-thickness / (depth x
// sin(sun elevation))) from below its base (what of the direct sun the deck stops), in between
// from inside. Per sprite, not per corner, so a near sprite's corners light alike. 0 for a
// cloud lit from every side.
fn deck_evenness(c: Cloud, camera_z: f32, sun_z: f32) -> f32 {
    let depth = c.level4_radius_flat.w;
    if (depth <= 0.0) {
        return 0.0;
    }
    let base = c.level_height.x;
    let top = c.level4_radius_flat.x;
    let thickness = max(top - base, 1.0);
    let stopped = 1.0 - exp(-thickness / (depth * max(sun_z, 0.05)));
    let below = clamp((top - camera_z) / thickness, 0.0, 1.0);
    return stopped * below;
}

// How deep `height_msl` lies in a deck: its depth below the top (0 at and above it) over the
// deck's `sunlit_depth_m`, the depth at which the direct sun falls to 1/e along its slanted path.
fn deck_depth(c: Cloud, height_msl: f32) -> f32 {
    return max(c.level4_radius_flat.x - height_msl, 0.0) / c.level4_radius_flat.w;
}

// The part of the direct sun that reaches `deck_depth` (Beer's law along the slanted path). What
// Wang's directional shading of a deck's corner goes by instead of the side of its cloud it is on.
fn deck_sunlit(depth: f32, sun_z: f32) -> f32 {
    return exp(-depth / max(sun_z, 0.05));
}

// Light scattered forward towards the eye: a Henyey-Greenstein lobe, strongest on the rim.
fn forward_percent(view_dir: vec3<f32>, rim: f32) -> f32 {
    let g = view.mapping_g.w;
    let cos_sun = clamp(dot(view_dir, view.sun_dir_camera_z.xyz), -1.0, 1.0);
    let base = (1.0 - g) * (1.0 - g) / (1.0 + g * g - 2.0 * g * cos_sun);
    let lobe = base * sqrt(base);
    let r = clamp(rim, 0.0, 1.0);
    return view.forward_lock.x * lobe * r * r * r * r;
}

// Harris and Lastra's light (as `lights` packs it: direct sun, total sun, sky) at `depth` in a
// deck taken as a homogeneous slab (`deck_depth`), as Wang's deck above: the same at every place
// and per corner, where the CPU's light through each lattice cell alone would light the cell's
// sunward side. The light scattered forward on the way fades at `hl_deck.x` of that rate (the
// recurrence of `HarrisLastra::light` through many faint particles); the sky's comes straight
// down.
fn deck_harris_lastra(depth: f32, sun_z: f32) -> vec4<f32> {
    let direct = deck_sunlit(depth, sun_z);
    let kept = view.hl_deck.x;
    return vec4<f32>(direct, pow(direct, kept), exp(-kept * depth), 0.0);
}

// Harris and Lastra 2001: the light a sprite scatters towards the eye. `light` is its packed
// light (direct sun, total sun, sky); the direct sun goes through the phase function (a
// Henyey-Greenstein lobe plus an isotropic rest), the light scattered forward on its way in and
// the skylight count as isotropic; plus the ambient term. Same as HarrisLastra::phase.
fn harris_lastra_rgb(light: vec4<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    let hl = view.hl_phase;
    let g = hl.y;
    let cos_sun = clamp(dot(view_dir, view.sun_dir_camera_z.xyz), -1.0, 1.0);
    let base = 1.0 + g * g - 2.0 * g * cos_sun;
    let hg = (1.0 - g * g) / (base * sqrt(base));
    let phase = (1.0 - hl.z) + hl.z * hg;
    let sun = view.directional_ambient.rgb * hl.w * (light.x * phase + max(light.y - light.x, 0.0));
    return sun + view.hl_sky.rgb * light.z + vec3<f32>(view.hl_sky.w);
}

// Wang 4: forming, the inner sprites fade in first; dissipating, the outer ones go first.
// Same as src/clouds/lifecycle.rs.
fn lifecycle_alpha(kind: u32, progress: f32, radius_fraction: f32) -> f32 {
    let inner_fraction = view.upright_lifecycle.z;
    let p = clamp(progress, 0.0, 1.0);
    if (kind == 1u) {
        if (radius_fraction <= inner_fraction) {
            return min(p / 0.5, 1.0);
        }
        let start = 0.5 * view.upright_lifecycle.w;
        return clamp((p - start) / (1.0 - start), 0.0, 1.0);
    }
    if (kind == 2u) {
        if (radius_fraction > inner_fraction) {
            return 1.0 - min(p / 0.5, 1.0);
        }
        let s = max((p - 0.5) / 0.5, 0.0);
        return 1.0 - min(s * (1.0 + radius_fraction / inner_fraction), 1.0);
    }
    return 1.0;
}

// The inset of a quad's texture in its cell, a fraction of the cell: keeps mips apart.
const CELL_INSET: f32 = 1.0 / 64.0;

// The sheet's texture coordinate of a point of cell `cell`'s quad (0..1 across, v down).
fn cell_uv(cell: u32, corner: vec2<f32>) -> vec2<f32> {
    let c = min(cell, 15u);
    let uv = vec2<f32>(f32(c % 4u), f32(c / 4u)) + vec2<f32>(CELL_INSET) +
        corner * (1.0 - 2.0 * CELL_INSET);
    return uv * 0.25;
}

// The part of cell `cell`'s quad its texture covers (x: left, y: top, z: right, w: bottom, 0..1
// across the quad, v down): `CELL_CROP` (src/render/sprites/sheet_crop.rs, put in front of this file
// when the pipeline is built) holds it as fractions of the cell, which the inset maps onto the
// quad. The quad is cut to it: its transparent margins cost fragments and show nothing.
fn cell_crop(cell: u32) -> vec4<f32> {
    let crop = (CELL_CROP[min(cell, 15u)] - vec4<f32>(CELL_INSET)) / (1.0 - 2.0 * CELL_INSET);
    return clamp(crop, vec4<f32>(0.0), vec4<f32>(1.0));
}

// The block of the draw list holding the frame's sprite `k`: the last whose `first` is <= k.
fn block_of(k: u32) -> u32 {
    var lo = 0u;
    var hi = draws.counts.x;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (draws.blocks[mid].first <= k) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The cloud of a block's list holding its sprite `k`: the last whose `first` is <= k.
fn cloud_of(b: DrawBlock, k: u32) -> u32 {
    var lo = b.list_base;
    var hi = b.list_base + b.list_len;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (lists[mid].first <= k) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The locked facing of sprite `slot`, or `fallback` if it has none.
fn locked_facing(slot: u32, fallback: Facing) -> Facing {
    for (var i = 0u; i < draws.counts.y; i++) {
        let l = view.locks[i];
        if (l.sprite == slot) {
            return Facing(l.right.xyz, l.up.xyz, l.normal);
        }
    }
    return fallback;
}

// Builds the four corners of the frame's sprite `k` (in drawing order) into `built[at..at + 4]`:
// what the corners share (finding the sprite, its facing, lock and fades) is done once.
fn build_sprite(k: u32, at: u32) {
    let b = draws.blocks[block_of(k)];
    // An entry may be a part of its block's cloud list (the clouds of two blocks the camera
    // stands between are drawn interleaved, `draw_entries` in src/render/sprites/draw_list.rs): its
    // list's sprite counts run on from the part's first cloud's.
    let in_block = k - b.first + lists[b.list_base].first;
    let entry = lists[cloud_of(b, in_block)];
    // In the cloud's order, or (the shadow map, `hl_deck.y`) in its slots' own: sums that do not
    // change with the camera's sort. A `select`, not an `if` on the uniform (see below).
    let stride = max(entry.stride, 1u);
    let in_order = entry.order_base + (in_block - entry.first) * stride;
    let slot = select(orders[in_order], in_order, view.hl_deck.y > 0.5);
    let s = sprites[slot];
    let cloud = clouds[entry.cloud];
    let flat_radius = cloud.level4_radius_flat;
    let centre_rel = b.origin_rel + cloud.centre_block.xyz;
    let offset = s.offset;
    let size = unpack2x16float(s.size);
    let width = size.x;
    let height = size.y;
    let group = vec3<f32>(
        unpack2x16float(s.group_xy),
        unpack2x16float(s.group_z_rotation & 0xffffu).x,
    );
    let rotation = f32(s.group_z_rotation >> 16u) * (6.283185307 / 65536.0);
    let morph_radius = unpack2x16unorm(s.morph_radius);
    let cam_local = -centre_rel;
    let to_cam = cam_local - offset;
    let radius = 0.5 * max(width, height);

    // Facing: camera facing, upright (fading seen from steeply above or below), flat, or locked.
    var face = facing_towards(normalize_or(to_cam, vec3<f32>(0.0, 1.0, 0.0)));
    var alpha = 1.0;
    if ((s.bits & 256u) != 0u) {
        face = upright_facing(to_cam);
        let sin_elevation = abs(to_cam.z / max(length(to_cam), 1e-3));
        let fade = view.upright_lifecycle;
        alpha = 1.0 - clamp((sin_elevation - fade.x) / max(fade.y - fade.x, 1e-4), 0.0, 1.0);
    }
    if (flat_radius.z > 0.5) {
        face = Facing(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    } else if (length(to_cam) < view.forward_lock.y * radius) {
        // Wang 3.3: inside half the radius the facing stays as it was when the camera came in;
        // the sprite fades as the angle between that facing and the camera grows.
        face = locked_facing(slot, face);
        let cos_angle = abs(dot(face.normal, normalize_or(to_cam, face.normal)));
        let lock = view.forward_lock;
        alpha *= clamp((cos_angle - lock.w) / max(lock.z - lock.w, 1e-4), 0.0, 1.0);
    }
    // Bit 4 of `fade_kind`: a distant block (a storm cell beyond the cloud field,
    // `DISTANT_BLOCK` in src/render/sprites/draw_list.rs), drawn however far; while the far field is
    // drawn (`hl_deck.z`) it fades in over the hand-over band as the near sprites fade out.
    let morph = morph_radius.x * lifecycle_alpha(b.fade_kind & 3u, b.fade_progress, morph_radius.y);
    let faded = far_fade(to_cam);
    alpha *= select(faded, 1.0 - view.hl_deck.z * faded, (b.fade_kind & 4u) != 0u);
    if (!(alpha > 0.0 && morph > 0.0)) {
        // Faded out: the draw puts its corners outside the clip volume.
        for (var c = 0u; c < 4u; c++) {
            built[at + c].position_visible = vec4<f32>(0.0);
        }
        return;
    }

    var quad_height = height;
    var turn = rotation;
    if (flat_radius.z <= 0.5 && (s.bits & 256u) == 0u && width > height) {
        let layer = layer_quad(width, height, rotation, offset, to_cam);
        quad_height = layer.x;
        turn = layer.y;
    }
    let sc = vec2<f32>(sin(turn), cos(turn));
    let right = face.right * sc.y + face.up * sc.x;
    let up = face.up * sc.y - face.right * sc.x;
    let light = view.directional_ambient;
    let sun = normalize_or(view.sun_dir_camera_z.xyz, vec3<f32>(0.0));
    let cell = s.bits & 15u;
    let evenness = deck_evenness(cloud, view.sun_dir_camera_z.w, sun.z);
    // A deck (its `sunlit_depth_m` set) is lit as one slab by both models, below.
    let deck = cloud.level4_radius_flat.w > 0.0;
    // Keep in sync with `SPRITE_PRECIPITATION` in src/render/gpu_types.rs.
    let rain = (s.bits & 512u) != 0u;
    let harris_lastra = view.hl_phase.x > 0.5;
    let hl_light = unpack4x8unorm(lights[slot]);
    let crop = cell_crop(cell);
    // Over the hand-over band a deck's sprites, fading alike, are lit more and more as its side
    // the camera sees (its top from above, its base from below), as the far field's sheet is:
    // the sprites its top had hidden show through as they fade, and lit by their own depth they
    // made the band a ring 1.5 to 2/255 darker than both sides (San Antonio from FL350).
    let deck_top = cloud.level4_radius_flat.x;
    let deck_span = max(deck_top - cloud.level_height.x, 1.0);
    let below_top = clamp((deck_top - view.sun_dir_camera_z.w) / deck_span, 0.0, 1.0);
    let seen_side = deck_top - deck_span * below_top;
    let to_side = select(0.0, (1.0 - faded) * view.hl_deck.z, deck);
    for (var c = 0u; c < 4u; c++) {
        // The corner on the cut quad: texture coordinates across it (v down), and where it is.
        let across = mix(crop.xy, crop.zw, vec2<f32>(f32(c & 1u), f32(c >> 1u)));
        let p = offset + right * ((across.x - 0.5) * width) + up * ((0.5 - across.y) * quad_height);
        // Wang eq. (3): (ambient + directional) x alpha_morph; the texture is the fragment's.
        let height_msl = mix(view.sun_dir_camera_z.w + centre_rel.z + p.z, seen_side, to_side);
        let ambient = level_colour(cloud, height_msl);
        let view_dir = normalize_or(p - cam_local, vec3<f32>(0.0));
        let rim = length(p) / flat_radius.y;
        let group_dir = normalize_or(p - group, vec3<f32>(0.0));
        // A deck is lit as one slab, not cell by cell: the direct sun falls off with the depth
        // below its top, the same at every place, so its lattice of clouds shows no sunlit and
        // shaded side per cell (a grid seen from above). Deeper in, the sun diffused through the
        // deck is left: the even median it shows from below.
        let depth = select(0.0, deck_depth(cloud, height_msl), deck);
        var wang = directional_percent(dot(group_dir, sun)) + forward_percent(view_dir, rim);
        if (deck) {
            let sunlit = deck_sunlit(depth, sun.z);
            wang = directional_percent(sunlit) + forward_percent(view_dir, sunlit);
        }
        // A heap's shaded base: the body above hides the sun from its lowest part.
        let shaded_base = cloud.centre_block.w;
        let above_base = height_msl - cloud.level_height.x;
        let sun_here = select(1.0, smoothstep(0.0, shaded_base, above_base), shaded_base > 0.0);
        let directional = mix(wang, view.mapping_g.y, evenness) * light.rgb * sun_here;
        // Both models' light, one chosen by `select`, not by an `if` on the view uniform:
        // lavapipe (Mesa 22) specialises a shader on the uniforms that decide a branch as it
        // runs it, and kept every copy: about 0.9 MB a frame without bound (tests/memory.rs).
        var received = hl_light;
        if (deck) {
            received = deck_harris_lastra(depth, sun.z);
        }
        let lit = select(
            ambient.rgb * light.w + directional,
            harris_lastra_rgb(received, view_dir),
            harris_lastra,
        );
        let base_rgb = select(
            ambient.rgb * light.w,
            view.hl_sky.rgb * received.z + vec3<f32>(view.hl_sky.w),
            harris_lastra,
        );
        // Rain and snow hang in the cloud's shadow: its base colour, dimmer and greyer, no sun.
        let shade = base_rgb * 0.6;
        let rain_rgb = mix(shade, vec3<f32>(dot(shade, vec3<f32>(0.3, 0.59, 0.11))), 0.5);
        // Texture v runs down the sheet: the top of the sprite is v = 0.
        built[at + c] = BuiltCorner(
            vec4<f32>(centre_rel + p, 1.0),
            cell_uv(cell, across),
            // x: the stride its cloud was built at (one sprite stands for that many).
            vec2<f32>(f32(stride), 0.0),
            vec4<f32>(select(lit, rain_rgb, rain), ambient.a * morph * alpha),
        );
    }
}

// Sprite `id` of the chunk (rows of 65,535 x 64 invocations), its four corners.
@compute @workgroup_size(64)
fn cs_build(@builtin(global_invocation_id) id: vec3<u32>) {
    let local = id.x + id.y * (65535u * 64u);
    let k = chunk.x + local;
    if (local >= CHUNK || k >= draws.counts.z) {
        return;
    }
    build_sprite(k, local * 4u);
}

// Keep in sync with `SPRITE_BASE` in src/render/gpu_types.rs.
const SPRITE_BASE: u32 = 1024u;
// A sprite's dense core and a base sprite's (src/clouds/core.rs `CORE_HALF_EXTENT`,
// `BASE_HALF_EXTENT`): fractions of its full width and height from its centre.
const CORE_HALF_EXTENT: f32 = 0.35;
const BASE_HALF_EXTENT: f32 = 0.5;

// `p` (metres, from a core's centre) in the core's unit sphere: turned by `along` (its first
// horizontal axis), divided by its semi-axes. Same as `SpriteCore::unit` in src/clouds/core.rs.
fn core_unit(p: vec3<f32>, along: vec2<f32>, semi: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(p.xy, along), along.x * p.y - along.y * p.x, p.z) / semi;
}

// The shadow map's corners (`cs_build_cores`): sprite `k` of the shadow view (in its slots'
// order) as its dense core, what every probe of the air data asks (src/clouds/core.rs: an
// ellipsoid of `CORE_HALF_EXTENT` of its size, a flat cloud's turned with it; a base sprite's
// as wide as it is, with the column under it down to the cloud's base; nothing below the
// base). The quad faces the map's sun (`sun_dir_camera_z`) and holds the core's outline, and
// each corner carries what the shadow pass (`cloud_shadow.wgsl`) needs to find the length of
// its ray inside the core: `colour.xyz` the corner in the core's unit sphere (linear across
// the quad, so each fragment gets its own point), `uv` and `stands_for.y` the ray's direction
// in the unit sphere, `colour.w` the base in the unit sphere's z, `stands_for.x` the optical
// depth's weight (the formation or dissipation fade, the probes' `lifecycle::alpha_at`, times
// the cloud's optical density, times how many sprites it stands for), negative for a base
// sprite. Rain and snow are not cloud.
fn build_core(k: u32, at: u32) {
    let b = draws.blocks[block_of(k)];
    let in_block = k - b.first + lists[b.list_base].first;
    let entry = lists[cloud_of(b, in_block)];
    let stride = max(entry.stride, 1u);
    let slot = entry.order_base + (in_block - entry.first) * stride;
    let s = sprites[slot];
    let cloud = clouds[entry.cloud];
    let centre_rel = b.origin_rel + cloud.centre_block.xyz + s.offset;
    let size = unpack2x16float(s.size);
    let rotation = f32(s.group_z_rotation >> 16u) * (6.283185307 / 65536.0);
    let radius_fraction = unpack2x16unorm(s.morph_radius).y;
    let fade = lifecycle_alpha(b.fade_kind & 3u, b.fade_progress, radius_fraction);
    let rain = (s.bits & 512u) != 0u;
    if (rain || !(fade > 0.0)) {
        for (var c = 0u; c < 4u; c++) {
            built[at + c].position_visible = vec4<f32>(0.0);
        }
        return;
    }
    // Keep in sync with `SpriteCore::new` and `SpriteCore::of` in src/clouds/core.rs.
    let flat = cloud.level4_radius_flat.z > 0.5;
    var semi = vec3<f32>(size.x, size.x, size.y) * CORE_HALF_EXTENT;
    var along = vec2<f32>(1.0, 0.0);
    if (flat) {
        semi = vec3<f32>(size.x, size.y, min(size.x, size.y)) * CORE_HALF_EXTENT;
        along = vec2<f32>(cos(rotation), sin(rotation));
    }
    let base = (s.bits & SPRITE_BASE) != 0u;
    if (base) {
        semi = vec3<f32>(semi.xy * (BASE_HALF_EXTENT / CORE_HALF_EXTENT), semi.z);
    }
    semi = max(semi, vec3<f32>(1e-3));
    // The cloud's base from the core's centre: a base sprite's column reaches down to it.
    let floor_rel = cloud.floor_pad.x - s.offset.z;
    let column = select(0.0, max(-floor_rel, 0.0), base);
    let reach = length(vec2<f32>(max(semi.x, max(semi.y, semi.z)), column));
    // Facing the map's sun (the shadow view's): the map is drawn orthographically along it, so
    // a fragment's ray is the line through its point on the quad along the sun.
    let face = facing_towards(normalize_or(view.sun_dir_camera_z.xyz, vec3<f32>(0.0, 0.0, 1.0)));
    let ray = core_unit(face.normal, along, semi);
    let weight = fade * cloud.floor_pad.y * f32(stride) * select(1.0, -1.0, base);
    for (var c = 0u; c < 4u; c++) {
        let corner = vec2<f32>(f32(c & 1u), f32(c >> 1u)) * 2.0 - 1.0;
        let p = (face.right * corner.x + face.up * corner.y) * reach;
        built[at + c] = BuiltCorner(
            vec4<f32>(centre_rel + p, 1.0),
            ray.xy,
            vec2<f32>(weight, ray.z),
            vec4<f32>(core_unit(p, along, semi), floor_rel / semi.z),
        );
    }
}

// Sprite `id` of the shadow view's chunk as its core (`build_core`).
@compute @workgroup_size(64)
fn cs_build_cores(@builtin(global_invocation_id) id: vec3<u32>) {
    let local = id.x + id.y * (65535u * 64u);
    let k = chunk.x + local;
    if (local >= CHUNK || k >= draws.counts.z) {
        return;
    }
    build_core(k, local * 4u);
}
