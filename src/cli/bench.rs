//! `skycast bench [--size WxH] [--frames N] [--cloud-scale S] [--out DIR]`: the frame-budget
//! benchmark of issue 6 (Wang 2003 section 6.3, figure 15). The three scenarios of
//! `weather/scenarios/` (sparse, scattered, overcast: about 170 %, 200 % and 475 % block
//! overdraw) are flown along the same straight path, a cruise due east at 5,000 ft above the
//! scenario's station, each with the impostor ring (far blocks in impostors) and without (every
//! block as sprites), and each of those with the clouds drawn at the cloud scale S (default: the
//! renderer settings' `[clouds] resolution_scale`) and at full resolution (scale 1), so one run
//! compares both: the two scales fly side by side, one host each, both drawing each sample
//! before the camera moves on, so load from elsewhere on a shared machine falls on both alike.
//! All runs see the same view: clouds out to the ring's view radius, sprites drawn that far.
//!
//! The path is sampled, not flown frame by frame: `--frames` points 12 km apart / (N - 1). A
//! real flight rebuilds the ring every 15% of its radius (3 km at 20 km: 25 s at 120 m/s, some
//! 1,500 frames at 60 a second, 8 of them rendering an impostor); between samples the camera
//! jumps hundreds of metres, so at each sample the ring is brought up to date first (the rebuild
//! frames and the crossfade, timed on their own), and the cloud shadow map too (its scrolled
//! strips and the blocks that came into its range, a budget a frame: the first sample's whole
//! sky takes a few hundred frames), and then one steady frame is timed, as most of a real
//! flight's frames are: one that draws neither. The frames at a sample after its first take a
//! frame's sky time (1/60 s), so the clouds are the same at each sample with the ring on or off.
//!
//! Out: one table on standard output headed by the adapter's name (scenario, block overdraw,
//! ring on or off, cloud scale, median and p95 of the steady frames' milliseconds, the sky's
//! passes alone, the median of the frames rendering an impostor, the off/on ratio of the
//! medians, the scale-1 over scale-S ratio, sprites drawn, the sky's CPU milliseconds (update
//! and recording) and the GPU memory of the resident sprites); the same rows as `bench.csv`,
//! every frame in `frames.csv` (with its cloud scale and the cloud target's bytes), and
//! `frame_time.png`, steady frame time along the path (plotters: axes with units, a legend
//! naming each run's scenario, ring and scale). Frame time is
//! the GPU time between timestamps around the frame's passes where the adapter has timestamp
//! queries, else the wall time from submit to the end of the poll-wait; the table says which.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use glam::{DVec2, DVec3};
use skycast::clouds::{CloudTypes, generate_block};
use skycast::demo::{DemoHost, GroundSettings, demo_ground};
use skycast::flight::world::{World, WorldSettings};

use skycast::render::{BlockMotion, RenderSettings, SkyConfig};
use skycast::shading::{TimeOfDayTable, sun_position};
use skycast::weather::{
    BlockIndex, CloudTypeRule, FieldSettings, LocalFrame, METRES_PER_FOOT, StationTable,
    WeatherInput,
};

use super::render::{load_look, parse_cloud_scale, parse_size, parse_time, time_or_default};

mod passes;
mod plot;

/// The scenarios, in the order of the table: the first three run by default, `storm` (a
/// thunderstorm report: the weather field's storm cells) when asked for with `--scenario`.
const SCENARIOS: [&str; 4] = ["sparse", "scattered", "overcast", "storm"];
/// The scenario run only when asked for.
const ON_REQUEST: &str = "storm";
/// The path: due east, centred on the station, this long, at this height above its ground.
const PATH_LENGTH_M: f64 = 12_000.0;
const CRUISE_FT_AGL: f64 = 5_000.0;
const PITCH_DEG: f64 = -3.0;
/// Cruise speed, metres a second: sets the simulated time from one sample to the next.
const SPEED_M_S: f64 = 120.0;
/// The sky time of each frame after a sample's first (a frame at 60 a second): the frames that
/// bring the ring and the shadow map up to date at a sample take the time a host's frames take,
/// so the sky (its clouds' forming and drift) is the same at each sample with the ring on or
/// off, however many frames each needed.
const FRAME_DT_S: f64 = 1.0 / 60.0;

