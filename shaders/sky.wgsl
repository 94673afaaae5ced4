// Pass `sky.background`: the sky gradient and sun disc behind everything the host drew, i.e.
// only where the host's depth is still at the far plane. Shared structs: shared/frame.wgsl.

struct SkyOut {
    @builtin(position) position: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_sky(@builtin(vertex_index) vi: u32) -> SkyOut {
    var o: SkyOut;
    o.position = fullscreen_position(vi);
    o.ndc = o.position.xy;
    return o;
}

@fragment
fn fs_sky(i: SkyOut) -> @location(0) vec4<f32> {
    if (!is_background(scene_depth_at(i.position.xy))) {
        discard;
    }
    // A point on the pixel's ray (depth 0.5 is finite under any projection, reversed or not).
    let far = frame.inv_view_proj * vec4<f32>(i.ndc, 0.5, 1.0);
    let dir = normalize(far.xyz / far.w);
    var c = sky_colour(dir);
    let cos_sun = dot(dir, frame.sun_dir.xyz);
    let disc = smoothstep(frame.sun_dir.w - 0.00002, frame.sun_dir.w + 0.00002, cos_sun);
    c = mix(c, frame.sun_rgb.rgb * 4.0, disc * step(-0.01, dir.z));
    return vec4<f32>(c, 1.0);
}
