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
// cloud stops at the ridge's full-resolution edge. Where the host drew nothing, the pass also
// draws the sky background (the sky pass is left out below full resolution). DIVISOR is put in
// front of this file when the pipeline is built. Shared structs: shared/frame.wgsl (group 0 binds the host's depth).

@group(1) @binding(0) var cloud_colour: texture_2d<f32>;
@group(1) @binding(1) var cloud_distance: texture_2d<f32>;
// The farthest distance of each block of host pixels, metres (`cloud_downsample.wgsl`).
@group(1) @binding(2) var farthest_distance: texture_2d<f32>;
@group(1) @binding(3) var cloud_sampler: sampler;

// The split composite's two draws test the host's depth against the background depth of
// `background_vertex` (equal: the sky's pixels; not equal: the host's scene).
@vertex
fn vs_composite(@builtin(vertex_index) vi: u32) -> BackgroundOut {
    return background_vertex(vi);
}

// The cloud target's premultiplied colour over host pixel `position`, and where it is sampled.
fn cloud_colour_at(position: vec2<f32>) -> vec4<f32> {
    // Texel i of the cloud target covers host pixels [i * DIVISOR, (i + 1) * DIVISOR).
    let low_size = vec2<f32>(textureDimensions(cloud_colour));
    let uv = position / (low_size * f32(DIVISOR));
    return textureSampleLevel(cloud_colour, cloud_sampler, uv, 0.0);
}

// Where the host drew nothing this pass is also the sky background (one full-resolution pass
// instead of two): the clouds over it, opaque. Sky pixels are the farthest of their block, so
// their clouds need no fix-up.
fn over_sky(i: BackgroundOut, colour: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(colour.rgb + (1.0 - colour.a) * background_along(i.far), 1.0);
}

// Over the host's scene (depth `d`): the clouds with their fade redone at this pixel's depth.
// Every host pixel redoes the fade, not only those nearer than their block's farthest depth:
// on terrain in front of the clouds the bilinear upsample also brings in the neighbouring
// texels' clouds, drawn against the sky beside it.
fn over_scene(position: vec2<f32>, colour: vec4<f32>, d: f32) -> vec4<f32> {
    let low_size = vec2<f32>(textureDimensions(cloud_colour));
    let uv = position / (low_size * f32(DIVISOR));
    let farthest_m = textureLoad(farthest_distance, vec2<i32>(position) / DIVISOR, 0).r;
    let here_m = linear_depth_m(d);
    let cloud_m = textureSampleLevel(cloud_distance, cloud_sampler, uv, 0.0).r * 1000.0 / colour.a;
    let drawn_with = clamp((farthest_m - cloud_m) * frame.params.y, 0.0, 1.0);
    let here = clamp((here_m - cloud_m) * frame.params.y, 0.0, 1.0);
    // Nothing of the cloud was left at the block's depth: it is hidden here too (a neighbour
    // texel's cloud must not bleed onto terrain in front of it).
    let keep = select(clamp(here / drawn_with, 0.0, 1.0), here, drawn_with < 1.0e-3);
    return colour * keep;
}

// One draw over every pixel, sky and scene told apart in the shader: for hosts whose depth
// cannot also be the pass's depth attachment (see `cloud_target.rs`).
@fragment
fn fs_composite(i: BackgroundOut) -> @location(0) vec4<f32> {
    let colour = cloud_colour_at(i.position.xy);
    let d = scene_depth_at(i.position.xy);
    if (is_background(d)) {
        return over_sky(i, colour);
    }
    if (colour.a < 1.0 / 2048.0) {
        discard;
    }
    return over_scene(i.position.xy, colour, d);
}

// The split composite's first draw, where the depth test passed the host's background only
// (written, not blended). On a software rasteriser a shader runs both sides of a branch for
// every pixel, while pixels the depth test rejects are not shaded at all: two draws, each
// shading only its own pixels, cost less than one that runs the sky and the fix-up everywhere.
@fragment
fn fs_composite_sky(i: BackgroundOut) -> @location(0) vec4<f32> {
    return over_sky(i, cloud_colour_at(i.position.xy));
}

// The split composite's second draw, where the depth test passed the host's scene only. No
// `discard` (a shader that may discard is depth-tested after it runs, on every pixel): where
// the target holds nothing it blends zero, which leaves the host's colour as it was.
@fragment
fn fs_composite_scene(i: BackgroundOut) -> @location(0) vec4<f32> {
    let colour = cloud_colour_at(i.position.xy);
    let over = over_scene(i.position.xy, colour, scene_depth_at(i.position.xy));
    return select(over, vec4<f32>(0.0), colour.a < 1.0 / 2048.0);
}