/// Flags of `skycast bench`.
#[derive(Debug, Args)]
pub struct BenchArgs {
    /// The model under each scenario's report.
    #[command(flatten)]
    pub model: super::model::ModelArgs,
    /// Image size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Frames per run (spread evenly along the path), at least 2.
    #[arg(long, default_value_t = 120)]
    pub frames: u32,
    /// Directory for bench.csv, frames.csv and frame_time.png (created).
    #[arg(long, default_value = "out/bench")]
    pub out: PathBuf,
    /// Directory holding sparse.metar, scattered.metar, overcast.metar and storm.metar.
    #[arg(long, default_value = "weather/scenarios")]
    pub scenarios: PathBuf,
    /// Station table placing the scenario reports.
    /// (default: NOAA's table built into skycast).
    #[arg(long)]
    pub stations: Option<PathBuf>,
    /// Renderer settings (default: the shipped config/render.toml); `[impostors]` is switched on
    /// and off by the benchmark.
    #[arg(long)]
    pub render_settings: Option<PathBuf>,
    /// View radius, kilometres: clouds out to here, far ones in impostors or all as sprites
    /// (default: the view radius of the renderer settings' `[impostors]`).
    #[arg(long)]
    pub view_km: Option<f64>,
    /// Time-of-day table (default: the shipped config/time_of_day.toml).
    #[arg(long)]
    pub time_of_day: Option<PathBuf>,
    /// Resolution the clouds are drawn at besides full resolution: 1, 1/2 or 1/4 (default: the
    /// renderer settings' `[clouds] resolution_scale`); each scenario is run at both.
    #[arg(long, value_parser = parse_cloud_scale)]
    pub cloud_scale: Option<f32>,
    /// UTC time, RFC 3339 (default: the shipped weather file's time).
    #[arg(long, value_parser = parse_time)]
    pub time: Option<f64>,
    /// Run only this scenario (sparse, scattered, overcast, or storm: SBBH's TSRA BKN045CB);
    /// repeat for more (default: sparse, scattered and overcast).
    #[arg(long = "scenario", value_parser = ["sparse", "scattered", "overcast", "storm"])]
    pub scenarios_only: Vec<String>,
    /// Camera height above the scenario's station, feet (the cruise-altitude case: 35000).
    #[arg(long, default_value_t = CRUISE_FT_AGL)]
    pub alt_ft: f64,
    /// Run only with the far field (`on`), only without it (`off`: its rows are the scenario
    /// name with `-nofar`), or both, one after the other.
    #[arg(long, default_value = "on", value_parser = ["on", "off", "both"])]
    pub far_field: String,
    /// Run only with the impostor ring (`on`), only without it (`off`), or both.
    #[arg(long, default_value = "both", value_parser = ["on", "off", "both"])]
    pub impostors: String,
    /// Also time each group of the sky's passes on the GPU (the build, the background or the
    /// downsample, the ring, the sprites, the composite; the ring and the sprites then go in
    /// passes of their own): a table of their medians, and columns in frames.csv. Needs GPU
    /// timestamps between passes.
    #[arg(long)]
    pub passes: bool,
    /// The clouds' shadows on the ground: `on` or `off` (default: the renderer settings'
    /// `[cloud_shadows] enabled`).
    #[arg(long, value_name = "on|off", value_parser = super::render::parse_on_off)]
    pub cloud_shadows: Option<bool>,
}

/// One frame of one run.
struct FrameRecord {
    /// False for the frames that bring the ring up to date at a sample (rebuild, crossfade).
    steady: bool,
    distance_m: f64,
    frame_ms: f64,
    /// The sky's passes alone (the host's ground left out); NaN without GPU timestamps.
    sky_ms: f64,
    cpu_update_ms: f64,
    upload_bytes: u64,
    sprite_gpu_bytes: u64,
    sprites_drawn: u32,
    blocks_near: u32,
    blocks_far: u32,
    impostors_rebuilt: u32,
    /// Bytes of the sky's off-screen cloud target (0 at scale 1).
    cloud_target_bytes: u64,
    /// Sprites and texels drawn into the cloud shadow map (`FrameStats::shadow_sprites`,
    /// `shadow_texels`).
    shadow_sprites: u32,
    shadow_texels: u64,
    /// The sky's passes one by one (`--passes`, where the device times them).
    passes: Option<skycast::render::PassTimes>,
}

/// One run: a scenario with impostors on or off, the clouds at one resolution scale.
struct Run {
    scenario: &'static str,
    overdraw: f64,
    impostors: bool,
    cloud_scale: f32,
    frames: Vec<FrameRecord>,
    /// Sprites in view where the run could not be drawn (too many for the device).
    not_drawn: Option<u64>,
}

