//! What the shadow tests (`tests/shadows.rs`, `tests/shadows_cirrus.rs`) share: the demo host
//! over the shipped bulk file, the sun's time at an elevation, and a quantile.

use std::path::Path;

use glam::DVec2;
use skycast::demo::DemoHost;
use skycast::demo::terrain::HeightField;
use skycast::flight::{SkySystemConfig, Weather};

/// The frame the shadow tests draw, pixels across.
pub const W: u32 = 320;
/// The frame the shadow tests draw, pixels down.
pub const H: u32 = 180;
/// The shipped bulk weather file.
pub const METARS: &str = "weather/awc-metars-2025-01-27T22Z.cache.csv";
/// The shipped weather file's time, 2025-01-27T22:00:00Z.
pub const UNIX_S: f64 = 1_738_015_200.0;

/// A demo host of `config` over flat ground, the shipped bulk file its weather, every cloud
/// around in the first frame (as `skycast render` has it: a simulator's first frames wait for
/// none and fade them in as they arrive).
pub fn host_over(config: SkySystemConfig) -> DemoHost {
    let flat = HeightField::from_fn(DVec2::ZERO, 1_000.0, 2, |_| 0.0);
    let mut host = DemoHost::new(W, H, &flat, config)
        .unwrap_or_else(|e| panic!("shadow tests need an adapter: {e}"));
    host.sky.world_mut().set_synchronous_clouds(true);
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    host.sky
        .set_weather(Weather::File(&manifest.join(METARS)))
        .unwrap();
    host
}

/// The first instant after `from_s` (whole seconds, going forward) the sun stands at
/// `elevation_deg` or lower over `at`.
pub fn sun_down_to(at: (f64, f64), from_s: f64, elevation_deg: f64) -> f64 {
    let elevation = |t: f64| skycast::shading::sun_position(t, at.0, at.1).elevation_deg;
    let (mut lo, mut hi) = (from_s, from_s + 6.0 * 3600.0);
    assert!(elevation(lo) > elevation_deg && elevation(hi) < elevation_deg);
    while hi - lo > 1.0 {
        let mid = 0.5 * (lo + hi);
        if elevation(mid) > elevation_deg {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The quantile `q` of `v` (sorted in place); 0 for none.
pub fn quantile(v: &mut [f32], q: f32) -> f32 {
    v.sort_by(f32::total_cmp);
    let k = ((v.len() as f32 * q) as usize).min(v.len().saturating_sub(1));
    v.get(k).copied().unwrap_or(0.0)
}
