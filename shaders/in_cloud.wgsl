// Pass `sky.in_cloud`: inside a cloud, density fog over everything (Wang 7.1's proposed fix), so
// the inside is as opaque as the outside suggests. Opacity grows with the host's depth at each
// pixel and with the in-cloud measure. Shared structs: shared/frame.wgsl.

struct FogOut {
    @builtin(position) position: vec4<f32>,
};

@vertex
fn vs_in_cloud(@builtin(vertex_index) vi: u32) -> FogOut {
    var o: FogOut;
    o.position = fullscreen_position(vi);
    return o;
}

@fragment
fn fs_in_cloud(i: FogOut) -> @location(0) vec4<f32> {
    return in_cloud_fog(i.position.xy);
}

// Into the cloud target: the fog starts at the camera, so its distance is 0 (the composite never
// cuts it at a silhouette).
@fragment
fn fs_in_cloud_offscreen(i: FogOut) -> CloudOut {
    return cloud_out(in_cloud_fog(i.position.xy), 0.0);
}

fn in_cloud_fog(frag_xy: vec2<f32>) -> vec4<f32> {
    // Where the host drew nothing this is its far plane's distance (1e9 for a far plane at
    // infinity): at the fog's tens of metres of visibility, opaque to within a millionth.
    let dist_m = scene_m_at(frag_xy);
    // The air data's visibility (src/flight/air.rs: in_cloud.visibility_m / in_cloud): extinction
    // in_cloud / visibility_m over at most visibility_m / (1 - in_cloud) of cloud, the path a
    // cloud holds at this depth (at its edge one visibility, so the sky fades in with the measure
    // as before; deep inside all of it, so nothing of the scene shows).
    let k = frame.in_cloud_rgba.a;
    let reach_m = frame.params.w / max(1.0 - k, 1e-6);
    let alpha = clamp(1.0 - exp(-min(dist_m, reach_m) * k / frame.params.w), 0.0, 1.0);
    return vec4<f32>(frame.in_cloud_rgba.rgb * alpha, alpha);
}