/// The `p`-quantile (0..=1) of `values`, nearest rank.
fn quantile(values: &[f64], p: f64) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let rank = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

impl Run {
    fn steady(&self) -> impl Iterator<Item = &FrameRecord> {
        self.frames.iter().filter(|f| f.steady)
    }
    fn frame_ms(&self) -> Vec<f64> {
        self.steady().map(|f| f.frame_ms).collect()
    }
    fn median_ms(&self) -> f64 {
        quantile(&self.frame_ms(), 0.5)
    }
    fn p95_ms(&self) -> f64 {
        quantile(&self.frame_ms(), 0.95)
    }
    /// Median of the frames that render an impostor (NaN when none did).
    fn rebuild_ms(&self) -> f64 {
        let ms: Vec<f64> = self
            .frames
            .iter()
            .filter(|f| f.impostors_rebuilt > 0)
            .map(|f| f.frame_ms)
            .collect();
        quantile(&ms, 0.5)
    }
    fn median_of(&self, f: impl Fn(&FrameRecord) -> f64) -> f64 {
        quantile(&self.steady().map(f).collect::<Vec<_>>(), 0.5)
    }
}

/// Mean overdraw of the 5 x 5 blocks around block (0, 0) (as `tests/clouds/scenarios.rs`).
fn mean_overdraw(world: &World, seed: u64) -> f64 {
    let types = CloudTypes::builtin();
    let weather = world.field().block_weather(BlockIndex::new(0, 0));
    let sum: f64 = (-2..=2)
        .flat_map(|j| (-2..=2).map(move |i| BlockIndex::new(i, j)))
        .map(|index| generate_block(index, &weather, seed, &types).overdraw())
        .sum();
    sum / 25.0
}

/// The scenario's world, centred on its one station.
fn scenario_world(
    dir: &Path,
    name: &str,
    stations: &StationTable,
    settings: &WorldSettings,
    model: Option<&std::sync::Arc<skycast::weather::model::ModelField>>,
) -> anyhow::Result<(World, (f64, f64))> {
    let path = dir.join(format!("{name}.metar"));
    let input = match super::defaults::shipped(&path) {
        Some(bytes) => WeatherInput::parse(&path, bytes, Some(stations))?,
        None => WeatherInput::load(&path, Some(stations))?,
    };
    let input = match (model, input) {
        (Some(model), WeatherInput::Reports(file)) => WeatherInput::Model {
            model: model.clone(),
            reports: Some(file),
        },
        (_, input) => input,
    };
    let Some(file) = input.reports() else {
        anyhow::bail!(
            "{}: a scenario is a report file, not a theme or a model",
            path.display()
        );
    };
    let Some(report) = file.reports.first() else {
        anyhow::bail!("{}: no report placed", path.display());
    };
    let at = (report.position.latitude_deg, report.position.longitude_deg);
    let field = input.field(
        LocalFrame::new(at.0, at.1),
        &FieldSettings::default(),
        &CloudTypeRule::default(),
    );
    Ok((World::new(field, settings), at))
}

/// What the runs share: the look, the size, the frame count and the time.
struct Setup {
    settings: RenderSettings,
    table: TimeOfDayTable,
    size: (u32, u32),
    frames: u32,
    unix_s: f64,
    /// Time the sky's passes one by one (`--passes`).
    passes: bool,
    /// Camera height above the station, feet.
    alt_ft_agl: f64,
}

/// What a run came to.
enum Flown {
    /// Its frames, the adapter's name and whether GPU timestamps timed them.
    Frames {
        frames: Vec<FrameRecord>,
        adapter: String,
        timestamps: bool,
    },
    /// Without impostors, the view holds more sprites than the device can draw at once.
    TooMany { sprites: u64, max_sprites: u64 },
}

