// Pass `sky.background`: the sky gradient and sun disc behind everything the host drew, i.e.
// only where the host's depth is still at the far plane: tested by the host's depth as a
// read-only attachment where it can be one (`fs_sky_tested`), else in the shader (`fs_sky`).
// Shared structs: shared/frame.wgsl.

@vertex
fn vs_sky(@builtin(vertex_index) vi: u32) -> BackgroundOut {
    return background_vertex(vi);
}

@fragment
fn fs_sky(i: BackgroundOut) -> @location(0) vec4<f32> {
    if (!is_background(scene_depth_at(i.position.xy))) {
        discard;
    }
    return vec4<f32>(background_along(i.far), 1.0);
}

// Where the depth test already kept only the host's background. On a software rasteriser the
// pixels it rejects are not shaded at all, while `discard` (as in `fs_sky`) runs the whole
// shader on every pixel first.
@fragment
fn fs_sky_tested(i: BackgroundOut) -> @location(0) vec4<f32> {
    return vec4<f32>(background_along(i.far), 1.0);
}
