// Pass `sky.sprite_corners` (appended to sprites.wgsl): the corners the vertex shader builds,
// written to a buffer so tests and tools can read them back (`Sky::read_back_corners`).

// Keep in sync with `GpuCorner` in src/render/gpu_types.rs.
struct CornerOut {
    // xyz: metres from the camera; w: 1 drawn, 0 not (faded out).
    rel_m_visible: vec4<f32>,
    colour: vec4<f32>,
};

@group(1) @binding(2) var<storage, read_write> corners_out: array<CornerOut>;

@compute @workgroup_size(64)
fn cs_sprite_corners(@builtin(global_invocation_id) id: vec3<u32>) {
    let vi = id.x;
    if (vi >= arrayLength(&corners_out)) {
        return;
    }
    let c = sprite_corner(vi);
    corners_out[vi] = CornerOut(vec4<f32>(c.rel_m, select(0.0, 1.0, c.visible)), c.colour);
}