/// Flies the runs of one ring setting side by side, one host a cloud scale: at each sample
/// every host draws its frames before the camera moves on, so a burst of load on a shared
/// machine falls on all the scales alike and their ratio holds.
fn fly(
    setup: &Setup,
    world: &mut World,
    at: (f64, f64),
    (impostors, scales): (bool, &[f32]),
) -> anyhow::Result<Vec<Flown>> {
    let ground = demo_ground(world.field(), &GroundSettings::default());
    // The storm cells beyond the blocks (the world's radius is the view radius), drawn whole
    // as a flight draws them, and the far field's map around the path (12 km: one map holds
    // both), made once; the map leaves cumulonimbus to the cells.
    let far_field = setup.settings.far_field;
    let distant = world.far_cell_blocks(
        DVec3::ZERO,
        setup.settings.impostors.view_radius_m,
        far_field
            .enabled
            .then_some(f64::from(far_field.fade_start_m)),
    );
    let far_map = setup.settings.far_field.enabled.then(|| {
        let f = setup.settings.far_field;
        skycast::clouds::far_map::FarMapFeed::new(f.texels, f.texel_m, f.move_texels, 1).update(
            DVec2::ZERO,
            true,
            world.far_map_cell(),
        )
    });
    let mut hosts = Vec::new();
    for &cloud_scale in scales {
        let mut settings = setup.settings;
        settings.impostors.enabled = impostors;
        settings.clouds.resolution_scale = cloud_scale;
        hosts.push(DemoHost::new(
            setup.size.0,
            setup.size.1,
            &ground,
            SkyConfig {
                targets: skycast::demo::headless::TARGETS,
                settings,
                time_of_day: setup.table.clone(),
                sheet: world.sheet(),
            },
        )?);
    }
    if let Some(Some(map)) = &far_map {
        for host in &mut hosts {
            host.sky.sky_mut().set_far_map(&host.gpu.queue, map, None);
        }
    }
    if setup.passes {
        for host in &mut hosts {
            if !host.sky.sky_mut().set_pass_timing(true) {
                eprintln!("bench: --passes: this device has no GPU timestamps between passes");
            }
        }
    }
    let Some(first) = hosts.first() else {
        return Ok(Vec::new());
    };
    let adapter = format!(
        "{} ({:?})",
        first.gpu.adapter_info.name, first.gpu.adapter_info.backend
    );
    let max_sprites = first.max_sprites();
    let alt_m = ground.height_at_m(DVec2::ZERO) + setup.alt_ft_agl * METRES_PER_FOOT;
    let sun = sun_position(setup.unix_s, at.0, at.1);
    let visibility_m = world.visibility_m();
    let step_m = PATH_LENGTH_M / (setup.frames - 1) as f64;
    let dt_s = step_m / SPEED_M_S;
    let position = |k: u32| DVec3::new(-PATH_LENGTH_M / 2.0 + k as f64 * step_m, 0.0, alt_m);
    let mut indices = Vec::new();
    let mut records: Vec<Vec<FrameRecord>> = hosts.iter().map(|_| Vec::new()).collect();
    let mut timestamps = true;
    // Sample 0 is drawn twice: the first time (pipelines warming up, the whole ring built at
    // once) is not counted.
    let mut warm_up = vec![0; hosts.len()];
    for (n, k) in std::iter::once(0).chain(0..setup.frames).enumerate() {
        let p = position(k);
        let now = world.block_indices(p);
        if now != indices {
            let blocks = world.sky_blocks(&now);
            let sprites: u64 = blocks
                .iter()
                .flat_map(|b| &b.clouds)
                .map(|c| c.sprites.len() as u64)
                .sum();
            if !impostors && sprites > max_sprites {
                // All of them as sprites do not fit the device's largest buffer.
                return Ok(scales
                    .iter()
                    .map(|_| Flown::TooMany {
                        sprites,
                        max_sprites,
                    })
                    .collect());
            }
            for host in &mut hosts {
                host.sky.sky_mut().set_clouds(blocks.clone());
                for block in &distant {
                    host.sky
                        .sky_mut()
                        .insert_distant_block(block.clone(), BlockMotion::default());
                }
            }
            indices = now;
        }
        let overhead = world.weather_over(p);
        for ((host, records), warm_up) in hosts.iter_mut().zip(&mut records).zip(&mut warm_up) {
            if n == 1 {
                *warm_up = records.len();
            }
            host.sky.sky_mut().set_weather_overhead(&overhead);
            let distance_m = k as f64 * step_m;
            timestamps &=
                draw_to_steady(host, (p, distance_m), (&sun, dt_s, visibility_m), records)?;
        }
    }
    Ok(records
        .into_iter()
        .zip(warm_up)
        .map(|(mut frames, warm_up)| {
            frames.drain(..warm_up);
            Flown::Frames {
                frames,
                adapter: adapter.clone(),
                timestamps,
            }
        })
        .collect())
}

