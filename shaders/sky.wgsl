// Pass `sky.background`: the sky gradient and sun disc behind everything the host drew, i.e.
// only where the host's depth is still at the far plane. Shared structs: shared/frame.wgsl.

struct SkyOut {
    @builtin(position) position: vec4<f32>,
    // The far-plane point of the pixel, homogeneous (see `background_along`).
    @location(0) far: vec4<f32>,
};

@vertex
fn vs_sky(@builtin(vertex_index) vi: u32) -> SkyOut {
    var o: SkyOut;
    o.position = fullscreen_position(vi);
    o.far = far_point(o.position.xy);
    return o;
}

@fragment
fn fs_sky(i: SkyOut) -> @location(0) vec4<f32> {
    if (!is_background(scene_depth_at(i.position.xy))) {
        discard;
    }
    return vec4<f32>(background_along(i.far), 1.0);
}
