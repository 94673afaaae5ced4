//! Where the resident set puts a block: in free slots ([`SlotRanges`]), else in buffers grown
//! for it, else in place of farther blocks; packing the slots in place on the device when they
//! are too scattered; and the upload of the records of the blocks placed, nearest first,
//! within the frame's budget (with their light, [`CloudLight::written`]).
//!
//! [`SlotRanges`]: super::super::slots::SlotRanges
//! [`CloudLight::written`]: super::super::cloud_light::CloudLight::written

use std::ops::Range;

use glam::DVec3;

use super::super::records::{gpu_cloud, gpu_sprite};
use super::super::slots::{copy_runs, pack};
use super::{
    Buffers, FIRST_CLOUDS, FIRST_SPRITES, Resident, ResidentSet, SlotMove, buffers, rebase,
};
use crate::render::gpu_types::{GpuCloud, GpuListCloud, GpuSprite};
use crate::render::stats::Stopwatch;

impl ResidentSet {
    /// Places one block: in free slots, else after growing, else in place of farther ones.
    pub(super) fn place_one(&mut self, queue: &wgpu::Queue, id: u64, d2: f64, camera_m: DVec3) {
        loop {
            if self.try_place(id) {
                return;
            }
            if self.grow_for(queue, id) {
                continue;
            }
            // Full: give the slots of the farthest placed block, if it is farther, to this one.
            let farthest = self
                .blocks
                .values()
                .filter(|r| r.place.is_some())
                .map(|r| ((r.centre_m() - camera_m).length_squared(), r))
                .max_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.tie_order(b.1)))
                .map(|(d2, r)| (d2, r.block.id));
            match farthest {
                Some((far_d2, far_id)) if far_d2 > d2 => {
                    if let Some(r) = self.blocks.get_mut(&far_id)
                        && let Some((s, c)) = r.place.take()
                    {
                        r.uploaded = false;
                        self.waiting.insert(far_id);
                        self.changes += 1;
                        self.sprite_slots.release(s);
                        self.cloud_slots.release(c);
                    }
                }
                _ => return,
            }
        }
    }

    pub(super) fn try_place(&mut self, id: u64) -> bool {
        let Some(r) = self.blocks.get(&id) else {
            return true;
        };
        let (n_sprites, n_clouds) = (r.sprite_count(), r.block.clouds.len() as u32);
        let Some(sprites) = self.sprite_slots.allocate(n_sprites) else {
            return false;
        };
        let Some(clouds) = self.cloud_slots.allocate(n_clouds) else {
            self.sprite_slots.release(sprites);
            return false;
        };
        // Until its first sort a cloud is drawn in its sprites' own order.
        for slot in sprites.clone() {
            self.orders_cpu[slot as usize] = slot;
        }
        self.dirty_orders.push(sprites.clone());
        self.placings += 1;
        let serial = self.placings;
        let Some(r) = self.blocks.get_mut(&id) else {
            return true;
        };
        let mut base = sprites.start;
        for (k, (state, cloud)) in r.clouds.iter_mut().zip(&r.block.clouds).enumerate() {
            state.sprite_base = base;
            state.cloud_slot = clouds.start + k as u32;
            state.ordered_at = None;
            base += cloud.sprites.len() as u32;
        }
        r.place = Some((sprites, clouds));
        r.place_serial = serial;
        r.uploaded = false;
        r.check = None;
        true
    }

    /// Grows (or only packs) the buffers so that block `id` fits, if the limits allow.
    ///
    /// Growing keeps every block where it is: the device copies the old buffers into the new
    /// ones (one submission, timed in [`Self::grow_wait`]) and the CPU writes only the orders
    /// and lists it keeps copies of, 4 bytes a sprite slot. Placing and writing every block again
    /// instead (20 to 27 MB in one frame) made the frames where the buffers grew take 42 to
    /// 144 ms. A buffer that grows gets a sixteenth more than it needs.
    ///
    /// A buffer with slots enough in pieces keeps its size ([`SlotRanges::capacity_for`]) and is
    /// packed ([`Self::pack_in_place`]): the device moves the blocks to close the gaps, and the
    /// CPU writes the orders and lists again, as when growing. Growing it instead (the cloud
    /// buffer went from 256 slots to 4,096 when a block's clouds found no range) made the size
    /// depend on how a long flight's changes had cut up the slots.
    ///
    /// [`SlotRanges::capacity_for`]: super::super::slots::SlotRanges::capacity_for
    pub(super) fn grow_for(&mut self, queue: &wgpu::Queue, id: u64) -> bool {
        let Some(r) = self.blocks.get(&id) else {
            return false;
        };
        let (n_sprites, n_clouds) = (r.sprite_count(), r.block.clouds.len() as u32);
        let need_sprites = self.sprite_slots.used() + n_sprites;
        let need_clouds = self.cloud_slots.used() + n_clouds;
        if need_sprites > self.limit_sprites {
            return false;
        }
        if self.sprite_slots.fits(n_sprites) && self.cloud_slots.fits(n_clouds) {
            return false;
        }
        // In steps of the first sizes: 4,096 sprites (160 KB), 256 clouds (36 KB); with room
        // for the blocks expected in the next frames, so that a weather change handed over a
        // part a frame grows the buffers once, not every frame.
        let with_expected = |n: u32, more: u64| n.saturating_add(more.min(u32::MAX as u64) as u32);
        let sprites = self
            .sprite_slots
            .capacity_for(with_expected(n_sprites, self.expected.0), FIRST_SPRITES)
            .min(self.limit_sprites)
            .max(need_sprites);
        let clouds = self
            .cloud_slots
            .capacity_for(with_expected(n_clouds, self.expected.1), FIRST_CLOUDS);
        debug_assert!(clouds >= need_clouds);
        let (packs_sprites, packs_clouds) = (
            sprites == self.sprite_slots.capacity(),
            clouds == self.cloud_slots.capacity(),
        );
        if !(packs_sprites && packs_clouds) {
            // One of them is too small in all: it grows and the other keeps its size; both keep
            // their blocks in place. A block that still finds no range (the other is cut up)
            // comes back here and packs.
            let sprites = if self.sprite_slots.fits(n_sprites) {
                self.sprite_slots.capacity()
            } else {
                sprites
            };
            let clouds = if self.cloud_slots.fits(n_clouds) {
                self.cloud_slots.capacity()
            } else {
                clouds
            };
            self.grow_in_place(queue, sprites, clouds);
            return true;
        }
        self.pack_in_place(queue);
        true
    }

    /// Packs the blocks held into the start of new buffers of the same size, in the order
    /// their slots lay in ([`pack`]), so that the free slots are one range. The device moves
    /// them, as it does when the buffers grow: one copy of the sprites, lights and clouds of
    /// each run of blocks that stay neighbours, in one submission (timed in
    /// [`Self::grow_wait`]). The CPU moves what holds slot numbers: each block's slots, its
    /// clouds' first sprite and cloud slots, its cloud list, and the orders (the sprite slots of
    /// their clouds, 4 bytes a slot) and lists it keeps copies of, written whole once the
    /// frame's blocks are placed. The order within each cloud stays, and with it the order
    /// cache. Placing and writing every block again instead wrote 21 to 27 MB in one frame on
    /// the FL350 cruise, about every 30 s (22 to 53 ms of the frame thread). A block placed and
    /// not written yet is moved too and written later where it is then; a moved block gets a
    /// placing of its own ([`Resident::place_serial`]), so that copies of its orders elsewhere
    /// (the impostor ring's) are written again. [`Self::moved_slot`] says where a slot went.
    pub(super) fn pack_in_place(&mut self, queue: &wgpu::Queue) {
        let (sprites, clouds) = (self.sprite_slots.capacity(), self.cloud_slots.capacity());
        let mut placed: Vec<(u64, Range<u32>, Range<u32>, bool)> = self
            .blocks
            .values()
            .filter_map(|r| {
                let (s, c) = r.place.clone()?;
                Some((r.block.id, s, c, r.uploaded))
            })
            .collect();
        // A fixed order (the map's is not), for the placings' serials.
        placed.sort_unstable_by_key(|p| (p.1.start, p.0));
        let held: Vec<Range<u32>> = placed.iter().map(|p| p.1.clone()).collect();
        let (sprite_slots, to_sprites) = pack(sprites, &held);
        let held: Vec<Range<u32>> = placed.iter().map(|p| p.2.clone()).collect();
        let (cloud_slots, to_clouds) = pack(clouds, &held);

        // The device copies what was written: runs of written blocks that stay neighbours.
        let b = buffers(&self.device, &self.layout, sprites, clouds);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky.resident_pack"),
            });
        let written = || placed.iter().enumerate().filter(|(_, p)| p.3);
        let sprite_runs = copy_runs(written().map(|(i, p)| (p.1.clone(), to_sprites[i].start)));
        let sprite_bytes = std::mem::size_of::<GpuSprite>() as u64;
        for &(from, to, len) in &sprite_runs {
            for (old, new, bytes) in [
                (&self.sprite_buffer, &b.sprites, sprite_bytes),
                (&self.light_buffer, &b.lights, 4),
            ] {
                let (from, to, len) = (from as u64 * bytes, to as u64 * bytes, len as u64 * bytes);
                encoder.copy_buffer_to_buffer(old, from, new, to, len);
            }
        }
        let cloud_runs = copy_runs(written().map(|(i, p)| (p.2.clone(), to_clouds[i].start)));
        let cloud_bytes = std::mem::size_of::<GpuCloud>() as u64;
        for &(from, to, len) in &cloud_runs {
            let (from, to, len) = (
                from as u64 * cloud_bytes,
                to as u64 * cloud_bytes,
                len as u64 * cloud_bytes,
            );
            encoder.copy_buffer_to_buffer(&self.cloud_buffer, from, &b.clouds, to, len);
        }

        // The CPU moves the slot numbers it holds.
        let mut orders = vec![0u32; sprites as usize];
        let mut lists = vec![GpuListCloud::default(); clouds as usize];
        let mut moves = Vec::with_capacity(placed.len());
        for (i, (id, old_s, old_c, _)) in placed.iter().enumerate() {
            let (new_s, new_c) = (to_sprites[i].clone(), to_clouds[i].clone());
            let (ds, dc) = ((old_s.start, new_s.start), (old_c.start, new_c.start));
            let len = old_s.len();
            let old_orders = &self.orders_cpu[old_s.start as usize..][..len];
            for (to, &from) in orders[new_s.start as usize..][..len]
                .iter_mut()
                .zip(old_orders)
            {
                *to = rebase(from, ds.0, ds.1);
            }
            if !old_s.is_empty() {
                moves.push(SlotMove {
                    from: old_s.clone(),
                    to: new_s.start,
                });
            }
            let Some(r) = self.blocks.get_mut(id) else {
                continue;
            };
            for state in &mut r.clouds {
                state.sprite_base = rebase(state.sprite_base, ds.0, ds.1);
                state.cloud_slot = rebase(state.cloud_slot, dc.0, dc.1);
            }
            for entry in &mut r.list {
                entry.cloud = rebase(entry.cloud, dc.0, dc.1);
                entry.order_base = rebase(entry.order_base, ds.0, ds.1);
            }
            // The GPU's copy of the list is the block's (`draw_list::main_view` writes both).
            lists[new_c.start as usize..][..r.list.len()].copy_from_slice(&r.list);
            if (old_s, old_c) != (&new_s, &new_c) {
                self.placings += 1;
                r.place_serial = self.placings;
            }
            r.place = Some((new_s, new_c));
        }
        moves.sort_by_key(|m| m.from.start);
        self.packs.push(moves);
        self.sprite_slots = sprite_slots;
        self.cloud_slots = cloud_slots;
        self.orders_cpu = orders;
        self.lists_cpu = lists;
        // What was dirty is in the copies, at the slots it has now.
        self.dirty_orders.clear();
        self.dirty_lists.clear();
        self.whole_due = true;
        // Writes queued for the old buffers this frame reach them before the copies.
        let wait = Stopwatch::start();
        queue.submit([encoder.finish()]);
        self.grow_wait += wait.spent();
        self.take_buffers(b);
    }

    /// New buffers of `sprites` and `clouds` slots (at least today's) holding every block where
    /// it is: the device copies the sprites, clouds, lights, orders and lists across (an order
    /// patch not applied yet applies to the new buffers, with the same values as the CPU
    /// copies). Writing the orders and lists whole from the CPU instead cost a live weather
    /// update's frame about 4.5 MB and 4 ms of the frame thread more.
    pub(super) fn grow_in_place(&mut self, queue: &wgpu::Queue, sprites: u32, clouds: u32) {
        let b = buffers(&self.device, &self.layout, sprites, clouds);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("sky.resident_grow"),
            });
        for (from, to) in [
            (&self.sprite_buffer, &b.sprites),
            (&self.cloud_buffer, &b.clouds),
            (&self.light_buffer, &b.lights),
            (&self.order_buffer, &b.orders),
            (&self.list_buffer, &b.lists),
        ] {
            encoder.copy_buffer_to_buffer(from, 0, to, 0, from.size().min(to.size()));
        }
        self.sprite_slots.extend_to(sprites);
        self.cloud_slots.extend_to(clouds);
        self.orders_cpu.resize(sprites as usize, 0);
        self.lists_cpu
            .resize(clouds as usize, GpuListCloud::default());
        // Writes queued for the old buffers this frame reach them before the copies: a queue's
        // writes go ahead of the submission that follows them.
        let wait = Stopwatch::start();
        queue.submit([encoder.finish()]);
        self.grow_wait += wait.spent();
        self.take_buffers(b);
    }

    /// Writes the order and list buffers whole from their CPU copies; returns the bytes.
    pub(super) fn write_whole(&self, queue: &wgpu::Queue) -> u64 {
        let orders: &[u8] = bytemuck::cast_slice(&self.orders_cpu);
        let lists: &[u8] = bytemuck::cast_slice(&self.lists_cpu);
        queue.write_buffer(&self.order_buffer, 0, orders);
        queue.write_buffer(&self.list_buffer, 0, lists);
        (orders.len() + lists.len()) as u64
    }

    /// Puts `b` in place of the buffers held; bind groups made with the old ones are made again
    /// (a new generation).
    pub(super) fn take_buffers(&mut self, b: Buffers) {
        self.sprite_buffer = b.sprites;
        self.cloud_buffer = b.clouds;
        self.light_buffer = b.lights;
        self.order_buffer = b.orders;
        self.list_buffer = b.lists;
        self.group = b.group;
        self.generation += 1;
    }

    /// Writes placed blocks not written yet, nearest first, until `budget` sprites are written
    /// (at least one block); returns the bytes.
    pub(super) fn upload(&mut self, queue: &wgpu::Queue, camera_m: DVec3, budget: u32) -> u64 {
        let mut bytes = 0;
        let mut sprites: Vec<GpuSprite> = Vec::new();
        let mut clouds: Vec<GpuCloud> = Vec::new();
        // A scene written whole and new (the first frame) is lit at once; blocks arriving one by
        // one, or many after the buffers grew, within the frame's budget.
        let mut light_us = 0;
        let fresh = budget == u32::MAX && self.blocks.values().all(|r| r.light.lights.is_empty());
        let mut light_left = if fresh {
            u32::MAX
        } else {
            self.light.budget().saturating_sub(self.lit_sprites)
        };
        let blocks = &self.blocks;
        let mut todo: Vec<(f64, &Resident)> = self
            .waiting
            .iter()
            .filter_map(|id| blocks.get(id))
            .filter(|r| r.place.is_some() && !r.uploaded)
            .map(|r| ((r.centre_m() - camera_m).length_squared(), r))
            .collect();
        todo.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.tie_order(b.1)));
        let todo: Vec<u64> = todo.iter().map(|(_, r)| r.block.id).collect();
        let mut written = 0u32;
        for id in todo {
            if written > 0 && written >= budget {
                break;
            }
            let Some(r) = self.blocks.get_mut(&id) else {
                continue;
            };
            let Some((s, c)) = r.place.clone() else {
                continue;
            };
            written = written.saturating_add(s.end - s.start);
            sprites.clear();
            clouds.clear();
            for cloud in &r.block.clouds {
                sprites.extend(cloud.sprites.iter().map(|sp| gpu_sprite(cloud, sp)));
                clouds.push(gpu_cloud(cloud, r.block.centre_m));
            }
            let sprite_bytes = std::mem::size_of::<GpuSprite>() as u64;
            let cloud_bytes = std::mem::size_of::<GpuCloud>() as u64;
            if !sprites.is_empty() {
                queue.write_buffer(
                    &self.sprite_buffer,
                    s.start as u64 * sprite_bytes,
                    bytemuck::cast_slice(&sprites),
                );
            }
            if !clouds.is_empty() {
                queue.write_buffer(
                    &self.cloud_buffer,
                    c.start as u64 * cloud_bytes,
                    bytemuck::cast_slice(&clouds),
                );
            }
            bytes += sprites.len() as u64 * sprite_bytes + clouds.len() as u64 * cloud_bytes;
            r.uploaded = true;
            self.waiting.remove(&id);
            self.changes += 1;
            if self.light.enabled() {
                let light_start = std::time::Instant::now();
                let to = (queue, &self.light_buffer, s.start);
                let block_light = (&r.block, &mut r.light);
                let (light_bytes, lit) = self.light.written(block_light, to, &mut light_left);
                light_us += light_start.elapsed().as_micros() as u64;
                bytes += light_bytes;
                self.lit_sprites += lit;
            }
        }
        self.light_us += light_us;
        bytes
    }
}