/// Draws frames at one sample until the ring and the shadow map are up to date there (the
/// frames that sort the ring's orders a budget at a time, 8 rebuild frames and a crossfade at
/// most; the map's strips, patches and arriving blocks, a budget a frame), 512 at most; the
/// last, which draws neither, is the steady one, as most of a flight's frames are. The first
/// frame's sky time is the flight from the last sample, the others' a frame's. False when the
/// frames were timed by the wall clock (no GPU timestamps).
fn draw_to_steady(
    host: &mut DemoHost,
    (p, distance_m): (DVec3, f64),
    (sun, dt_s, visibility_m): (&skycast::shading::SunPosition, f64, f32),
    records: &mut Vec<FrameRecord>,
) -> anyhow::Result<bool> {
    let camera = host.camera(p, 90.0, PITCH_DEG);
    let mut timestamps = true;
    for frame in 0..512 {
        let start = Instant::now();
        let dt_s = if frame == 0 { dt_s } else { FRAME_DT_S };
        let stats = host.draw(&camera, sun, dt_s, visibility_m)?;
        let (frame_ms, sky_ms) = match host.last_gpu_split_ms() {
            Some([ground, sky]) => (ground + sky, sky),
            None => {
                timestamps = false;
                host.wait_idle()?;
                // Submit to the end of the wait: the draw call minus its CPU update.
                let wall = start.elapsed().as_secs_f64() * 1e3;
                ((wall - stats.cpu_update_us as f64 / 1e3).max(0.0), f64::NAN)
            }
        };
        let steady = stats.impostors_rebuilt == 0
            && stats.crossfade_weight == 0.0
            && stats.ring_sprites_sorted == 0
            && !stats.shadow_redrawn;
        records.push(FrameRecord {
            steady,
            distance_m,
            frame_ms,
            sky_ms,
            cpu_update_ms: stats.sky_cpu_us() as f64 / 1e3,
            upload_bytes: stats.upload_bytes,
            sprite_gpu_bytes: stats.sprite_gpu_bytes,
            sprites_drawn: stats.sprites_drawn,
            blocks_near: stats.blocks_near,
            blocks_far: stats.blocks_far,
            impostors_rebuilt: stats.impostors_rebuilt,
            cloud_target_bytes: stats.cloud_target_bytes,
            shadow_sprites: stats.shadow_sprites,
            shadow_texels: stats.shadow_texels,
            passes: host.sky.sky().pass_times(),
        });
        if steady {
            break;
        }
    }
    Ok(timestamps)
}

