//! `skycast bench --passes`: where each run's steady frames spend their GPU time, by group of
//! the sky's passes ([`PassTimes`]: the compute build, the background or the downsample, the
//! far field, the impostor ring, the sprites, the composite), medians over the steady frames,
//! and what the frames that draw into the cloud shadow map spend on it (a steady frame draws
//! nothing there: the map is drawn only as it scrolls, as blocks arrive or leave and as clouds
//! form).

use skycast::render::PassTimes;

use super::{Run, quantile, scale_text};

/// How to read one group's milliseconds.
type Read = fn(&PassTimes) -> f64;

/// The groups, as the table and `frames.csv` name them, and how to read each.
pub const COLUMNS: [(&str, Read); 7] = [
    ("build_ms", |p| p.build_ms),
    ("background_ms", |p| p.background_ms),
    ("far_field_ms", |p| p.far_field_ms),
    ("ring_ms", |p| p.ring_ms),
    ("sprites_ms", |p| p.sprites_ms),
    ("composite_ms", |p| p.composite_ms),
    ("shadow_ms", |p| p.shadow_ms),
];

/// The table of the runs' medians per group (nothing when no frame was timed by pass).
pub fn print(runs: &[Run]) {
    let timed: Vec<(&Run, Vec<&PassTimes>, Vec<f64>)> = runs
        .iter()
        .map(|r| {
            let steady: Vec<&PassTimes> = r.steady().filter_map(|f| f.passes.as_ref()).collect();
            let map_drawn: Vec<f64> = r
                .frames
                .iter()
                .filter(|f| f.shadow_sprites > 0 || f.shadow_texels > 0)
                .filter_map(|f| f.passes.as_ref().map(|p| p.shadow_ms))
                .collect();
            (r, steady, map_drawn)
        })
        .filter(|(_, p, _)| !p.is_empty())
        .collect();
    if timed.is_empty() {
        return;
    }
    println!(
        "where the sky's GPU time goes (medians of the steady frames, ms; the far field, the ring and the sprites in passes of their own; map draws: the shadow pass's median over the frames that drew into the map, and how many of the run's frames did):"
    );
    println!(
        "{:<10} {:>9} {:>5} {:>8} {:>11} {:>9} {:>8} {:>8} {:>10} {:>8} {:>8} {:>15}",
        "scenario",
        "impostors",
        "scale",
        "build",
        "background",
        "far field",
        "ring",
        "sprites",
        "composite",
        "shadows",
        "sum",
        "map draws"
    );
    for (run, passes, map_drawn) in timed {
        let median =
            |read: Read| quantile(&passes.iter().map(|p| read(p)).collect::<Vec<_>>(), 0.5);
        let [
            build,
            background,
            far_field,
            ring,
            sprites,
            composite,
            shadows,
        ] = COLUMNS.map(|(_, read)| median(read));
        let map_draws = format!(
            "{:.2} ({}/{})",
            quantile(&map_drawn, 0.5),
            map_drawn.len(),
            run.frames.len()
        );
        println!(
            "{:<10} {:>9} {:>5} {:>8.2} {:>11.2} {:>9.2} {:>8.2} {:>8.2} {:>10.2} {:>8.2} {:>8.2} {:>15}",
            run.scenario,
            if run.impostors { "on" } else { "off" },
            scale_text(run.cloud_scale),
            build,
            background,
            far_field,
            ring,
            sprites,
            composite,
            shadows,
            median(PassTimes::total_ms),
            map_draws,
        );
    }
}
