// Pass `sky.background`: the sky gradient and sun disc behind everything the host drew, i.e.
// only where the host's depth is still at the far plane: tested by the host's depth as a
// read-only attachment where it can be one (`fs_sky_tested`), else in the shader (`fs_sky`).
// Shared structs: shared/frame.wgsl.

struct SkyOut {
    // Invariant: the depth test compares it with the host's depth exactly.
    @invariant @builtin(position) position: vec4<f32>,
    // The far-plane point of the pixel, homogeneous (see `background_along`).
    @location(0) far: vec4<f32>,
};

@vertex
fn vs_sky(@builtin(vertex_index) vi: u32) -> SkyOut {
    var o: SkyOut;
    o.position = fullscreen_position(vi);
    o.far = far_point(o.position.xy);
    // At the host's background depth: with the host's depth attached, an `Equal` test keeps
    // the pixels where the host drew nothing.
    o.position.z = frame.params.x;
    return o;
}

@fragment
fn fs_sky(i: SkyOut) -> @location(0) vec4<f32> {
    if (!is_background(scene_depth_at(i.position.xy))) {
        discard;
    }
    return vec4<f32>(background_along(i.far), 1.0);
}

// Where the depth test already kept only the host's background. On a software rasteriser the
// pixels it rejects are not shaded at all, while `discard` (as in `fs_sky`) runs the whole
// shader on every pixel first.
@fragment
fn fs_sky_tested(i: SkyOut) -> @location(0) vec4<f32> {
    return vec4<f32>(background_along(i.far), 1.0);
}
