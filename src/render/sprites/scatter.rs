//! The sprite orders and cloud lists a frame changed, sent to the GPU as one patch and written
//! into place there (`shaders/scatter.wgsl`): a queue write costs a few microseconds whatever
//! its size, and a frame changes a hundred scattered orders. The patch is applied by the next
//! `Sky::record` (or corner read-back); a frame prepared and never recorded keeps its patch for
//! the next one, which writes only what it adds to it, and past the size of the buffers
//! themselves the whole buffers are written instead, so nothing grows however the sky is driven.
//! The spans' count is the first entry of their buffer, so the pass binds whole buffers and its
//! bind group is made again only when one of them is replaced (making and dropping one every
//! frame was a fifth of the patch's CPU time).

use std::cell::Cell;
use std::ops::Range;

use super::resident::storage_buffer;
use crate::render::gpu_types::GpuListCloud;
use crate::render::id_hash::IdMap;

const WGSL: &str = include_str!("../../../shaders/scatter.wgsl");
/// Workgroups per dispatch row.
const ROW: u32 = 65_535;

/// What a patch writes into: the CPU copy, the buffer, the spans of the copy changed.
type Target<'a, T> = (&'a [T], &'a wgpu::Buffer, &'a mut Vec<Range<u32>>);

/// The patch being gathered and its GPU side.
pub(in crate::render) struct Scatter {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    values: Vec<u32>,
    /// `[dst, src, count, target]`: target 0 the orders, 1 the cloud lists (as words); the
    /// first entry is the header, `[spans after it, 0, 0, 0]`.
    spans: Vec<[u32; 4]>,
    patch: wgpu::Buffer,
    span_buffer: wgpu::Buffer,
    /// Bound as the list target by a patch of orders only (the impostor ring's).
    no_lists: wgpu::Buffer,
    /// How many of `values` and `spans` the GPU buffers hold already: a patch kept over frames
    /// prepared and never drawn is added to there, not written again whole each frame.
    sent: (usize, usize),
    /// The bind group over the patch's buffers and the two it writes into, with those two (it
    /// is made again when either is replaced).
    group: Option<(wgpu::BindGroup, [wgpu::Buffer; 2])>,
    /// Whether a patch was written that the next recording applies.
    ready: bool,
    /// Whether that patch went into a recorded frame (then the next one starts afresh).
    applied: Cell<bool>,
    /// The newest span of the patch by target and first slot ([`start_key`]): a cloud sorted
    /// again in a frame never drawn writes over its earlier spans instead of adding one beside
    /// them ([`Self::push`]).
    by_start: IdMap<u32>,
    /// For each span, the one before it from the same first slot ([`NO_SPAN`]: none), so that
    /// a patch's index of spans allocates nothing per span (a map of lists did, a fifth of the
    /// patch's CPU time in the Cb circle's profile).
    earlier: Vec<u32>,
}

/// No span ([`Scatter::earlier`]).
const NO_SPAN: u32 = u32::MAX;

/// The key of a first slot `dst` of `target` in [`Scatter::by_start`].
fn start_key(target: u32, dst: u32) -> u64 {
    (u64::from(target) << 32) | u64::from(dst)
}

impl Scatter {
    /// The pipeline and empty buffers.
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sky.scatter"),
            source: wgpu::ShaderSource::Wgsl(WGSL.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("sky.scatter"),
            layout: None,
            module: &module,
            entry_point: Some("cs_scatter"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            layout: pipeline.get_bind_group_layout(0),
            pipeline,
            values: Vec::new(),
            spans: vec![[0; 4]],
            patch: storage_buffer(device, "sky.scatter_patch", 16 << 10),
            span_buffer: storage_buffer(device, "sky.scatter_spans", 4 << 10),
            no_lists: storage_buffer(device, "sky.scatter_no_lists", 16),
            sent: (0, 0),
            group: None,
            ready: false,
            applied: Cell::new(true),
            by_start: IdMap::default(),
            earlier: vec![NO_SPAN],
        }
    }

