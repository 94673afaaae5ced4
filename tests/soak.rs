//! Hours of flight through changing weather: nothing the sky holds grows. A weather file, watched
//! as `skycast fly --watch` watches one, is rewritten every five simulated minutes through six
//! weathers of very different sprite counts (clear, FEW, SCT and BKN cumulus, an overcast deck,
//! thunderstorm cells) while the camera circles; one frame a simulated second, every tenth drawn
//! (192 x 108) and read back. Every buffer and texture the sky holds is counted
//! ([`skycast::render::SkyMemory`]: the ring and the off-screen cloud target included), with the
//! blocks and slots behind them and the queues of the live weather.
//!
//! The circle takes five minutes, as long as a weather lasts, and the air is calm: each cycle of
//! the six weathers meets the camera at the same places, so each asks the sky for the same
//! blocks, and any growth from one cycle to the next is the sky's own. The sprite buffers are
//! sized by the most sprites held at once (`docs/src/long-flights.md`); the cloud buffer grew
//! from 256 slots to 4,096 (553 KB) two hours into a flight when a block's clouds found no free
//! range long enough, though there were slots enough in all.
//!
//! `make test` flies one hour; `make soak` flies `SOAK_HOURS` (6) and prints the figures of each
//! hour. Its own test binary, so that no other test's allocations move the process's memory.

#[path = "support/rss.rs"]
mod rss;

use rss::rss_bytes;

use std::path::{Path, PathBuf};
use std::time::Duration;

use glam::DVec3;
use skycast::demo::{DemoHost, GroundSettings, demo_ground};
use skycast::flight::{SkySystemConfig, Weather};
use skycast::render::{SkyMemory, resident_slots_bound};
use skycast::shading::FogSettings;
use skycast::weather::{CloudTypeRule, FieldSettings, LocalFrame, WeatherInput};

const W: u32 = 192;
const H: u32 = 108;
/// San Antonio International (KSAT): the frame origin.
const ORIGIN: (f64, f64) = (29.53, -98.47);
/// 2025-01-27 22:00 UTC: the afternoon sun over San Antonio.
const UTC_S: f64 = 1_738_015_200.0;
/// A weather lasts five minutes, and the circle takes as long.
const WEATHER_S: u64 = 300;
const SPEED_M_S: f64 = 60.0;
/// Blocks within 8 km of the camera get clouds (the shipped 60 km would hold 14 times more).
const FIELD_RADIUS_M: f64 = 8_000.0;

