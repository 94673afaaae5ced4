// Pass `ring.impostor` (appended to sprites.wgsl): cloud sprites rendered into an impostor of the
// ring from the ring centre. Besides the colour it accumulates the view depth in kilometres times
// alpha with the same premultiplied over blending, so depth / alpha is the alpha-weighted depth
// of the clouds seen through each texel (read back in impostor_quad.wgsl).

struct ImpostorOut {
    @location(0) colour: vec4<f32>,
    @location(1) depth_km: vec4<f32>,
};

@fragment
fn fs_sprite_impostor(i: VertexOut) -> ImpostorOut {
    let c = sprite_colour(i);
    var o: ImpostorOut;
    o.colour = c;
    o.depth_km = vec4<f32>(view_depth_m(i) * 0.001 * c.a, 0.0, 0.0, c.a);
    return o;
}
