//! What the sky holds on the GPU, assembled from its parts ([`Sky::memory`]).

use super::Sky;
use crate::render::stats::SkyMemory;
use crate::render::view::View;

impl Sky {
    /// Bytes of the GPU buffers the sky holds now (frame uniforms, the resident sprites, the
    /// draw list, the ring); [`Self::memory`] counts the textures too.
    pub fn gpu_buffer_bytes(&self) -> u64 {
        self.views.iter().map(View::gpu_buffer_bytes).sum::<u64>()
            + self.sprites.resident.gpu_bytes()
            + self.sprites.quads.0.size()
            + self.sprites.build.gpu_bytes()
            + self.sprites.scatter.gpu_bytes()
            + self.shadows.gpu_bytes()
    }

    /// Every buffer and texture the sky holds now (the ring and the off-screen cloud target
    /// included), and the blocks and slots behind the resident buffers: what a long flight
    /// watches for growth.
    pub fn memory(&self) -> SkyMemory {
        let (blocks, sprites, sprite_slots, cloud_slots) = self.sprites.resident.occupancy();
        SkyMemory {
            resident_bytes: self.sprites.resident.gpu_bytes(),
            draw_bytes: self
                .views
                .iter()
                .map(|v| v.frame_buffer.size() + v.view.gpu_bytes())
                .sum::<u64>()
                + self.sprites.quads.0.size()
                + self.sprites.build.gpu_bytes()
                + self.sprites.scatter.gpu_bytes(),
            ring_bytes: self.views.iter().map(|v| v.ring.gpu_bytes()).sum(),
            cloud_target_bytes: self.views.iter().map(|v| v.clouds.gpu_bytes()).sum(),
            shadow_bytes: self.shadows.gpu_bytes(),
            sheet_bytes: self.sheet_bytes,
            far_field_bytes: self.far_field.gpu_bytes(),
            blocks,
            sprites,
            sprite_slots: sprite_slots.0,
            sprite_slots_used: sprite_slots.1,
            cloud_slots: cloud_slots.0,
            cloud_slots_used: cloud_slots.1,
        }
    }
}
