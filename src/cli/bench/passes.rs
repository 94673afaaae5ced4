//! `skycast bench --passes`: where each run's steady frames spend their GPU time, by group of
//! the sky's passes ([`PassTimes`]: the compute build, the background or the downsample, the
//! far field, the impostor ring, the sprites, the composite), medians over the steady frames.

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
    let timed: Vec<(&Run, Vec<&PassTimes>)> = runs
        .iter()
        .map(|r| (r, r.steady().filter_map(|f| f.passes.as_ref()).collect()))
        .filter(|(_, p): &(&Run, Vec<&PassTimes>)| !p.is_empty())
        .collect();
    if timed.is_empty() {
        return;
    }
    println!(
        "where the sky's GPU time goes (medians of the steady frames, ms; the far field, the ring and the sprites in passes of their own):"
    );
    println!(
        "{:<10} {:>9} {:>5} {:>8} {:>11} {:>9} {:>8} {:>8} {:>10} {:>8} {:>8}",
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
        "sum"
    );
    for (run, passes) in timed {
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
        println!(
            "{:<10} {:>9} {:>5} {:>8.2} {:>11.2} {:>9.2} {:>8.2} {:>8.2} {:>10.2} {:>8.2} {:>8.2}",
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
        );
    }
}
