//! Tests of the ring's orders: the sorting budget, the orders kept between builds, and the
//! order buffer's copy (written once a sort, again only where a cloud moved).

use glam::DVec3;

use super::*;
use crate::render::scene::SkyCloud;
use crate::render::sprites::draw_list::sprites_back_to_front;
use crate::render::sprites::draw_list::tests::{cache, small_cloud};
use crate::render::sprites::resident::Resident;

/// `blocks` blocks of `clouds` small clouds each, 30 km north of the origin in a row, placed
/// (slots given as the sky would) so that the ring's views can be read.
fn far_row(blocks: u64, clouds: usize) -> Blocks {
    let mut base = 0u32;
    (0..blocks)
        .map(|id| {
            let centre = DVec3::new(id as f64 * 4000.0, 30_000.0, 1500.0);
            let block = crate::render::scene::SkyBlock {
                id,
                centre_m: centre,
                clouds: (0..clouds)
                    .map(|k| SkyCloud {
                        centre_m: centre + DVec3::new(k as f64 * 500.0, 0.0, 0.0),
                        ..small_cloud()
                    })
                    .collect(),
            };
            let mut r = Resident::new(block, Default::default());
            let start = base;
            for (k, state) in r.clouds.iter_mut().enumerate() {
                state.sprite_base = base;
                state.cloud_slot = id as u32 * clouds as u32 + k as u32;
                base += state.sprites;
            }
            r.place = Some((start..base, 0..clouds as u32));
            r.place_serial = id + 1;
            (id, r)
        })
        .collect()
}

/// The ring's sprite orders are sorted a budget at a time: no call sorts more sprites than it is
/// given (the frame's budget left after the sky camera's clouds), the impostor's view is made
/// only once every cloud has its order, and that view is the back-to-front order from the ring
/// centre. A later build from nearly the same centre (the far blocks changed, the sun turned)
/// sorts nothing; one 3 km away sorts every cloud again. Sorting the whole sector in one call,
/// as the ring did before, fails the budget here.
#[test]
fn ring_orders_are_sorted_within_the_frames_budget_and_kept_between_builds() {
    let blocks = far_row(4, 3);
    let ids: Vec<u64> = (0..4).collect();
    let cache = cache();
    let centre = DVec3::new(0.0, 0.0, 1000.0);
    let reach = (centre, 100_000.0);
    let mut ring = RingOrders::default();
    ring.fit(480);
    let when = |since_s: f64, time_s: f64| RingSort {
        gather: since_s as u64,
        since_s,
        time_s,
        cache: &cache,
        largest: 100,
    };
    // 12 clouds of 40 sprites, 100 sprites a frame: two clouds a frame, six frames.
    let mut frames = 0;
    let mut total = 0;
    loop {
        let mut budget = 100;
        let (done, sorted) = ring.sort(
            &blocks,
            &ids,
            reach,
            &when(0.0, frames as f64 * 0.1),
            &mut budget,
        );
        assert!(sorted <= 100, "frame {frames}: {sorted} sprites sorted");
        assert_eq!(budget, 100 - sorted);
        total += sorted;
        frames += 1;
        if done {
            break;
        }
        assert!(frames < 20, "never done");
    }
    assert_eq!((frames, total), (6, 480));
    // The sorts wrote every order at its cloud's slots; the view writes none again.
    let mut spans = Vec::new();
    assert_eq!(ring.take_dirty(&mut spans), 0);
    assert_eq!(spans, vec![0..480]);
    let (mut out, mut lists) = (Vec::new(), Vec::new());
    let sprites = ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    assert_eq!(sprites, 480);
    assert_eq!(lists.len(), 12);
    assert_eq!(ring.take_dirty(&mut spans), 0);
    assert_eq!(spans, vec![0..480], "the view wrote orders");
    // Farthest block first; within each cloud the slots in the reference order from the centre.
    assert_eq!(out.len(), 4);
    assert!(out[0].origin_rel[0] > out[3].origin_rel[0], "{out:?}");
    assert_slots_hold_orders(&ring, &blocks, &lists, centre, 100);
    // A rebuild 20 s later from 50 m away: every order still good (Wang's thresholds 30 km out
    // allow 605 m and 32 s). From 3 km away: all sorted again, within the budget.
    let near = (centre + DVec3::new(50.0, 0.0, 0.0), 100_000.0);
    let mut budget = 100;
    assert_eq!(
        ring.sort(&blocks, &ids, near, &when(20.0, 20.0), &mut budget),
        (true, 0)
    );
    let moved = (centre + DVec3::new(3000.0, 0.0, 0.0), 100_000.0);
    let mut budget = 100;
    assert_eq!(
        ring.sort(&blocks, &ids, moved, &when(21.0, 21.0), &mut budget),
        (false, 80)
    );
    // A cloud larger than any frame's budget is never sorted (nor waited for): it goes in in
    // its sprites' own order, written by the first view that draws it, and by no later one.
    let mut ring = RingOrders::default();
    ring.fit(480);
    let mut budget = 30;
    let big = RingSort {
        largest: 30,
        ..when(0.0, 0.0)
    };
    assert_eq!(
        ring.sort(&blocks, &ids, reach, &big, &mut budget),
        (true, 0)
    );
    ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    assert_eq!(ring.take_dirty(&mut spans), 480);
    assert_slots_hold_orders(&ring, &blocks, &lists, centre, 30);
    ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    assert_eq!(ring.take_dirty(&mut spans), 0);
}

