//! `skycast fly --weather FILE --path FLIGHT.toml --out DIR [--size WxH] [--every N]`: flies a
//! scripted path through the real weather. Every simulated frame runs the sky's CPU update (so
//! the vertex cache sees the real frame rate); every Nth frame is drawn and written as PNG.
//! `frames.csv` has one row per simulated frame (GPU milliseconds on drawn frames where the
//! adapter has timestamp queries). The clouds live: the clouds stage's field
//! generates blocks in the background, drifts them with the wind and forms and dissipates them.
//!
//! Live weather: with `--watch` the weather file is watched; the flight path's timed weather
//! events (a front passing) go the same way. A new weather is decoded and its field built off the
//! frame thread; each changed block's clouds dissipate while the new ones form (durations from
//! `--clouds`). `frames.csv` says per frame how long the frame thread spent on weather
//! (`weather_us`: polling and switching, never loading) and which file was applied.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use glam::DVec2;
use skycast::clouds::CloudsConfig;
use skycast::demo::{DemoHost, GroundSettings, HeightField, ground_from_field};
use skycast::flight::{FlightPath, FlightPlan, HostPosition, Weather};
use skycast::render::Stopwatch;
use skycast::weather::{LocalFrame, METRES_PER_FOOT, WeatherField, theme};

use super::render::{
    ElevationArgs, LookArgs, demo_ground_reach_m, parse_size, parse_time, sky_config,
    time_or_default,
};
use super::weather::{WindsAloftArgs, load};

/// The demo ground under a whole flight: over its track, with as much ground around it as is
/// seen from its highest point ([`demo_ground_reach_m`]), at the shipped vertex count. A square
/// around the start alone ended 65 km east of Los Angeles, which from FL350 three minutes into
/// the eastbound flight showed as a straight edge across the cloud field (sky instead of
/// ground between the clouds beyond it).
fn ground_under_flight(field: &WeatherField, flight: &FlightPath) -> HeightField {
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    let mut top_m = f64::MIN;
    // A pose every 5 s: a track bends little in that time.
    let steps = (flight.duration_s() / 5.0).ceil().max(1.0) as u32;
    for k in 0..=steps {
        let t = flight.start_s() + flight.duration_s() * f64::from(k) / f64::from(steps);
        let p = flight.pose_at(t).position_m;
        (lo, hi) = (lo.min(p.truncate()), hi.max(p.truncate()));
        top_m = top_m.max(p.z);
    }
    let shipped = GroundSettings::default();
    let reach_m = demo_ground_reach_m(top_m / METRES_PER_FOOT);
    let size_m = (hi - lo).max_element() + 2.0 * reach_m;
    ground_from_field(
        field,
        (lo + hi) / 2.0,
        size_m,
        shipped.samples,
        shipped.relief_m,
    )
}

/// Flags of `skycast fly`.
#[derive(Debug, Args)]
pub struct FlyArgs {
    /// The weather file: metars.cache.csv, a NOAA cycle file, one METAR a line, a weather
    /// theme (`.toml`), or a weather model's GRIB2 file (told by its content).
    #[arg(long)]
    pub weather: PathBuf,
    /// The model under the reports.
    #[command(flatten)]
    pub model: super::model::ModelArgs,
    /// Station table placing reports the file does not place.
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// The winds aloft for the air data (watched with `--watch`).
    #[command(flatten)]
    pub aloft: WindsAloftArgs,
    /// The flight path (TOML, see config/flights/).
    #[arg(long)]
    pub path: PathBuf,
    /// Directory for the frames and frames.csv (created).
    #[arg(long)]
    pub out: PathBuf,
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "960x540", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Simulated frames per second of flight time.
    #[arg(long, default_value_t = 10.0)]
    pub fps: f64,
    /// Draw and write every Nth simulated frame.
    #[arg(long, default_value_t = 50)]
    pub every: u32,
    /// UTC time at the start of the flight, RFC 3339 (default: the shipped weather file's time).
    #[arg(long, value_parser = parse_time)]
    pub time: Option<f64>,
    /// The look: renderer settings, cloud scale, time-of-day table.
    #[command(flatten)]
    pub look: LookArgs,
    /// Watch the weather file: when it changes, the sky follows (changed blocks re-form); and
    /// the `--winds-aloft` file: the air data takes a good new version, a broken one is refused.
    #[arg(long)]
    pub watch: bool,
    /// Quiet time after a change of the watched file before it is read, milliseconds.
    #[arg(long, default_value_t = 500)]
    pub settle_ms: u64,
    /// Clouds config: how long clouds take to form and dissipate when the weather changes
    /// (default: the shipped config/clouds.toml).
    #[arg(long)]
    pub clouds: Option<PathBuf>,
    /// The ground from an elevation file instead of the stations' elevations.
    #[command(flatten)]
    pub elevation: ElevationArgs,
    /// Every frame waits for its clouds, as the first one does: the frames then depend on the
    /// flight alone, not on how fast the background threads were (golden frames, tests).
    #[arg(long)]
    pub synchronous_clouds: bool,
}