/// Runs `skycast bench`.
pub fn run(args: &BenchArgs) -> anyhow::Result<()> {
    if args.frames < 2 {
        anyhow::bail!("--frames {} is less than 2", args.frames);
    }
    let (mut settings, table) = load_look(
        args.render_settings.as_ref(),
        args.time_of_day.as_ref(),
        args.cloud_scale,
    )?;
    if let Some(on) = args.cloud_shadows {
        settings.cloud_shadows.enabled = on;
    }
    // The chosen scale first, then full resolution to compare with.
    let mut scales = vec![settings.clouds.resolution_scale];
    if scales[0] != 1.0 {
        scales.push(1.0);
    }
    let unix_s = time_or_default(args.time)?;
    let stations = super::defaults::station_table(args.stations.as_deref())?;
    let view_radius_m = match args.view_km {
        Some(km) if (1.0..=200.0).contains(&km) => km * 1000.0,
        Some(km) => anyhow::bail!("--view-km {km} is outside 1..=200"),
        None => settings.impostors.view_radius_m,
    };
    // The same view with and without impostors: clouds out to the view radius, sprites drawn
    // that far.
    let mut setup = Setup {
        settings,
        table,
        size: args.size,
        frames: args.frames,
        unix_s,
        passes: args.passes,
        alt_ft_agl: args.alt_ft,
    };
    if !(0.0..=60_000.0).contains(&args.alt_ft) {
        anyhow::bail!("--alt-ft {} is outside 0..=60000", args.alt_ft);
    }
    let fars: &[bool] = match args.far_field.as_str() {
        "on" => &[true],
        "off" => &[false],
        _ => &[true, false],
    };
    setup.settings.impostors.view_radius_m = view_radius_m;
    let clouds = &mut setup.settings.clouds;
    clouds.draw_distance_m = clouds.draw_distance_m.max(view_radius_m as f32);
    let world_settings = WorldSettings {
        cloud_radius_m: view_radius_m,
        ..WorldSettings::default()
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut runs = Vec::new();
    let mut adapter = String::new();
    let mut timestamps = true;
    let rings: &[bool] = match args.impostors.as_str() {
        "on" => &[true],
        "off" => &[false],
        _ => &[true, false],
    };
    let model = match &args.model.model {
        Some(path) => Some(std::sync::Arc::new(
            skycast::weather::model::ModelField::load(path)?,
        )),
        None => None,
    };
    let settings = skycast::weather::model::ModelSettings::default();
    if let Some(warning) = model
        .as_ref()
        .and_then(|m| m.time_warning(unix_s, &settings.time))
    {
        eprintln!("warning: {warning}");
    }
    for scenario in SCENARIOS {
        let asked = args.scenarios_only.iter().any(|s| s == scenario);
        if (!args.scenarios_only.is_empty() || scenario == ON_REQUEST) && !asked {
            continue;
        }
        let (mut world, at) = scenario_world(
            &args.scenarios,
            scenario,
            &stations,
            &world_settings,
            model.as_ref(),
        )?;
        let overdraw = mean_overdraw(&world, world_settings.seed);
        for (&impostors, &far) in rings.iter().flat_map(|r| fars.iter().map(move |f| (r, f))) {
            setup.settings.far_field.enabled = far;
            // Rows without the far field go by a name of their own (a leak of a few bytes a
            // run, for the life of the command).
            let label: &'static str = if far {
                scenario
            } else {
                Box::leak(format!("{scenario}-nofar").into_boxed_str())
            };
            eprintln!(
                "bench: {label}, impostors {}, cloud scales {}",
                if impostors { "on" } else { "off" },
                scales
                    .iter()
                    .map(|&s| scale_text(s))
                    .collect::<Vec<_>>()
                    .join(" and ")
            );
            let flown = fly(&setup, &mut world, at, (impostors, &scales))?;
            for (flown, &cloud_scale) in flown.into_iter().zip(&scales) {
                let mut not_drawn = None;
                let frames = match flown {
                    Flown::Frames {
                        frames,
                        adapter: name,
                        timestamps: gpu,
                    } => {
                        adapter = name;
                        timestamps &= gpu;
                        frames
                    }
                    Flown::TooMany {
                        sprites,
                        max_sprites,
                    } => {
                        eprintln!(
                            "bench: {scenario} without impostors: {sprites} sprites in view, this device draws at most {max_sprites} at once; not drawn (choose a smaller --view-km to compare)"
                        );
                        not_drawn = Some(sprites);
                        Vec::new()
                    }
                };
                runs.push(Run {
                    scenario: label,
                    overdraw,
                    impostors,
                    cloud_scale,
                    frames,
                    not_drawn,
                });
            }
        }
    }
    // In the table each scenario's rows go by scale, then ring on and off.
    let scale_rank = |run: &Run| scales.iter().position(|&s| s == run.cloud_scale);
    runs.sort_by_key(|r| {
        (
            SCENARIOS.iter().position(|&s| r.scenario.starts_with(s)),
            r.scenario.len(),
            scale_rank(r),
            !r.impostors,
        )
    });
    let timing = if timestamps {
        "GPU timestamps"
    } else {
        "wall time, submit to poll-wait"
    };
    let rows = summary_rows(&runs);
    print_table(&adapter, args, timing, &rows);
    passes::print(&runs);
    write_csv(&args.out.join("bench.csv"), &adapter, timing, &rows)?;
    write_frames_csv(&args.out.join("frames.csv"), &runs)?;
    let png = args.out.join("frame_time.png");
    plot::write(&png, &runs_for_plot(&runs))?;
    println!(
        "{}: bench.csv, frames.csv, frame_time.png",
        args.out.display()
    );
    Ok(())
}

/// A scale as the table and the CSV files write it: 1, 1/2, 1/4.
fn scale_text(scale: f32) -> String {
    if scale >= 1.0 {
        "1".to_string()
    } else {
        format!("1/{}", (1.0 / scale).round())
    }
}

/// A row of the table and of `bench.csv`.
struct Row {
    scenario: &'static str,
    overdraw_pct: f64,
    impostors: bool,
    cloud_scale: f32,
    median_ms: f64,
    p95_ms: f64,
    /// Median of the sky's passes alone over the steady frames (NaN: no GPU timestamps).
    sky_ms: f64,
    /// Median of the frames rendering an impostor (NaN: none).
    rebuild_ms: f64,
    /// Median without impostors over median with them (the same on both rows of a scenario).
    ratio: f64,
    /// The same for the sky's passes alone.
    sky_ratio: f64,
    /// Median at scale 1 over median at this row's scale, same scenario and ring (1 at scale 1).
    scale_ratio: f64,
    /// The same for the sky's passes alone.
    sky_scale_ratio: f64,
    sprites_drawn: f64,
    cpu_update_ms: f64,
    /// Median GPU memory of the resident sprites (records, orders, indices, draw list), MB.
    sprite_mb: f64,
    /// False where the run did not fit the device (sprites_drawn is then the sprites in view).
    drawn: bool,
}