    /// Bytes of its buffers.
    pub fn gpu_bytes(&self) -> u64 {
        self.patch.size() + self.span_buffer.size() + self.no_lists.size()
    }

    /// Gathers the changed spans of the orders and lists (their CPU copies) and writes the patch;
    /// a patch not yet applied is kept and added to. Returns the bytes written.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (orders, order_buffer): (&[u32], &wgpu::Buffer),
        dirty_orders: &mut Vec<Range<u32>>,
        (lists, list_buffer): (&[GpuListCloud], &wgpu::Buffer),
        dirty_lists: &mut Vec<Range<u32>>,
    ) -> u64 {
        self.prepare_any(
            device,
            queue,
            (orders, order_buffer, dirty_orders),
            Some((lists, list_buffer, dirty_lists)),
        )
    }

    /// [`Self::prepare`] for a buffer of orders alone (the impostor ring's).
    pub fn prepare_orders(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (orders, order_buffer): (&[u32], &wgpu::Buffer),
        dirty_orders: &mut Vec<Range<u32>>,
    ) -> u64 {
        self.prepare_any(device, queue, (orders, order_buffer, dirty_orders), None)
    }

    fn prepare_any(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (orders, order_buffer, dirty_orders): Target<u32>,
        lists: Option<Target<GpuListCloud>>,
    ) -> u64 {
        let (lists, list_buffer, mut dirty_lists) = match lists {
            Some((l, b, d)) => (l, b, Some(d)),
            None => (&[][..], &self.no_lists, None),
        };
        let list_buffer = list_buffer.clone();
        if self.applied.replace(false) {
            self.clear_patch();
        }
        self.ready = false;
        for r in dirty_orders.drain(..) {
            self.push(0, r.start, &orders[r.start as usize..r.end as usize]);
        }
        for r in dirty_lists.iter_mut().flat_map(|d| d.drain(..)) {
            let part = &lists[r.start as usize..r.end as usize];
            self.push(1, r.start * 4, bytemuck::cast_slice(part));
        }
        let n = self.spans.len() - 1;
        if n == 0 {
            return 0;
        }
        let whole = orders.len() + lists.len() * 4;
        if self.values.len() > whole {
            // Frames prepared and never drawn piled up more than the buffers hold: write them.
            self.clear_patch();
            queue.write_buffer(order_buffer, 0, bytemuck::cast_slice(orders));
            if !lists.is_empty() {
                queue.write_buffer(&list_buffer, 0, bytemuck::cast_slice(lists));
            }
            return whole as u64 * 4;
        }
        let value_bytes = self.values.len() as u64 * 4;
        let span_bytes = self.spans.len() as u64 * 16;
        // A buffer replaced is bound again (a bind group keeps the old one alive and reads it).
        let mut replaced = false;
        if value_bytes > self.patch.size() {
            self.patch =
                storage_buffer(device, "sky.scatter_patch", value_bytes.next_power_of_two());
            self.sent.0 = 0;
            replaced = true;
        }
        if span_bytes > self.span_buffer.size() {
            let bytes = span_bytes.next_power_of_two();
            self.span_buffer = storage_buffer(device, "sky.scatter_spans", bytes);
            self.sent.1 = 0;
            replaced = true;
        }
        self.spans[0][0] = n as u32;
        // What the buffers do not hold yet (all of it, after a drawn frame or a new buffer),
        // and the header, whose count changed.
        let (values, spans) = (&self.values[self.sent.0..], &self.spans[self.sent.1..]);
        let at = (self.sent.0 as u64 * 4, self.sent.1 as u64 * 16);
        if !values.is_empty() {
            queue.write_buffer(&self.patch, at.0, bytemuck::cast_slice(values));
        }
        let mut written = (values.len() * 4 + spans.len() * 16) as u64;
        if self.sent.1 > 0 {
            queue.write_buffer(&self.span_buffer, 0, bytemuck::cast_slice(&self.spans[..1]));
            written += 16;
        }
        if !spans.is_empty() {
            queue.write_buffer(&self.span_buffer, at.1, bytemuck::cast_slice(spans));
        }
        self.sent = (self.values.len(), self.spans.len());
        let targets = [order_buffer.clone(), list_buffer];
        if replaced
            || self
                .group
                .as_ref()
                .is_none_or(|(_, bound)| *bound != targets)
        {
            self.group = Some((self.bind_group(device, &targets), targets));
        }
        self.ready = true;
        written
    }

    /// The pass's bind group: the patch and spans buffers and `[orders, lists]`, whole.
    fn bind_group(
        &self,
        device: &wgpu::Device,
        [orders, lists]: &[wgpu::Buffer; 2],
    ) -> wgpu::BindGroup {
        fn whole(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky.scatter"),
            layout: &self.layout,
            entries: &[
                whole(0, &self.patch),
                whole(1, &self.span_buffer),
                whole(2, orders),
                whole(3, lists),
            ],
        })
    }

    /// Starts an empty patch.
    fn clear_patch(&mut self) {
        self.values.clear();
        self.spans.truncate(1);
        self.sent = (0, 0);
        self.by_start.clear();
        self.earlier.truncate(1);
    }

    /// Adds `data` for the slots from `dst` of `target`. One dispatch applies the spans in no
    /// order, so spans over the same slots (a cloud sorted again in a frame prepared and never
    /// drawn) must agree: the new values are written over the earlier spans from the same slot
    /// (sent again), and a span that holds them all takes no new one. Spans from other first
    /// slots do not meet in practice (a cloud's slots and a block's list stay put until the
    /// block goes, and a packing drops the patch).
    fn push(&mut self, target: u32, dst: u32, data: &[u32]) {
        if data.is_empty() {
            return;
        }
        let key = start_key(target, dst);
        let newest = self.by_start.get(&key).copied().unwrap_or(NO_SPAN);
        let (mut held, mut i) = (false, newest);
        while i != NO_SPAN {
            let [_, src, count, _] = self.spans[i as usize];
            let n = (count as usize).min(data.len());
            self.values[src as usize..][..n].copy_from_slice(&data[..n]);
            self.sent.0 = self.sent.0.min(src as usize);
            held |= n == data.len();
            i = self.earlier[i as usize];
        }
        if held {
            return;
        }
        self.by_start.insert(key, self.spans.len() as u32);
        self.earlier.push(newest);
        self.spans
            .push([dst, self.values.len() as u32, data.len() as u32, target]);
        self.values.extend_from_slice(data);
    }

    /// Drops a patch kept from frames prepared and never recorded: the buffers it was for were
    /// written whole since (the resident buffers were packed; its spans are at the slots of
    /// before).
    pub fn forget_kept(&mut self) {
        self.applied.set(true);
        self.ready = false;
    }

    /// Records the patch's pass into `encoder` (before anything reads the orders), if there is
    /// one; the next [`Self::prepare`] starts a new patch.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        self.applied.set(true);
        self.record_kept(encoder);
    }

    /// Records the patch's pass like [`Self::record`] but keeps the patch for the next
    /// [`Self::prepare`] to add to (the values are absolute, so applying them again is
    /// harmless): for a submission of the sky's own that only some frames make (the cloud
    /// shadow map's), so the patches, and the buffer they grow, are those of the frames the
    /// host records whether or not it comes.
    pub fn record_kept(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some((group, _)) = self.group.as_ref().filter(|_| self.ready) else {
            return;
        };
        let n = self.spans.len() as u32 - 1;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("sky.scatter"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        // One workgroup a span, in rows of 65,535; the last row's extra groups find no span
        // (the header's count bounds them).
        pass.dispatch_workgroups(n.min(ROW), n.div_ceil(ROW), 1);
    }
}