/// Runs `skycast fly`.
pub fn run(args: &FlyArgs) -> anyhow::Result<()> {
    if !(args.fps > 0.0 && args.fps <= 240.0) {
        anyhow::bail!("--fps {} is outside (0, 240]", args.fps);
    }
    if args.every == 0 {
        anyhow::bail!("--every must be at least 1");
    }
    let plan = match super::defaults::shipped(&args.path) {
        Some(bytes) => FlightPlan::parse(&String::from_utf8_lossy(bytes), &args.path)?,
        None => FlightPlan::load(&args.path)?,
    };
    let (lat, lon) = plan.origin_lat_lon_deg;
    let flight = plan.place(&LocalFrame::new(lat, lon));
    let (settings, table) = args.look.load()?;
    let loaded = load(
        &args.weather,
        args.model.model.as_deref(),
        args.stations.as_deref(),
        None,
        None,
    )?
    .usable()?;
    let start_unix_s = time_or_default(args.time)?;
    super::model::warn_if_far_in_time(&loaded.input, start_unix_s);
    let field = loaded
        .input
        .field(LocalFrame::new(lat, lon), &loaded.settings, &loaded.rule);
    let ground = match args.elevation.elevation {
        Some(_) => args.elevation.ground(&field)?,
        None => ground_under_flight(&field, &flight),
    };
    // Live weather (the watched file, the flight's timed events) needs the station table for
    // report files; a theme places itself.
    let needs_table = (args.watch && !theme::is_theme_path(&args.weather))
        || plan
            .weather_events
            .iter()
            .any(|e| !theme::is_theme_path(&e.weather));
    let mut config = sky_config((lat, lon), (settings, table), &loaded);
    if needs_table {
        config.stations = Some(super::defaults::station_table(args.stations.as_deref())?);
    }
    let mut host = DemoHost::new(args.size.0, args.size.1, &ground, config)?;
    host.sky.set_weather_field(field);
    if let Some(path) = &args.aloft.winds_aloft
        && args.watch
    {
        // Placed through the sky's station table (`--stations` when watching reports).
        let (placed, _) = host
            .sky
            .watch_winds_aloft(path, Duration::from_millis(args.settle_ms))?;
        eprintln!(
            "winds aloft: {}: {placed} sites placed; watching it",
            path.display()
        );
    } else if let Some((fb, table)) = args.aloft.load(args.stations.as_deref())? {
        let (placed, _) = host.sky.world_mut().set_winds_aloft(Some(&fb), &table);
        eprintln!(
            "winds aloft: {}: {placed} of {} sites placed",
            fb.path.display(),
            fb.sites.len()
        );
    }
    if let Some(path) = super::defaults::settings_file(args.clouds.as_deref(), "clouds.toml") {
        host.sky
            .world_mut()
            .set_clouds_config(CloudsConfig::load(&path)?);
    }
    for event in &plan.weather_events {
        host.sky
            .schedule_weather(&event.weather, event.time_s - flight.start_s())?;
    }
    if args.watch {
        // A `--model` stays under the watched reports.
        if let Some(model) = loaded.input.model() {
            host.sky.set_model(Some(model.clone()));
        }
        host.sky.set_weather(Weather::Watch {
            path: &args.weather,
            settle: Duration::from_millis(args.settle_ms),
        })?;
        eprintln!("watching {}", args.weather.display());
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let csv_path = args.out.join("frames.csv");
    let mut csv = csv::Writer::from_path(&csv_path)
        .with_context(|| format!("cannot write {}", csv_path.display()))?;
    csv.write_record([
        "frame",
        "time_s",
        "east_m",
        "north_m",
        "alt_m",
        "heading_deg",
        "pitch_deg",
        "sprites_drawn",
        "clouds_drawn",
        "clouds_recomputed",
        "cache_hit_rate",
        "cpu_update_us",
        "field_us",
        "record_us",
        "sky_cpu_us",
        "upload_bytes",
        "sprite_gpu_bytes",
        "blocks_left_out",
        "impostors_rebuilt",
        "weather_us",
        "weather_applied",
        "written",
        "gpu_ms",
        "cloud_scale",
        "cloud_target_bytes",
        "in_cloud",
        "light_us",
        "sprites_lit",
        "air_us",
        "air_at_us",
        "wind_from_deg",
        "wind_kt",
        "gust_kt",
        "temperature_c",
        "dewpoint_c",
        "pressure_hpa",
        "pressure_altitude_ft",
        "visibility_m",
        "precipitation_mm_h",
        "air_in_cloud",
        "nearest_cloud_m",
        "turbulence",
        "icing",
        "sight_hits",
        "flashes",
        "sprites_recomputed",
        "ring_sprites_sorted",
        "ring_orders_rewritten",
        "gpu_wait_us",
        "preempted",
        "sky_thread_us",
        "field_thread_us",
        "update_thread_us",
        "record_thread_us",
        "air_thread_us",
        "far_field_us",
        "far_field_gpu_bytes",
        "shadow_sprites",
        "shadow_texels",
        "shadow_us",
    ])?;
    let frames = (flight.duration_s() * args.fps).floor() as u64 + 1;
    let dt_s = 1.0 / args.fps;
    let (mut written, mut inside_cloud) = (0u32, 0u32);
    // For the closing summary: what the book quotes (docs/src/performance.md), from this run.
    let mut summary = Summary::default();
    // On a terminal only (indicatif hides it when stderr is a file or a pipe).
    let progress = indicatif::ProgressBar::new(frames);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "[{bar:30}] {percent:>3}% {pos}/{len} frames, {msg} ({eta} left)",
    ) {
        progress.set_style(style.progress_chars("#> "));
    }
    for k in 0..frames {
        let time_s = flight.start_s() + k as f64 * dt_s;
        let pose = flight.pose_at(time_s);
        let camera = host.camera(pose.position_m, pose.heading_deg, pose.pitch_deg);
        let write = k % args.every as u64 == 0 || k + 1 == frames;
        // The frame step: new weather that is ready (the frame never waits for a file), the
        // living clouds, the sun, the sky's CPU share; drawn on written frames.
        let step_s = if k == 0 { 0.0 } else { dt_s };
        // The first frame is the warm-up: it waits for the clouds around, so the flight starts
        // under its whole sky; after it blocks arrive as they are generated.
        host.sky
            .world_mut()
            .set_synchronous_clouds(k == 0 || args.synchronous_clouds);
        let switches_before = involuntary_switches();
        let (stats, changes) = host.step(&camera, start_unix_s + time_s, step_s, write)?;
        let mut applied = String::new();
        for change in changes {
            applied = match change {
                Ok(source) => source
                    .file_name()
                    .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
                // Logged where it was found; the last good weather stays.
                Err(_) => "rejected".to_string(),
            };
        }
        let mut gpu_ms = String::new();
        if write {
            let frame = host.target.read_back(&host.gpu)?;
            frame.write_png(&args.out.join(format!("frame_{k:05}.png")))?;
            if let Some(ms) = host.last_gpu_ms() {
                gpu_ms = format!("{ms:.2}");
            }
            written += 1;
            // Entirely inside a cloud: the frame is the in-cloud fog and nothing else.
            inside_cloud += (stats.in_cloud >= 0.99) as u32;
        }
        // What a simulator asks every frame: the air data where the aircraft is, and 64 lines
        // of sight (its sensors, landing lights), counted in the sky's CPU.
        let mut stats = stats;
        let air_start = Stopwatch::start();
        let air = host.sky.air_at(HostPosition::Local(pose.position_m));
        let air_at_us = air_start.wall_us();
        let sight_hits = sight_fan(&host.sky, pose.position_m, pose.heading_deg);
        stats.set_air(air_start.spent());
        // Whether the system took the core away meanwhile (then the frame's times hold another
        // process's time slice too): a fact about the machine's load, reported, never excluded.
        let preempted = switches_before
            .zip(involuntary_switches())
            .map_or_else(String::new, |(a, b)| b.saturating_sub(a).to_string());
        summary.add(&stats);
        let p = pose.position_m;
        csv.write_record([
            k.to_string(),
            format!("{time_s:.2}"),
            format!("{:.1}", p.x),
            format!("{:.1}", p.y),
            format!("{:.1}", p.z),
            format!("{:.1}", pose.heading_deg),
            format!("{:.1}", pose.pitch_deg),
            stats.sprites_drawn.to_string(),
            stats.clouds_drawn.to_string(),
            stats.clouds_recomputed.to_string(),
            format!("{:.3}", stats.cache_hit_rate),
            stats.cpu_update_us.to_string(),
            stats.field_us.to_string(),
            stats.record_us.to_string(),
            stats.sky_cpu_us().to_string(),
            stats.upload_bytes.to_string(),
            stats.sprite_gpu_bytes.to_string(),
            stats.blocks_left_out.to_string(),
            stats.impostors_rebuilt.to_string(),
            stats.weather_us.to_string(),
            applied,
            (write as u8).to_string(),
            gpu_ms,
            stats.cloud_scale.to_string(),
            stats.cloud_target_bytes.to_string(),
            format!("{:.2}", stats.in_cloud),
            stats.light_us.to_string(),
            stats.sprites_lit.to_string(),
            stats.air_us.to_string(),
            air_at_us.to_string(),
            format!("{:.0}", air.wind_from_deg),
            format!("{:.1}", air.wind_kt),
            format!("{:.1}", air.gust_kt),
            format!("{:.1}", air.temperature_c),
            format!("{:.1}", air.dewpoint_c),
            format!("{:.1}", air.pressure_hpa),
            format!("{:.0}", air.pressure_altitude_ft),
            format!("{:.0}", air.visibility_m),
            format!("{:.1}", air.precipitation_mm_h),
            format!("{:.2}", air.in_cloud),
            air.nearest_cloud_m
                .map_or_else(String::new, |d| format!("{d:.0}")),
            format!("{:.2}", air.turbulence),
            (air.icing as u8).to_string(),
            sight_hits.to_string(),
            // The lightning flashes this frame, drained as a host drains them.
            host.sky.drain_flashes().len().to_string(),
            stats.sprites_recomputed.to_string(),
            stats.ring_sprites_sorted.to_string(),
            stats.ring_orders_rewritten.to_string(),
            stats.gpu_wait_us.to_string(),
            preempted,
            stats.sky_thread_us().to_string(),
            stats.thread.field_us.to_string(),
            stats.thread.update_us.to_string(),
            stats.thread.record_us.to_string(),
            stats.thread.air_us.to_string(),
            stats.far_field_us.to_string(),
            stats.far_field_gpu_bytes.to_string(),
            stats.shadow_sprites.to_string(),
            stats.shadow_texels.to_string(),
            stats.shadow_us.to_string(),
        ])?;
        progress.set_message(format!("{written} written"));
        progress.inc(1);
    }
    progress.finish();
    csv.flush()?;
    println!(
        "{}: {written} frames ({inside_cloud} of them entirely inside cloud) and frames.csv ({frames} simulated at {} fps)",
        args.out.display(),
        args.fps
    );
    println!("{}", summary.line());
    Ok(())
}