fn summary_rows(runs: &[Run]) -> Vec<Row> {
    runs.iter()
        .map(|r| {
            let other = runs.iter().find(|o| {
                o.scenario == r.scenario
                    && o.cloud_scale == r.cloud_scale
                    && o.impostors != r.impostors
            });
            let full = runs.iter().find(|o| {
                o.scenario == r.scenario && o.impostors == r.impostors && o.cloud_scale == 1.0
            });
            let (on, off) = match other {
                Some(o) if r.impostors => (r, o),
                Some(o) => (o, r),
                None => (r, r),
            };
            let sky = |run: &Run| run.median_of(|f| f.sky_ms);
            let (ratio, sky_ratio) = match other {
                Some(_) => (off.median_ms() / on.median_ms(), sky(off) / sky(on)),
                None => (f64::NAN, f64::NAN),
            };
            let (scale_ratio, sky_scale_ratio) = match full {
                Some(f) => (f.median_ms() / r.median_ms(), sky(f) / sky(r)),
                None => (f64::NAN, f64::NAN),
            };
            Row {
                scenario: r.scenario,
                overdraw_pct: r.overdraw * 100.0,
                impostors: r.impostors,
                cloud_scale: r.cloud_scale,
                scale_ratio,
                sky_scale_ratio,
                median_ms: r.median_ms(),
                p95_ms: r.p95_ms(),
                sky_ms: sky(r),
                rebuild_ms: r.rebuild_ms(),
                ratio,
                sky_ratio,
                sprites_drawn: match r.not_drawn {
                    Some(n) => n as f64,
                    None => r.median_of(|f| f.sprites_drawn as f64),
                },
                drawn: r.not_drawn.is_none(),
                cpu_update_ms: r.median_of(|f| f.cpu_update_ms),
                sprite_mb: r.median_of(|f| f.sprite_gpu_bytes as f64 / 1e6),
            }
        })
        .collect()
}

const HEADER: [&str; 16] = [
    "scenario",
    "overdraw_pct",
    "impostors",
    "cloud_scale",
    "median_ms",
    "p95_ms",
    "sky_ms",
    "rebuild_ms",
    "off_on_ratio",
    "sky_off_on_ratio",
    "full_scale_ratio",
    "sky_full_scale_ratio",
    "sprites_drawn",
    "cpu_update_ms",
    "sprite_gpu_mb",
    "drawn",
];

fn print_table(adapter: &str, args: &BenchArgs, timing: &str, rows: &[Row]) {
    println!(
        "skycast bench on {adapter}: {}x{}, {} frames a run over {:.0} km at {:.0} ft AGL; frame time: {timing}",
        args.size.0,
        args.size.1,
        args.frames,
        PATH_LENGTH_M / 1000.0,
        args.alt_ft
    );
    println!(
        "{:<10} {:>9} {:>9} {:>5} {:>10} {:>8} {:>8} {:>10} {:>7} {:>10} {:>6} {:>7} {:>10} {:>9} {:>9}",
        "scenario",
        "overdraw",
        "impostors",
        "scale",
        "median ms",
        "p95 ms",
        "sky ms",
        "rebuild ms",
        "off/on",
        "sky off/on",
        "1/S",
        "sky 1/S",
        "sprites",
        "cpu ms",
        "gpu MB"
    );
    let ms = |v: f64| {
        if v.is_finite() {
            format!("{v:.2}")
        } else {
            "-".to_string()
        }
    };
    for r in rows {
        println!(
            "{:<10} {:>8.0}% {:>9} {:>5} {:>10} {:>8} {:>8} {:>10} {:>7} {:>10} {:>6} {:>7} {:>10.0} {:>9} {:>9.1}{}",
            r.scenario,
            r.overdraw_pct,
            if r.impostors { "on" } else { "off" },
            scale_text(r.cloud_scale),
            ms(r.median_ms),
            ms(r.p95_ms),
            ms(r.sky_ms),
            ms(r.rebuild_ms),
            ms(r.ratio),
            ms(r.sky_ratio),
            ms(r.scale_ratio),
            ms(r.sky_scale_ratio),
            r.sprites_drawn,
            ms(r.cpu_update_ms),
            r.sprite_mb,
            if r.drawn {
                ""
            } else {
                "  not drawn: more sprites in view than the device draws at once"
            }
        );
    }
}

