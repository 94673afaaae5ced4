// Pass `clouds.downsample`: the host's depth at the cloud target's resolution, the farthest depth
// of each DIVISOR x DIVISOR block of host pixels (Cantlay, GPU Gems 3 ch. 23, maximum-depth
// downsampling), stored as metres from the camera plane: a cloud in front of any pixel of the
// block is drawn in its texel, never hidden by terrain it stands in front of; where the block also
// holds nearer terrain, the composite (`cloud_composite.wgsl`) cuts the cloud at full resolution.
// Metres, converted once a texel here, spare every cloud fragment the conversion
// (`SCENE_IN_METRES` in shared/frame.wgsl). DIVISOR (1/resolution_scale) is a constant put in
// front of this file when the pipeline is built: loop bounds stay out of uniforms (lavapipe
// recompiles a shader whose loop bound is a uniform on every frame). Shared structs:
// shared/frame.wgsl (group 0 binds the host's depth here).

@vertex
fn vs_downsample(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    return fullscreen_position(vi);
}

@fragment
fn fs_downsample(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let last = vec2<i32>(textureDimensions(scene_depth)) - 1;
    let origin = vec2<i32>(position.xy) * DIVISOR;
    // The nearest depth there is (the near plane: 0 standard, 1 reversed), so every pixel of the
    // block is at least as far.
    var farthest = 1.0 - frame.params.x;
    for (var y = 0; y < DIVISOR; y++) {
        for (var x = 0; x < DIVISOR; x++) {
            let at = min(origin + vec2<i32>(x, y), last);
            farthest = farther_depth(farthest, textureLoad(scene_depth, at, 0).r);
        }
    }
    // Where the host drew nothing in the whole block, nothing is in front of the far field's
    // clouds beyond its far plane either (`far_field.wgsl`).
    return vec4<f32>(select(linear_depth_m(farthest), 1.0e9, is_background(farthest)), 0.0, 0.0, 0.0);
}