/// Lines of sight a frame in [`sight_fan`].
const SIGHT_LINES: usize = 64;

/// Casts 64 lines of sight of 10 km from `at_m` (16 headings around `heading_deg` at 4 pitches,
/// -10 to +20 degrees), as a host's sensors would; returns how many met a cloud.
fn sight_fan(sky: &skycast::SkySystem, at_m: glam::DVec3, heading_deg: f64) -> usize {
    let mut hits = 0;
    for k in 0..SIGHT_LINES {
        let heading = (heading_deg + (k % 16) as f64 * 22.5).to_radians();
        let pitch = (-10.0 + (k / 16) as f64 * 10.0_f64).to_radians();
        let dir = glam::DVec3::new(
            heading.sin() * pitch.cos(),
            heading.cos() * pitch.cos(),
            pitch.sin(),
        );
        let to = at_m + dir * 10_000.0;
        hits += sky
            .first_cloud(HostPosition::Local(at_m), HostPosition::Local(to))
            .is_some() as usize;
    }
    hits
}

/// The flight's figures, printed when it ends: the sky's CPU a frame on the frame thread's own
/// clock (`sky_thread_us`) and on the wall clock (`sky_cpu_us`, which holds any time slice
/// another thread took from the frame thread), over all frames and over those that rebuild an
/// impostor, the waits for the GPU apart from both, how much of the sort order came from the
/// cache, the frame thread's time on weather, peak memory.
#[derive(Default)]
struct Summary {
    sky_thread_us: Vec<u64>,
    sky_cpu_us: Vec<u64>,
    /// `sky_thread_us` of the frames that rebuild an impostor.
    rebuild_thread_us: Vec<u64>,
    /// `sky_cpu_us` of the frames that rebuild an impostor.
    rebuild_cpu_us: Vec<u64>,
    /// `gpu_wait_us` of the frames that waited.
    gpu_wait_us: Vec<u64>,
    cache_hit_rate: Vec<f32>,
    weather_us_max: u64,
}

