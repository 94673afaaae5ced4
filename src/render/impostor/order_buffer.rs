//! The ring's order buffer on the GPU: [`RingOrders`]' slots, as long as the resident sprite
//! slots, patched each frame with the spans the sorts and views wrote (the scatter pass, as the
//! sky camera's orders are) and written whole only when the resident buffers grow.

use std::ops::Range;

use super::orders::RingOrders;
use crate::render::sprites::resident::storage_buffer;
use crate::render::sprites::scatter::Scatter;

/// The buffer, its patch and how many times it was made again.
pub(super) struct OrderBuffer {
    buffer: wgpu::Buffer,
    /// Counts buffers made: the impostor views' bind groups made with an older one are made
    /// again.
    generation: u64,
    scatter: Scatter,
    dirty: Vec<Range<u32>>,
}

impl OrderBuffer {
    /// An empty buffer, grown by the first [`Self::fit`].
    pub fn new(device: &wgpu::Device) -> Self {
        Self {
            buffer: storage_buffer(device, "ring.orders", 16),
            generation: 0,
            scatter: Scatter::new(device),
            dirty: Vec::new(),
        }
    }

    /// Bytes of its buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffer.size() + self.scatter.gpu_bytes()
    }

    /// The buffer and its generation.
    pub fn buffer(&self) -> (&wgpu::Buffer, u64) {
        (&self.buffer, self.generation)
    }

    /// Before a frame's sorts: makes `orders` and the buffer as long as the resident sprite
    /// slots (`slots`); a grown buffer is written whole, from the CPU copy. Returns the bytes
    /// written.
    pub fn fit(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        orders: &mut RingOrders,
        slots: u32,
    ) -> u64 {
        if !orders.fit(slots) {
            return 0;
        }
        let bytes = slots as u64 * 4;
        self.buffer = storage_buffer(device, "ring.orders", bytes.max(16));
        self.generation += 1;
        // The whole copy goes, spans written before it included.
        orders.take_dirty(&mut self.dirty);
        self.dirty.clear();
        queue.write_buffer(&self.buffer, 0, bytemuck::cast_slice(orders.slots()));
        bytes
    }

    /// After a frame's sorts and views: sends the spans of `orders` written since the last
    /// call as one patch. Returns the bytes written and the sprite orders the views wrote again
    /// (blocks placed again since, or clouds too large to sort).
    pub fn send(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        orders: &mut RingOrders,
    ) -> (u64, u32) {
        let rewritten = orders.take_dirty(&mut self.dirty);
        let bytes = self.scatter.prepare_orders(
            device,
            queue,
            (orders.slots(), &self.buffer),
            &mut self.dirty,
        );
        (bytes, rewritten)
    }

    /// Records the patch's pass (before the impostor renders that read the orders).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        self.scatter.record(encoder);
    }
}