/// A block placed again (another placing: the resident buffers packed) has its clouds' orders
/// written at its new slots by the next view, without a sort, and a block that takes the slots
/// another one's orders were written at has its own written over them: the order buffer never
/// shows a cloud another cloud's order. Blocks that stayed are not written again.
#[test]
fn orders_follow_their_clouds_to_other_slots() {
    let mut blocks = far_row(4, 3);
    let ids: Vec<u64> = (0..4).collect();
    let cache = cache();
    let centre = DVec3::new(0.0, 0.0, 1000.0);
    let reach = (centre, 100_000.0);
    let when = RingSort {
        gather: 0,
        since_s: 0.0,
        time_s: 0.0,
        cache: &cache,
        largest: 100,
    };
    let mut ring = RingOrders::default();
    ring.fit(960);
    assert_eq!(
        ring.sort(&blocks, &ids, reach, &when, &mut { u32::MAX }),
        (true, 480)
    );
    let (mut out, mut lists, mut spans) = (Vec::new(), Vec::new(), Vec::new());
    ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    ring.take_dirty(&mut spans);
    // Blocks 0 and 1 swap slots; block 3 moves up to 480.. .
    let place = |blocks: &mut Blocks, id: u64, start: u32| {
        let r = blocks.get_mut(&id).unwrap();
        let mut base = start;
        for state in &mut r.clouds {
            state.sprite_base = base;
            base += state.sprites;
        }
        r.place = Some((start..base, r.place.clone().unwrap().1));
        // Another placing, as the resident set numbers them.
        r.place_serial += 100;
    };
    place(&mut blocks, 0, 120);
    place(&mut blocks, 1, 0);
    place(&mut blocks, 3, 480);
    spans.clear();
    ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    assert_eq!(ring.take_dirty(&mut spans), 360, "{spans:?}");
    spans.sort_by_key(|r| r.start);
    assert_eq!(
        spans,
        vec![0..120, 120..240, 480..600],
        "block 2 was written again"
    );
    assert_slots_hold_orders(&ring, &blocks, &lists, centre, 100);
    // A block placed again at the slots it had is written again too (its slots may have held
    // another block's orders meanwhile); gone blocks' orders are forgotten.
    place(&mut blocks, 2, 240);
    spans.clear();
    ring.view(&blocks, &ids, reach, &mut out, &mut lists);
    assert_eq!(ring.take_dirty(&mut spans), 120, "{spans:?}");
    assert_eq!(spans, vec![240..360]);
    blocks.remove(&3);
    ring.retain(&blocks);
    assert!(!ring.kept.contains_key(&3));
}

/// Every listed cloud's orders in the ring's slots are its sprites' slots back to front from
/// `centre`, or their own order for a cloud of more than `largest` sprites.
fn assert_slots_hold_orders(
    ring: &RingOrders,
    blocks: &Blocks,
    lists: &[GpuListCloud],
    centre: DVec3,
    largest: u32,
) {
    for list in lists {
        let (r, ci) = blocks
            .values()
            .find_map(|r| {
                let ci = r.clouds.iter().position(|c| c.cloud_slot == list.cloud)?;
                Some((r, ci))
            })
            .unwrap();
        let state = &r.clouds[ci];
        assert_eq!(list.order_base, state.sprite_base, "cloud {}", list.cloud);
        let rel = (centre - (state.centre_m + r.offset_m())).as_vec3();
        let reference: Vec<u32> = if state.sprites > largest {
            (state.sprite_base..state.sprite_base + state.sprites).collect()
        } else {
            sprites_back_to_front(&r.block.clouds[ci], rel)
                .iter()
                .map(|s| state.sprite_base + s.0 as u32)
                .collect()
        };
        let at = list.order_base as usize;
        let held = &ring.slots()[at..at + state.sprites as usize];
        assert_eq!(held, &reference[..], "cloud {}", list.cloud);
    }
}