/// The median and the 99th percentile (nearest rank) of `v`, sorted in place; 0 when empty.
fn median_p99(v: &mut [u64]) -> (u64, u64) {
    v.sort_unstable();
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    if v.is_empty() {
        (0, 0)
    } else {
        (at(0.5), at(0.99))
    }
}

impl Summary {
    fn add(&mut self, stats: &skycast::render::FrameStats) {
        self.sky_thread_us.push(stats.sky_thread_us());
        self.sky_cpu_us.push(stats.sky_cpu_us());
        if stats.impostors_rebuilt > 0 {
            self.rebuild_thread_us.push(stats.sky_thread_us());
            self.rebuild_cpu_us.push(stats.sky_cpu_us());
        }
        if stats.gpu_wait_us > 0 {
            self.gpu_wait_us.push(stats.gpu_wait_us);
        }
        self.cache_hit_rate.push(stats.cache_hit_rate);
        self.weather_us_max = self.weather_us_max.max(stats.weather_us);
    }

    fn line(&mut self) -> String {
        let (median, p99) = median_p99(&mut self.sky_thread_us);
        let (wall_median, wall_p99) = median_p99(&mut self.sky_cpu_us);
        let (rebuild_median, rebuild_p99) = median_p99(&mut self.rebuild_thread_us);
        let (rebuild_wall_median, rebuild_wall_p99) = median_p99(&mut self.rebuild_cpu_us);
        let (_, wait_p99) = median_p99(&mut self.gpu_wait_us);
        let wait_max = self.gpu_wait_us.last().copied().unwrap_or(0);
        self.cache_hit_rate.sort_by(f32::total_cmp);
        let hit = self
            .cache_hit_rate
            .get(((self.cache_hit_rate.len().saturating_sub(1)) as f64 * 0.5).round() as usize)
            .copied()
            .unwrap_or(0.0);
        let peak = peak_rss_bytes().map_or_else(
            || "unknown (no /proc/self/status)".to_string(),
            |b| format!("{:.0} MB", b as f64 / 1e6),
        );
        // Without a per-thread clock the thread figures are all 0: only the wall clock's said.
        let thread_clock = if self.sky_thread_us.iter().any(|&us| us > 0) {
            format!(
                "median {median} us, p99 {p99} us on the frame thread's CPU clock (the {} \
                 frames that rebuild an impostor: median {rebuild_median} us, p99 \
                 {rebuild_p99} us); ",
                self.rebuild_thread_us.len()
            )
        } else {
            String::new()
        };
        format!(
            "sky CPU a frame: {thread_clock}median {wall_median} us, p99 {wall_p99} us on the \
             wall clock, with the time slices other threads took from the frame thread (the {} \
             frames that rebuild an impostor: median {rebuild_wall_median} us, p99 \
             {rebuild_wall_p99} us); waiting for the GPU, apart: {} frames, p99 {wait_p99} us, at \
             most {wait_max} us; order cache hit rate, median: {:.1}%; weather on the frame \
             thread: at most {} us; peak memory (RSS): {peak}",
            self.rebuild_cpu_us.len(),
            self.gpu_wait_us.len(),
            hit * 100.0,
            self.weather_us_max
        )
    }
}

