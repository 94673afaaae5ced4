// Pass `sky.scatter`: writes the sprite orders and cloud lists that changed this frame into the
// resident buffers, from one upload of all of them (the CPU sends one patch, not a write per
// cloud). One workgroup per span; a span copies `count` words of the patch to `dst` of its
// target (0: orders, 1: cloud lists, as words).

// Keep in sync with the spans built in src/render/sprites/scatter.rs.
struct Span {
    dst: u32,
    src: u32,
    count: u32,
    which: u32,
};

// The spans of the patch after a header that counts them: the buffers are bound whole, and
// hold more than this patch's spans.
struct Spans {
    count: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    list: array<Span>,
};

@group(0) @binding(0) var<storage, read> patch_words: array<u32>;
@group(0) @binding(1) var<storage, read> spans: Spans;
@group(0) @binding(2) var<storage, read_write> orders: array<u32>;
@group(0) @binding(3) var<storage, read_write> lists: array<u32>;

@compute @workgroup_size(64)
fn cs_scatter(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_id) local: vec3<u32>) {
    let index = group.x + group.y * 65535u;
    if (index >= spans.count) {
        return;
    }
    let span = spans.list[index];
    for (var i = local.x; i < span.count; i += 64u) {
        let value = patch_words[span.src + i];
        if (span.which == 0u) {
            orders[span.dst + i] = value;
        } else {
            lists[span.dst + i] = value;
        }
    }
}
