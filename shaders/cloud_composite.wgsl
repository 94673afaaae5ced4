// Pass `clouds.composite`: the cloud target (premultiplied colour and alpha-weighted cloud
// distance at 1/DIVISOR of the resolution) over the host's colour at full resolution.
//
// The colour is upsampled bilinearly: clouds are soft, so within a cloud nothing is lost. At a
// silhouette (a ridge in front of a cloud) the cloud texels were drawn against the farthest depth
// of their block (`cloud_downsample.wgsl`), so they hold cloud where the ridge is; a plain
// upsample would lay that cloud over the ridge as a halo. Each full-resolution pixel therefore
// repeats the soft depth fade (Bahnassi) with its own depth, against the distance of the clouds
// the texel shows (stored distance / alpha): the fade the texel had at its block's farthest
// depth is replaced by the fade at this pixel's depth. Where the pixel's depth is the block's,
// the ratio is 1 and the upsample is untouched; on a ridge in front of the cloud it is 0, so the
// cloud stops at the ridge's full-resolution edge. DIVISOR is put in front of this file when the
// pipeline is built. Shared structs: shared/frame.wgsl (group 0 binds the host's depth).

@group(1) @binding(0) var cloud_colour: texture_2d<f32>;
@group(1) @binding(1) var cloud_distance: texture_2d<f32>;
@group(1) @binding(2) var farthest_depth: texture_2d<f32>;
@group(1) @binding(3) var cloud_sampler: sampler;

@vertex
fn vs_composite(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(vi);
}

// The soft depth fade of a cloud `cloud_m` from the camera plane in front of scene depth `d`.
fn soft_fade(d: f32, cloud_m: f32) -> f32 {
    return clamp((linear_depth_m(d) - cloud_m) / frame.params.z, 0.0, 1.0);
}

@fragment
fn fs_composite(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // Texel i of the cloud target covers host pixels [i * DIVISOR, (i + 1) * DIVISOR).
    let low_size = vec2<f32>(textureDimensions(cloud_colour));
    let uv = position.xy / (low_size * f32(DIVISOR));
    let colour = textureSampleLevel(cloud_colour, cloud_sampler, uv, 0.0);
    if (colour.a < 1.0 / 2048.0) {
        discard;
    }
    let cloud_m = textureSampleLevel(cloud_distance, cloud_sampler, uv, 0.0).r * 1000.0 / colour.a;
    let block = vec2<i32>(position.xy) / DIVISOR;
    let drawn_with = soft_fade(textureLoad(farthest_depth, block, 0).r, cloud_m);
    let here = soft_fade(scene_depth_at(position.xy), cloud_m);
    // Nothing of the cloud was left at the block's depth: it is hidden here too (a neighbour
    // texel's cloud must not bleed onto terrain in front of it).
    let keep = select(clamp(here / drawn_with, 0.0, 1.0), here, drawn_with < 1.0e-3);
    return colour * keep;
}