fn manifest(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A calm theme with one cloud layer (`None`: clear).
fn theme(name: &str, layer: Option<(&str, &str, u32, u32)>) -> String {
    let mut t = format!(
        "name = \"{name}\"\n[surface]\nvisibility_m = 40000\nwind_speed_kt = 0\n\
         temperature_c = 24\ndewpoint_c = 11\n"
    );
    // A clear sky says it has no layers (a TOML file without them is not taken for weather).
    let Some((cloud_type, cover, base_ft, top_ft)) = layer else {
        return format!("layers = []\n{t}");
    };
    {
        t += &format!(
            "[[layers]]\ncloud_type = \"{cloud_type}\"\ncover = \"{cover}\"\n\
             base_ft = {base_ft}\ntop_ft = {top_ft}\n"
        );
    }
    t
}

/// The six weathers, in the order they come: their names and theme files.
fn weathers() -> Vec<(&'static str, String)> {
    // The shipped thunderstorm theme, made calm (its 10 kt would move the field on by 1.5 km
    // each cycle, so that cycles would ask for different blocks).
    let storm = std::fs::read_to_string(manifest("weather/themes/thunderstorm_cells.toml"))
        .expect("the storm theme")
        .replace("wind_speed_kt = 10", "wind_speed_kt = 0");
    assert!(
        storm.contains("wind_speed_kt = 0"),
        "the storm theme's wind"
    );
    vec![
        ("clear", theme("Clear", None)),
        (
            "FEW cumulus",
            theme("Few", Some(("cumulus_mediocris", "FEW", 4000, 6500))),
        ),
        (
            "SCT cumulus",
            theme("Scattered", Some(("cumulus_mediocris", "SCT", 4000, 6500))),
        ),
        (
            "BKN cumulus",
            theme("Broken", Some(("cumulus_congestus", "BKN", 3500, 9000))),
        ),
        (
            "OVC stratocumulus",
            theme("Overcast", Some(("stratocumulus", "OVC", 3000, 4500))),
        ),
        ("thunderstorm cells", storm),
    ]
}

/// Generations in the living field, blocks queued for generation, timed weather events waiting.
type Queues = (usize, usize, usize);

fn queues(host: &DemoHost) -> Queues {
    let field = host.sky.world().living_field().expect("the living field");
    (
        field.blocks().count(),
        field.pending(),
        host.sky.weather_events_pending(),
    )
}

/// What one simulated hour (or cycle of the weathers) held at most, and at its end.
#[derive(Debug, Default, Clone, Copy)]
struct Span {
    gpu_max: u64,
    rss_max: u64,
    sprite_slots_max: u32,
    cloud_slots_max: u32,
    /// Sprites and clouds on the GPU at once, at most.
    sprites_held_max: u32,
    clouds_held_max: u32,
    blocks_max: u32,
    sprites_max: u32,
    /// Generations in the field and blocks queued for generation, at most.
    generations_max: usize,
    generating_max: usize,
    /// Timed weather events waiting, at most.
    events_max: usize,
    last: SkyMemory,
}

impl Span {
    fn add(&mut self, m: &SkyMemory, rss: u64, (generations, generating, events): Queues) {
        self.gpu_max = self.gpu_max.max(m.gpu_bytes());
        self.rss_max = self.rss_max.max(rss);
        self.sprite_slots_max = self.sprite_slots_max.max(m.sprite_slots);
        self.cloud_slots_max = self.cloud_slots_max.max(m.cloud_slots);
        self.sprites_held_max = self.sprites_held_max.max(m.sprite_slots_used);
        self.clouds_held_max = self.clouds_held_max.max(m.cloud_slots_used);
        self.blocks_max = self.blocks_max.max(m.blocks);
        self.sprites_max = self.sprites_max.max(m.sprites);
        self.generations_max = self.generations_max.max(generations);
        self.generating_max = self.generating_max.max(generating);
        self.events_max = self.events_max.max(events);
        self.last = *m;
    }
}

/// What a soak saw: per simulated hour and per cycle of the six weathers.
struct Soak {
    hours: Vec<Span>,
    cycles: Vec<Span>,
    /// Sprites drawn at most under each weather (by its index), over the whole flight.
    drawn: Vec<u32>,
    /// Sprites held in the last second of each weather (the one before mostly gone), at most.
    settled: Vec<u32>,
}

/// Flies `hours` simulated hours; prints each hour's figures.
fn soak(hours: u64) -> Soak {
    let weathers = weathers();
    let dir = std::env::temp_dir().join(format!("skycast-soak-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let live = dir.join("live.toml");
    std::fs::write(&live, &weathers[0].1).unwrap();
    let first = WeatherInput::load(&live, None).unwrap().field(
        LocalFrame::new(ORIGIN.0, ORIGIN.1),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    let mut config = SkySystemConfig::new(skycast::demo::headless::TARGETS, ORIGIN);
    config.world.cloud_radius_m = FIELD_RADIUS_M;
    let ground = GroundSettings {
        size_m: 60_000.0,
        samples: 65,
        ..GroundSettings::default()
    };
    let mut host = DemoHost::new(W, H, &demo_ground(&first, &ground), config)
        .unwrap_or_else(|e| panic!("the soak needs an adapter: {e}"));
    let settle = Duration::from_millis(50);
    host.sky
        .set_weather(Weather::Watch {
            path: &live,
            settle,
        })
        .unwrap();
    // Blocks arrive in the frame they are queued, so every cycle draws the same frames.
    host.sky.world_mut().set_synchronous_clouds(true);
    // The weathers are calm so that every cycle asks for the same blocks: without the least
    // gradient wind a calm region has (`[wind] calm_gradient_kt`) their clouds stay put too.
    let mut air = *host.sky.world().air_settings();
    air.wind.calm_gradient_kt = 0.0;
    host.sky
        .world_mut()
        .set_air_settings(air, FogSettings::default());
    let radius_m = SPEED_M_S * WEATHER_S as f64 / std::f64::consts::TAU;
    let cycle_s = WEATHER_S * weathers.len() as u64;
    let mut soak = Soak {
        hours: Vec::new(),
        cycles: Vec::new(),
        drawn: vec![0; weathers.len()],
        settled: vec![0; weathers.len()],
    };
    let mut hour = Span::default();
    let mut cycle = Span::default();
    let mut time_s = 0.0;
    for s in 0..hours * 3600 {
        let k = (s / WEATHER_S) as usize;
        let a = time_s * SPEED_M_S / radius_m;
        let position = DVec3::new(radius_m * a.cos(), radius_m * a.sin(), 900.0);
        let camera = host.camera(position, 90.0, 8.0);
        if s > 0 && s % WEATHER_S == 0 {
            // The next weather, written over the watched file; the flight's clock waits (frames
            // of no time) until the watch has read and built it.
            std::fs::write(&live, &weathers[k % weathers.len()].1).unwrap();
            let mut arrived = Vec::new();
            for _ in 0..2_000 {
                let (_, changes) = host.step(&camera, UTC_S + time_s, 0.0, false).unwrap();
                arrived.extend(changes);
                // The new generations are placed in this frame: its slots count.
                let (m, q) = (host.sky.sky().memory(), queues(&host));
                hour.add(&m, rss_bytes(), q);
                cycle.add(&m, rss_bytes(), q);
                if !arrived.is_empty() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(5));
            }
            assert!(
                matches!(&arrived[..], [Ok(p)] if p == &live),
                "at {s} s, the change to {}: {arrived:?}",
                weathers[k % weathers.len()].0
            );
        }
        let draw = s % 10 == 0;
        let (stats, changes) = host.step(&camera, UTC_S + time_s, 1.0, draw).unwrap();
        assert!(changes.is_empty(), "at {s} s: {changes:?}");
        if draw {
            host.target.read_back(&host.gpu).unwrap();
            let w = k % weathers.len();
            soak.drawn[w] = soak.drawn[w].max(stats.sprites_drawn);
        }
        time_s += 1.0;
        let (m, q, rss) = (host.sky.sky().memory(), queues(&host), rss_bytes());
        if (s + 1) % WEATHER_S == 0 {
            let w = k % weathers.len();
            soak.settled[w] = soak.settled[w].max(m.sprites);
        }
        hour.add(&m, rss, q);
        cycle.add(&m, rss, q);
        if (s + 1) % cycle_s == 0 {
            soak.cycles.push(std::mem::take(&mut cycle));
        }
        if (s + 1) % 3600 == 0 {
            let h = std::mem::take(&mut hour);
            let mb = |b: u64| b as f64 / 1e6;
            eprintln!(
                "hour {}: RSS {:.1} MB (at most {:.1}); GPU {:.3} MB (at most {:.3}: resident \
                 {:.3}, drawing {:.3}, ring {:.3}, cloud target {:.3}, sheet {:.3}); blocks {} \
                 (at most {}) of {} sprites (at most {}); sprite slots {}/{} (at most {}), cloud \
                 slots {}/{} (at most {}); field generations at most {}, queued for generation \
                 at most {}, weather events waiting at most {}",
                soak.hours.len() + 1,
                mb(rss),
                mb(h.rss_max),
                mb(h.last.gpu_bytes()),
                mb(h.gpu_max),
                mb(h.last.resident_bytes),
                mb(h.last.draw_bytes),
                mb(h.last.ring_bytes),
                mb(h.last.cloud_target_bytes),
                mb(h.last.sheet_bytes),
                h.last.blocks,
                h.blocks_max,
                h.last.sprites,
                h.sprites_max,
                h.last.sprite_slots_used,
                h.last.sprite_slots,
                h.sprite_slots_max,
                h.last.cloud_slots_used,
                h.last.cloud_slots,
                h.cloud_slots_max,
                h.generations_max,
                h.generating_max,
                h.events_max,
            );
            soak.hours.push(h);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    let names = || weathers.iter().map(|w| w.0);
    eprintln!(
        "most sprites drawn under each weather: {:?}",
        names().zip(&soak.drawn).collect::<Vec<_>>()
    );
    eprintln!(
        "sprites held at the end of each weather: {:?}",
        names().zip(&soak.settled).collect::<Vec<_>>()
    );
    for (c, span) in soak.cycles.iter().enumerate() {
        eprintln!(
            "cycle {}: GPU at most {} bytes, sprite slots {} for {} held at most, cloud \
             slots {} for {}; {} blocks of {} sprites at most",
            c + 1,
            span.gpu_max,
            span.sprite_slots_max,
            span.sprites_held_max,
            span.cloud_slots_max,
            span.clouds_held_max,
            span.blocks_max,
            span.sprites_max
        );
    }
    soak
}

/// What every soak holds to: the clouds were drawn (all but the clear sky); the resident
/// buffers are within their bound for the most sprites and clouds held at once so far
/// ([`resident_slots_bound`]); and once every weather has been seen (the first cycle), nothing
/// the sky holds on the GPU grows, unless the cycle held more at once than any before it (a
/// new high-water mark: the camera's path through the block grid differs from cycle to cycle,
/// and a cycle can hold a block or two more). Each cycle's most is then at most the one
/// before's; a cycle that sets a new mark grows within the bound above, and the last cycle
/// sets none (a leak of held blocks would set one every cycle).
fn check(soak: &Soak) {
    for (w, &drawn) in soak.drawn.iter().enumerate().skip(1) {
        assert!(drawn > 0, "weather {w} drew no sprite");
    }
    // The buffers never shrink: their bound is the most held so far, not in this cycle alone.
    let (mut sprites_held, mut clouds_held) = (0, 0);
    for (c, span) in soak.cycles.iter().enumerate() {
        sprites_held = span.sprites_held_max.max(sprites_held);
        clouds_held = span.clouds_held_max.max(clouds_held);
        let bound = resident_slots_bound(sprites_held, clouds_held);
        assert!(
            span.sprite_slots_max <= bound.0 && span.cloud_slots_max <= bound.1,
            "cycle {}: {} sprite slots and {} cloud slots for at most {sprites_held} sprites \
             and {clouds_held} clouds held so far (bound {bound:?})",
            c + 1,
            span.sprite_slots_max,
            span.cloud_slots_max,
        );
    }
    for c in 1..soak.cycles.len() {
        let (before, after) = (&soak.cycles[c - 1], &soak.cycles[c]);
        let earlier = &soak.cycles[..c];
        let new_mark = earlier
            .iter()
            .all(|e| after.sprites_held_max > e.sprites_held_max)
            || earlier
                .iter()
                .all(|e| after.clouds_held_max > e.clouds_held_max);
        // A leak of held blocks would set a new mark every cycle, the last one too.
        assert!(
            !(new_mark && c + 1 == soak.cycles.len()),
            "the last cycle, {}, held more at once than any before: {} sprites, {} clouds",
            c + 1,
            after.sprites_held_max,
            after.clouds_held_max
        );
        if new_mark {
            eprintln!(
                "cycle {} held more at once than any before ({} sprites, {} clouds): its \
                 growth is checked against the bound only",
                c + 1,
                after.sprites_held_max,
                after.clouds_held_max
            );
            continue;
        }
        assert!(
            after.gpu_max <= before.gpu_max,
            "cycle {} held {} GPU bytes, the one before {}, holding no more at once than \
             before ({} sprites, {} clouds)",
            c + 1,
            after.gpu_max,
            before.gpu_max,
            after.sprites_held_max,
            after.clouds_held_max
        );
        assert!(
            after.sprite_slots_max <= before.sprite_slots_max
                && after.cloud_slots_max <= before.cloud_slots_max,
            "cycle {}: sprite slots {} after {}, cloud slots {} after {}",
            c + 1,
            after.sprite_slots_max,
            before.sprite_slots_max,
            after.cloud_slots_max,
            before.cloud_slots_max
        );
    }
}

/// One simulated hour: two cycles of the six weathers.
#[test]
fn one_hour_of_weather_changes_holds_no_more_than_its_first_cycle() {
    let soak = soak(1);
    assert_eq!(soak.cycles.len(), 2);
    check(&soak);
}

/// `make soak`: `SOAK_HOURS` (6) simulated hours; the resident memory grows by less than 2%
/// from the first hour to the last.
#[test]
#[ignore = "hours of flight: make soak"]
fn hours_of_weather_changes_do_not_grow() {
    let hours = std::env::var("SOAK_HOURS")
        .ok()
        .map(|h| {
            h.parse::<u64>()
                .expect("SOAK_HOURS: a whole number of hours")
        })
        .unwrap_or(6);
    assert!(hours >= 2, "SOAK_HOURS: at least 2, to compare hours");
    let soak = soak(hours);
    check(&soak);
    let (first, last) = (
        soak.hours[0].rss_max,
        soak.hours[soak.hours.len() - 1].rss_max,
    );
    eprintln!(
        "RSS at most {:.1} MB in hour 1, {:.1} MB in hour {hours}: {:+.2}%",
        first as f64 / 1e6,
        last as f64 / 1e6,
        (last as f64 / first as f64 - 1.0) * 100.0
    );
    assert!(
        last * 100 < first * 102,
        "RSS grew from {first} to {last} bytes"
    );
}