fn write_csv(path: &Path, adapter: &str, timing: &str, rows: &[Row]) -> anyhow::Result<()> {
    let mut csv =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut header: Vec<&str> = HEADER.to_vec();
    header.extend(["adapter", "frame_time"]);
    csv.write_record(&header)?;
    // Runs that were not drawn have no times: empty cells.
    let ms = |v: f64| {
        if v.is_finite() {
            format!("{v:.3}")
        } else {
            String::new()
        }
    };
    for r in rows {
        csv.write_record([
            r.scenario.to_string(),
            format!("{:.0}", r.overdraw_pct),
            (if r.impostors { "on" } else { "off" }).to_string(),
            r.cloud_scale.to_string(),
            ms(r.median_ms),
            ms(r.p95_ms),
            ms(r.sky_ms),
            ms(r.rebuild_ms),
            ms(r.ratio),
            ms(r.sky_ratio),
            ms(r.scale_ratio),
            ms(r.sky_scale_ratio),
            format!("{:.0}", r.sprites_drawn),
            ms(r.cpu_update_ms),
            format!("{:.1}", r.sprite_mb),
            (if r.drawn {
                "yes"
            } else {
                "no: too many sprites"
            })
            .to_string(),
            adapter.to_string(),
            timing.to_string(),
        ])?;
    }
    csv.flush()?;
    Ok(())
}

fn write_frames_csv(path: &Path, runs: &[Run]) -> anyhow::Result<()> {
    let mut csv =
        csv::Writer::from_path(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut header = vec![
        "scenario",
        "impostors",
        "cloud_scale",
        "frame",
        "steady",
        "distance_m",
        "frame_ms",
        "sky_ms",
        "cpu_update_ms",
        "upload_bytes",
        "sprite_gpu_bytes",
        "sprites_drawn",
        "blocks_near",
        "blocks_far",
        "impostors_rebuilt",
        "cloud_target_bytes",
        "shadow_sprites",
        "shadow_texels",
    ];
    header.extend(passes::COLUMNS.map(|(name, _)| name));
    csv.write_record(&header)?;
    for run in runs {
        for (k, f) in run.frames.iter().enumerate() {
            let mut row = vec![
                run.scenario.to_string(),
                (if run.impostors { "on" } else { "off" }).to_string(),
                run.cloud_scale.to_string(),
                k.to_string(),
                (if f.steady { "yes" } else { "no" }).to_string(),
                format!("{:.0}", f.distance_m),
                format!("{:.3}", f.frame_ms),
                if f.sky_ms.is_finite() {
                    format!("{:.3}", f.sky_ms)
                } else {
                    String::new()
                },
                format!("{:.3}", f.cpu_update_ms),
                f.upload_bytes.to_string(),
                f.sprite_gpu_bytes.to_string(),
                f.sprites_drawn.to_string(),
                f.blocks_near.to_string(),
                f.blocks_far.to_string(),
                f.impostors_rebuilt.to_string(),
                f.cloud_target_bytes.to_string(),
                f.shadow_sprites.to_string(),
                f.shadow_texels.to_string(),
            ];
            row.extend(passes::COLUMNS.map(|(_, read)| {
                f.passes
                    .as_ref()
                    .map_or(String::new(), |p| format!("{:.3}", read(p)))
            }));
            csv.write_record(&row)?;
        }
    }
    csv.flush()?;
    Ok(())
}

/// One line a run: colour by scenario (lighter at full resolution when another scale is run),
/// dashed without the impostor ring.
fn runs_for_plot(runs: &[Run]) -> Vec<plot::Series> {
    let several_scales = runs.iter().any(|r| r.cloud_scale != runs[0].cloud_scale);
    runs.iter()
        .map(|r| plot::Series {
            label: format!(
                "{}, ring {}, clouds at {}",
                r.scenario,
                if r.impostors { "on" } else { "off" },
                scale_text(r.cloud_scale)
            ),
            colour: match (r.scenario, several_scales && r.cloud_scale == 1.0) {
                ("sparse", false) => [40, 110, 220],
                ("sparse", true) => [140, 180, 240],
                ("scattered", false) => [30, 160, 60],
                ("scattered", true) => [140, 210, 150],
                (_, false) => [210, 50, 40],
                (_, true) => [240, 150, 140],
            },
            dashed: !r.impostors,
            points: r.steady().map(|f| (f.distance_m, f.frame_ms)).collect(),
        })
        .collect()
}
