// Pass `sky.sprites`: cloud sprites, back to front, premultiplied alpha, from the corners the
// build pass (`sprite_build.wgsl`) made this frame. The fragment multiplies in the sheet texture,
// fades against the host's depth over soft_depth_fade_m (Bahnassi) instead of cutting hard, and
// fades distant sprites into the horizon haze. Shared structs: shared/frame.wgsl.

@group(1) @binding(0) var sheet: texture_2d<f32>;
@group(1) @binding(1) var sheet_sampler: sampler;

// Keep in sync with `GpuSpriteVertex` in src/render/gpu_types.rs.
struct VertexIn {
    @location(0) position_visible: vec4<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) colour: vec4<f32>,
};

// Two interpolated vectors: the software rasteriser's triangle setup, run on one core for every
// sprite at any resolution, costs per interpolated vector. The fragment's view depth is
// 1 / position.w (WGSL's fragment position holds 1 / clip w, which is the view depth here).
struct VertexOut {
    @builtin(position) position: vec4<f32>,
    // xy: sheet texture coordinates; z: how far the sprite has faded into the horizon haze,
    // 0..1 (per corner: it varies little across a sprite, and the exponential per fragment was
    // a tenth of the fill cost).
    @location(0) uv_haze: vec3<f32>,
    @location(1) colour: vec4<f32>,
};

// The fragment's distance from the camera plane, metres.
fn view_depth_m(i: VertexOut) -> f32 {
    return 1.0 / i.position.w;
}

@vertex
fn vs_sprite(v: VertexIn) -> VertexOut {
    var o: VertexOut;
    if (v.position_visible.w < 0.5) {
        // Faded out: every corner outside the clip volume.
        o.position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return o;
    }
    // A lightning flash inside the cell: light falling off with distance from it (Gaussian in
    // its reach, per corner), a little blue-white, on top of the cloud's own light. Nothing
    // when no flash is lit (`flash.w` 0); no branch on it, which lavapipe would specialise the
    // shader on, a copy for each flash's brightness (far_field.wgsl).
    let d = distance(v.position_visible.xyz, frame.flash.xyz) / max(frame.flash_reach.x, 1.0);
    let glow = frame.flash.w * exp(-d * d);
    o.colour = vec4<f32>(v.colour.rgb + glow * vec3<f32>(0.92, 0.94, 1.0), v.colour.a);
    // On the round Earth (`earth_curved`): at 100 km a sprite sits 0.8 km below the flat frame.
    let rel = earth_curved(v.position_visible.xyz);
    o.position = frame.view_proj * vec4<f32>(rel, 1.0);
    // Beyond the host's far plane (a storm cell 100-450 km off): held just inside it rather
    // than clipped; the view depth (1 / w) stays true. `params.x`: 1 standard Z (far at w),
    // 0 reversed (far at 0).
    let w = o.position.w;
    o.position.z = select(
        max(o.position.z, 0.0),
        min(o.position.z, w * 0.999999),
        frame.params.x > 0.5,
    );
    // Aerial perspective: distant clouds fade into the horizon haze, thinner with height.
    let haze = 1.0 - haze_transmittance(length(rel), v.position_visible.z);
    o.uv_haze = vec3<f32>(v.uv, haze);
    return o;
}

@fragment
fn fs_sprite(i: VertexOut) -> @location(0) vec4<f32> {
    return sprite_colour(i);
}

// Into the cloud target (`cloud_target.wgsl`): the colour, and the sprite's distance weighted
// by its alpha, blended the same way, so the composite knows how far the clouds of each texel are.
@fragment
fn fs_sprite_offscreen(i: VertexOut) -> CloudOut {
    return cloud_out(sprite_colour(i), view_depth_m(i));
}

// Premultiplied colour of a sprite fragment (also used by the impostor pass).
fn sprite_colour(i: VertexOut) -> vec4<f32> {
    let texel = textureSample(sheet, sheet_sampler, i.uv_haze.xy);
    // Where the host drew nothing, nothing is in front however far the cloud (a storm cell
    // beyond the host's far plane); the cloud target's depth says so already (1e9 metres).
    let background = !SCENE_IN_METRES && is_background(scene_depth_at(i.position.xy));
    let scene_m = select(scene_m_at(i.position.xy), 1.0e9, background);
    let soft = clamp((scene_m - view_depth_m(i)) * frame.params.y, 0.0, 1.0);
    let alpha = texel.a * i.colour.a * soft;
    let rgb = mix(i.colour.rgb * texel.rgb, frame.sky_horizon_rgb.rgb, i.uv_haze.z);
    return vec4<f32>(rgb * alpha, alpha);
}
