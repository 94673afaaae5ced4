//! The shadow map's view of the resident sprites: the draw list of the blocks a drawing covers,
//! each with every cloud of its in its list (kept between drawings, `KeptLists`), and their
//! upload with the view's uniform ([`CloudShadows::write_view`]). What
//! [`CloudShadows::prepare`] writes once it has decided to draw.

use glam::DVec3;

use super::{CloudShadows, NO_FAR_FADE_M, ShadowFrame, is_covered, is_near};
use crate::render::gpu_types::{GpuDrawBlock, GpuListCloud};
use crate::render::id_hash::IdSet;
use crate::render::sprites::draw_list::{Blocks, fade_code};
use crate::render::sprites::resident::{ResidentSet, storage_buffer};
use crate::render::sprites::sprite_view::{self, ViewData, ViewLight};

impl CloudShadows {
    /// Writes the cloud lists and the view of the resident sprites for a drawing at `frame` of
    /// `sprites` (the draw list `shadow_view` made); returns the bytes written.
    pub(super) fn write_view(
        &mut self,
        queue: &wgpu::Queue,
        resident: &ResidentSet,
        light: &ViewLight,
        frame: &ShadowFrame,
        sprites: u32,
    ) -> u64 {
        let mut bytes = 0;
        let mut header = sprite_view::header(&ViewLight {
            camera_z_m: frame.eye_m.z as f32,
            farthest_m: NO_FAR_FADE_M,
            ..*light
        });
        // The cores' rays run along the map's own sun (`build_core`).
        header.sun_dir_camera_z[..3].copy_from_slice(&frame.sun.as_vec3().to_array());
        // Seen from the sun: no facing locks (the eye is never near), upright base sprites
        // never fade (from a high sun they are edge on anyway), no far fade.
        header.forward_lock[1] = 0.0;
        header.upright_lifecycle[0] = 2.0;
        header.upright_lifecycle[1] = 3.0;
        // Each cloud's sprites in their slots' order: the half-float sums then come out the
        // same wherever the camera's sort has put them (a moved camera re-sorts clouds).
        header.hl_deck[1] = 1.0;
        header.far_fade_layer_turn[0] = NO_FAR_FADE_M;
        header.far_fade_layer_turn[1] = 2.0 * NO_FAR_FADE_M;
        let list_bytes = (self.lists.len() as u64 * 16).max(16);
        if list_bytes > self.list_buffer.size() {
            let size = list_bytes.next_power_of_two();
            self.list_buffer = storage_buffer(&self.device, "sky.cloud_shadow_lists", size);
            self.list_buffers_made += 1;
        }
        if !self.lists.is_empty() {
            let data = bytemuck::cast_slice(&self.lists);
            queue.write_buffer(&self.list_buffer, 0, data);
            bytes += data.len() as u64;
        }
        bytes += self.sprites_view.write(
            &self.device,
            queue,
            &self.view_layout,
            &header,
            None,
            ViewData::Resident {
                counts: [self.draws.len() as u32, 0, sprites, 0],
                draws: &self.draws,
                lists: &self.list_buffer,
                orders: &resident.order_buffer,
                // A new group when either buffer was replaced.
                generation: resident
                    .generation
                    .wrapping_mul(1_000_003)
                    .wrapping_add(self.list_buffers_made),
            },
        );
        bytes
    }

    /// The draw list of the blocks the map covers (placed on the GPU, their drift included),
    /// with every cloud of theirs in its list (its sprites in the resident order); returns the
    /// sprites. `only`: just these blocks (added to a map drawn before), each moved back by
    /// `back_m` (the clouds' drift since that drawing). `none`: no block (the sun is too low
    /// for shadows).
    pub(super) fn shadow_view(
        &mut self,
        blocks: &Blocks,
        frame: &ShadowFrame,
        only: Option<&IdSet>,
        back_m: DVec3,
        none: bool,
    ) -> u32 {
        self.draws.clear();
        self.lists.clear();
        if none {
            return 0;
        }
        // A fixed order (by place, then id): the half-float sums come out the same every run.
        // Blocks added to a map are a few of the thousands held: looked up, not searched for.
        // Sorted on keys copied out of the blocks (a comparison that reads two blocks costs two
        // cache misses).
        let mut order: Vec<(f64, f64, u64, &crate::render::sprites::resident::Resident)> =
            match only {
                Some(ids) => ids
                    .iter()
                    .filter_map(|id| blocks.get(id))
                    .collect::<Vec<_>>(),
                None => blocks.values().collect(),
            }
            .into_iter()
            .filter(|r| is_covered(r, frame))
            .map(|r| (r.block.centre_m.x, r.block.centre_m.y, r.block.id, r))
            .collect();
        order.sort_by(|a, b| {
            a.0.total_cmp(&b.0)
                .then(a.1.total_cmp(&b.1))
                .then(a.2.cmp(&b.2))
        });
        if only.is_none() {
            // Lists of blocks no longer covered are not kept.
            let covered: IdSet = order.iter().map(|o| o.2).collect();
            self.kept_lists.retain(|id, _| covered.contains(id));
        }
        let mut total = 0u32;
        for (_, _, id, r) in order {
            let list_base = self.lists.len() as u32;
            // Beyond `full_detail_m` across the rays, every `far_sprite_stride`th sprite of a
            // cloud stands for that many (its optical depth times the stride): far shadows lie
            // under the haze, and the far field holds most of the sprites.
            let stride = if is_near(frame, r.centre_m() - back_m, r.radius_m, &self.settings) {
                1
            } else {
                self.settings.far_sprite_stride
            };
            let kept = self.kept_lists.entry(id).or_default();
            if kept.built_for != Some((r.place_serial, stride)) {
                kept.lists.clear();
                let mut first = 0u32;
                for state in r.clouds.iter().filter(|c| c.sprites > 0) {
                    kept.lists.push(GpuListCloud {
                        cloud: state.cloud_slot,
                        first,
                        order_base: state.sprite_base,
                        stride,
                    });
                    first += state.sprites.div_ceil(stride);
                }
                (kept.built_for, kept.sprites) = (Some((r.place_serial, stride)), first);
            }
            self.lists.extend_from_slice(&kept.lists);
            let (fade_kind, fade_progress) = fade_code(r.motion.fade);
            self.draws.push(GpuDrawBlock {
                origin_rel: (r.centre_m() - back_m - frame.eye_m).as_vec3().to_array(),
                first: total,
                list_base,
                list_len: self.lists.len() as u32 - list_base,
                fade_kind,
                fade_progress,
            });
            total += kept.sprites;
        }
        total
    }
}