/// Involuntary context switches of the calling thread so far (Linux: the thread's
/// `nonvoluntary_ctxt_switches`), `None` elsewhere: a frame with more at its end than at its
/// start was preempted (the system ran something else on its core meanwhile).
fn involuntary_switches() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/thread-self/status").ok()?;
    let line = status
        .lines()
        .find(|l| l.starts_with("nonvoluntary_ctxt_switches:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The process's peak resident memory (Linux: `VmHWM` of /proc/self/status).
fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;
    use skycast::weather::{CloudTypeRule, FieldSettings, WeatherInput};

    /// From every point of the shipped FL350 flight the demo ground reaches past the horizon
    /// (and from low flights past the draw distance): the square around the start alone ended
    /// 65 km east of it, 3 minutes into the 6-minute flight.
    #[test]
    fn the_ground_reaches_past_what_is_seen_from_every_point_of_a_flight() {
        let input = WeatherInput::load(
            std::path::Path::new("weather/themes/building_cumulus_cb_line.toml"),
            None,
        )
        .expect("theme");
        for (path, reach_m) in [
            // The horizon from FL350 (sqrt(2 R h)).
            (
                "config/flights/cruise_fl350_los_angeles_east.toml",
                369_000.0,
            ),
            // The sprites' draw distance.
            ("config/flights/cruise_scattered_cumulus.toml", 60_000.0),
        ] {
            let plan = FlightPlan::load(std::path::Path::new(path)).expect("shipped flight");
            let (lat, lon) = plan.origin_lat_lon_deg;
            let frame = LocalFrame::new(lat, lon);
            let flight = plan.place(&frame);
            let field = input.field(frame, &FieldSettings::default(), &CloudTypeRule::default());
            let ground = ground_under_flight(&field, &flight);
            let half = ground.size_m / 2.0;
            for k in 0..=flight.duration_s().ceil() as u32 {
                let p = flight.pose_at(flight.start_s() + f64::from(k)).position_m;
                let to_edge = half - (p.truncate() - ground.centre_m).abs().max_element();
                assert!(
                    to_edge >= reach_m,
                    "{path} at {k} s: the ground ends {:.0} km away",
                    to_edge / 1000.0
                );
            }
        }
    }
}
