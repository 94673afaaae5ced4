//! The world of clouds a sky shows: weather reports go in as a weather field; the cloud blocks
//! around the camera come out, converted to [`SkyBlock`]s for the [`Sky`].
//!
//! Blocks are generated on demand (a pure function of block index, block weather and seed) and
//! kept, so a flight regenerates nothing it has seen. A living world hands the sky its changes
//! only, as plain data ([`World::advance_sky`] returns a [`SkyUpdate`] that
//! [`Sky::apply`] applies): a generation that appears is uploaded once, one that goes is
//! retired, and every frame the rest only move with the wind and fade. What it needs to know of
//! the sky (where the impostor ring and the far field take over) it is given as values
//! ([`World::set_sky_reach`]).

use std::collections::HashMap;

use glam::{DVec2, DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::clouds::config::MAX_DRIFT_BANDS;
use crate::clouds::{
    BlockGenerator, Cloud, CloudField, CloudTypes, CloudsConfig, DriftBand, field::weather_changed,
    generate_block,
};
#[cfg(doc)]
use crate::render::Sky;
use crate::render::scene::{BandOffsets, SkyBlock, SkyCloud, SkySprite};
use crate::render::update::{SkyReach, SkyUpdate};
use crate::render::{RenderError, SpriteSheet, Stopwatch};
use crate::shading::{ColourLevel, ColourLevels};
use crate::weather::field::WeatherField;
use crate::weather::storms::{Flash, FlashKind, flashes_between};
use crate::weather::{BLOCK_SIZE_M, BlockIndex, BlockWeather};

use super::block_weathers::BlockWeathers;
use super::living::{BandClouds, HandOver, LivingClouds};
use std::sync::Arc;

/// Settings of the world (`render` and `fly` use the defaults; `bench` widens the cloud radius
/// to its view radius).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSettings {
    /// Blocks whose centre lies within this horizontal distance of the camera get clouds, metres.
    pub cloud_radius_m: f64,
    /// Seed of the cloud generation.
    pub seed: u64,
    /// A block generated for a sky that had none around it (the first frames, a jump to
    /// another place) fades in over this time as it arrives, seconds of the frames' time,
    /// instead of appearing at once; beyond the impostor ring it comes in with the ring's
    /// crossfade instead. Not while clouds are synchronous ([`World::set_synchronous_clouds`]).
    #[serde(default = "default_arrival_fade_s")]
    pub arrival_fade_s: f64,
    /// Sprites of new generations handed to the sky a frame, at most (the nearest first; at
    /// least one generation a frame): a weather change forms every block of the field anew,
    /// hundreds of thousands of sprites, and handing them over in the frames they are
    /// generated in took 10 to 14 ms of the frame thread twice. They form from no opacity, so
    /// a few frames late shows nothing. Not while clouds are synchronous.
    #[serde(default = "default_joined_sprites_per_frame")]
    pub joined_sprites_per_frame: u32,
}

fn default_joined_sprites_per_frame() -> u32 {
    WorldSettings::default().joined_sprites_per_frame
}

fn default_arrival_fade_s() -> f64 {
    WorldSettings::default().arrival_fade_s
}

impl Default for WorldSettings {
    fn default() -> Self {
        Self {
            // As far as sprites are drawn (`draw_distance_m`): from altitude a deck that ended
            // at 24 km showed its edge; beyond the 20 km ring radius they are impostors.
            cloud_radius_m: 60_000.0,
            seed: 2003,
            arrival_fade_s: 3.0,
            joined_sprites_per_frame: 40_000,
        }
    }
}

impl From<&Cloud> for SkyCloud {
    fn from(c: &Cloud) -> Self {
        let z = c.centre_m.z as f32;
        SkyCloud {
            centre_m: c.centre_m,
            sprites: c
                .sprites
                .iter()
                .map(|s| SkySprite {
                    offset_m: Vec3::from_array(s.offset_m),
                    width_m: s.width_m,
                    height_m: s.height_m,
                    rotation_deg: s.rotation_deg,
                    cell: s.texture,
                    group: s.shading_group,
                    alpha_morph: s.alpha_morph,
                    radius_fraction: s.radius_fraction,
                    upright: s.upright,
                    precipitation: s.precipitation,
                    base: s.base,
                })
                .collect(),
            group_centres_m: c
                .shading_groups
                .iter()
                .map(|g| Vec3::from_array(g.centre_m))
                .collect(),
            colour_levels: ColourLevels(c.colour_levels.map(|l| ColourLevel {
                height_m: z + l.height_m,
                rgba: l.rgba,
            })),
            flat: c.flat,
            sunlit_depth_m: c.sunlit_depth_m,
            shaded_base_m: c.shaded_base_m,
            floor_m: c.floor_m,
            floor_slab_m: c.floor_slab_m,
            optical_density: c.optical_density,
        }
    }
}

/// Weather field and cloud blocks around a reference point.
pub struct World {
    /// Shared with the worker that works out the weather of the blocks ahead.
    field: Arc<WeatherField>,
    types: CloudTypes,
    settings: WorldSettings,
    blocks: HashMap<BlockIndex, SkyBlock>,
    living: Option<LivingClouds>,
    clouds_config: CloudsConfig,
    synchronous_clouds: bool,
    /// Counts weather fields taken ([`World::set_field`]).
    field_version: u64,
    /// Settings and caches of the air data ([`super::air`]).
    pub(super) air: super::air::AirState,
    /// Lightning flashes not yet drained by the host, oldest first.
    flashes: std::collections::VecDeque<Flash>,
    /// The latest in-cloud flash, lighting its cell while it lasts.
    lit: Option<Flash>,
    /// Where the sky hands its clouds over to the ring and the far field
    /// ([`World::set_sky_reach`]).
    sky_reach: SkyReach,
}

/// Flashes kept for a host that does not drain them, at most (the oldest go first).
const FLASHES_KEPT: usize = 1024;

impl World {
    /// The world of `field` (whose frame origin is the world's centre).
    pub fn new(field: WeatherField, settings: &WorldSettings) -> Self {
        Self {
            field: Arc::new(field),
            types: CloudTypes::builtin(),
            settings: *settings,
            blocks: HashMap::new(),
            living: None,
            clouds_config: CloudsConfig::builtin(),
            synchronous_clouds: false,
            field_version: 0,
            air: Default::default(),
            flashes: std::collections::VecDeque::new(),
            lit: None,
            sky_reach: SkyReach::default(),
        }
    }

    /// Tells the world where the sky it feeds hands its clouds over ([`Sky::reach`]: the
    /// impostor ring's radius, the far field's band), before [`Self::advance_sky`]: arrivals
    /// fade in within the ring, far storm cells are drawn whole past the band's start. A plain
    /// copy, so [`crate::SkySystem::update`] gives it every frame (a host may switch the ring
    /// or the far field at any time). Until given: neither is drawn.
    pub fn set_sky_reach(&mut self, reach: SkyReach) {
        self.sky_reach = reach;
    }

    /// What [`Self::set_sky_reach`] last gave.
    pub fn sky_reach(&self) -> SkyReach {
        self.sky_reach
    }

    /// The in-cloud flash lighting its cell now, as the sky draws it: its light fades from the
    /// settings' `brightness` to none over `duration_s` (`config/storms.toml`).
    pub fn flash_now(&self) -> Option<crate::render::SkyFlash> {
        let field = self.living.as_ref()?.lowest();
        let f = self.lit?;
        let l = field.storms().settings.lightning;
        let age = field.time_s() - f.time_s;
        (0.0..l.duration_s)
            .contains(&age)
            .then(|| crate::render::SkyFlash {
                position_m: DVec3::from_array(f.position_m),
                reach_m: l.reach_m as f32,
                light: (l.brightness * (1.0 - age / l.duration_s)) as f32,
            })
    }

    /// The lightning flashes since the last call, oldest first, positions in the local frame
    /// (metres east, north, up MSL): for thunder and for lighting the host's own scene. At most
    /// the last 1,024 are kept between calls.
    pub fn drain_flashes(&mut self) -> Vec<Flash> {
        self.flashes.drain(..).collect()
    }

    /// The flashes that started in the last `dt_s` seconds of the living field, queued.
    fn queue_flashes(&mut self, dt_s: f64) {
        let Some(living) = self.living.as_ref() else {
            return;
        };
        let field = living.lowest();
        let now = field.time_s();
        let drift = field.drift_m();
        let lightning = field.storms().settings.lightning;
        for mut f in flashes_between(field.cells(), now - dt_s, now, &lightning, field.seed()) {
            f.position_m[0] += drift.x;
            f.position_m[1] += drift.y;
            if f.kind == FlashKind::InCloud {
                self.lit = Some(f);
            }
            if self.flashes.len() >= FLASHES_KEPT {
                self.flashes.pop_front();
            }
            self.flashes.push_back(f);
        }
    }

    /// The weather field.
    pub fn field(&self) -> &WeatherField {
        &self.field
    }

    /// Uses `config` (lifecycle durations: how long a changed block's clouds take to form and
    /// dissipate) for the living clouds; call before the first [`Self::advance_sky`]. The
    /// field radius and seed stay the world's.
    pub fn set_clouds_config(&mut self, config: CloudsConfig) {
        self.clouds_config = config;
    }

    /// The clouds settings in use (the world's radius and seed in its field's).
    pub fn clouds_config(&self) -> &CloudsConfig {
        &self.clouds_config
    }

    /// When `on`, every frame of [`Self::advance_sky`] waits for the blocks it queued, so what
    /// a frame shows does not depend on thread timing, and they show whole at once: the warm-up
    /// for tests and offline rendering (turned on for the first frame, it gives that frame
    /// every cloud), never for a simulator's frame loop. Off by default: no frame waits, not
    /// even the first; blocks arrive as they are generated and fade in.
    pub fn set_synchronous_clouds(&mut self, on: bool) {
        self.synchronous_clouds = on;
    }

    /// Whether every frame waits for its clouds ([`Self::set_synchronous_clouds`]).
    pub fn synchronous_clouds(&self) -> bool {
        self.synchronous_clouds
    }

    /// How long clouds that arrive in a sky that had none take to fade in, seconds; `None`
    /// while clouds are synchronous (they are there whole in the first frame) or it is 0.
    pub fn arrival_fade_s(&self) -> Option<f64> {
        let s = self.settings.arrival_fade_s;
        (s > 0.0 && !self.synchronous_clouds).then_some(s)
    }

    /// Takes a new weather field (built off the frame thread, e.g. by a
    /// [`LiveWeather`](crate::weather::live::LiveWeather)'s prepare) without stopping: the living
    /// clouds of every block whose weather changed dissipate while the new ones form; unchanged
    /// blocks stay as they are.
    pub fn set_field(&mut self, field: WeatherField) {
        let old = std::mem::replace(&mut self.field, Arc::new(field));
        // Block weathers are looked up again lazily, from the new field (the kept ones follow
        // the version).
        self.field_version += 1;
        let new = &self.field;
        self.blocks.retain(|&index, _| {
            !weather_changed(&old.block_weather(index), &new.block_weather(index))
        });
    }

    /// The clouds stage's living field of the lowest drift band (the lowest layer of every
    /// block, and the storm cells), once [`Self::advance_sky`] has run.
    pub fn living_field(&self) -> Option<&CloudField> {
        self.living.as_ref().map(LivingClouds::lowest)
    }

    /// The clouds stage's living fields, one per drift band ([`crate::clouds::bands`]), the
    /// lowest first; empty before [`Self::advance_sky`] has run.
    pub fn living_fields(&self) -> impl Iterator<Item = &CloudField> {
        self.living
            .iter()
            .flat_map(|l| l.bands.iter().map(|b| &b.field))
    }

    /// The texture sheet of the clouds stage.
    pub fn sheet(&self) -> SpriteSheet {
        SpriteSheet::generated()
    }

    /// Horizontal visibility at the origin, metres. METAR caps visibility at 10 km (9999) or
    /// 10 statute miles; a capped value means clear air, taken as 40 km for the ground's fog.
    pub fn visibility_m(&self) -> f32 {
        let v = self.field.weather_at(DVec2::ZERO).visibility_m;
        if v >= 9_000.0 { 40_000.0 } else { v }
    }

    /// The weather over `camera_m` (for [`crate::render::Sky::set_weather_overhead`]).
    pub fn weather_over(&self, camera_m: DVec3) -> BlockWeather {
        let default_qnh_hpa = self.air_settings().pressure.default_qnh_hpa;
        self.weather_here(camera_m.truncate(), default_qnh_hpa).0
    }

    /// How many weather fields the world has taken ([`Self::set_field`]).
    pub(super) fn field_version(&self) -> u64 {
        self.field_version
    }

    /// The blocks that get clouds around `camera_m`, in a fixed order.
    pub fn block_indices(&self, camera_m: DVec3) -> Vec<BlockIndex> {
        let r = self.settings.cloud_radius_m;
        let at = camera_m.truncate();
        let lo = BlockIndex::containing(at - DVec2::splat(r));
        let hi = BlockIndex::containing(at + DVec2::splat(r));
        (lo.j..=hi.j)
            .flat_map(|j| (lo.i..=hi.i).map(move |i| BlockIndex::new(i, j)))
            .filter(|b| b.centre_m().distance(at) <= r)
            .collect()
    }

    /// The cloud blocks with these indices (generated on first use, then kept).
    pub fn sky_blocks(&mut self, indices: &[BlockIndex]) -> Vec<SkyBlock> {
        indices
            .iter()
            .map(|&index| {
                self.blocks
                    .entry(index)
                    .or_insert_with(|| {
                        let weather = self.field.block_weather(index);
                        let generated =
                            generate_block(index, &weather, self.settings.seed, &self.types);
                        let clouds: Vec<SkyCloud> =
                            generated.clouds.iter().map(SkyCloud::from).collect();
                        let c = index.centre_m();
                        let mean_z = if clouds.is_empty() {
                            weather.ground_elevation_m as f64
                        } else {
                            clouds.iter().map(|c| c.centre_m.z).sum::<f64>() / clouds.len() as f64
                        };
                        SkyBlock {
                            id: block_id(index),
                            centre_m: DVec3::new(c.x, c.y, mean_z),
                            clouds,
                        }
                    })
                    .clone()
            })
            .collect()
    }

    /// The cloud blocks around `camera_m`.
    pub fn sky_blocks_around(&mut self, camera_m: DVec3) -> Vec<SkyBlock> {
        let indices = self.block_indices(camera_m);
        self.sky_blocks(&indices)
    }
}

impl World {
    /// Makes the living clouds if there are none yet; true when it did.
    fn start_living(&mut self) -> Result<bool, RenderError> {
        if self.living.is_some() {
            return Ok(false);
        }
        let mut config = self.clouds_config;
        config.field.radius_m = self.settings.cloud_radius_m;
        config.field.seed = self.settings.seed;
        // Generating while frames go on: one thread per core but one, so the frame thread
        // keeps a core of its own (on 2 busy cores the first update's median went from 11
        // to 3 ms). Synchronous (the warm-up, tests, offline): every core (0).
        let threads = match self.synchronous_clouds {
            true => 0,
            false => std::thread::available_parallelism().map_or(1, |n| n.get().max(2) - 1),
        };
        // One pool for every band's field: the bands share the cores, as one field did.
        let types = Arc::new(self.types.clone());
        let pool = BlockGenerator::new(Arc::clone(&types), threads)
            .map_err(|e| RenderError::Clouds(e.to_string()))?
            .pool();
        let storms = self.storm_context(Default::default());
        let bands = DriftBand::all(config.field.drift_bands)
            .map(|band| {
                let generator = BlockGenerator::with_pool(Arc::clone(&types), Arc::clone(&pool));
                let mut field = CloudField::with_generator(config, generator).in_band(band);
                field.set_storms(storms);
                BandClouds::new(field)
            })
            .collect();
        self.clouds_config = config;
        self.living = Some(LivingClouds {
            bands,
            weather: BlockWeathers::default(),
            far_cells: super::far_cells::FarCells::new(
                crate::weather::storms::StormSettings::default().far,
            ),
        });
        Ok(true)
    }

    /// The storm cells beyond `radius_m` of `camera_m` (or reaching past `band_start_m`, where
    /// a drawn far field's hand-over starts) as the living world draws them (each a block for
    /// [`Sky::insert_distant_block`]), found at once, without drift: for a still world (the
    /// bench). None when `config/storms.toml` `[far]` is off.
    pub fn far_cell_blocks(
        &self,
        camera_m: DVec3,
        radius_m: f64,
        band_start_m: Option<f64>,
    ) -> Vec<SkyBlock> {
        let settings = crate::weather::storms::StormSettings::default();
        if !settings.far.enabled {
            return Vec::new();
        }
        let ctx = self.storm_context(settings);
        let f = super::far_cells::FarCellFrame {
            weather: &self.field,
            version: self.field_version,
            storms: (&ctx, self.settings.seed),
            types: &self.types,
            camera_air_m: camera_m.truncate(),
            drift_m: DVec2::ZERO,
            field_radius_m: radius_m,
            band_start_m,
            now_s: 0.0,
            whole: true,
        };
        super::far_cells::FarCells::blocks_now(settings.far, &f)
    }

    /// What the storm cells are decided with: `settings`, the air data's own wind profile
    /// (storm anvils spread along its wind aloft) and the frame's latitude.
    fn storm_context(
        &self,
        settings: crate::weather::storms::StormSettings,
    ) -> crate::weather::storms::StormContext {
        crate::weather::storms::StormContext {
            settings,
            wind: self.air_settings().wind,
            lat_deg: self.field.frame().to_lat_lon_deg(DVec2::ZERO).0,
        }
    }

    /// The far field's map's cell at a point, of the weather there with the world's cloud types'
    /// looks: the field's weather, without its cumulonimbus while storm cells beyond the cloud
    /// field are drawn as cells ([`Self::draws_far_cells`]), not as a layer from base to top.
    /// Decided once, for the thousands of points of a map.
    pub fn far_map_cell(&self) -> impl Fn(DVec2) -> crate::clouds::far_map::FarCell + '_ {
        let cells_apart = self.draws_far_cells();
        move |p| {
            let mut w = self.field.weather_at(p);
            if cells_apart {
                w.layers
                    .retain(|l| l.cloud_type != crate::weather::CloudType::Cumulonimbus);
            }
            crate::clouds::far_map::far_cell(&w, &self.types)
        }
    }

    /// Whether storm cells beyond the cloud field are drawn as cells (`config/storms.toml`
    /// `[far]`): the far field then leaves cumulonimbus out of its map.
    pub fn draws_far_cells(&self) -> bool {
        // `_else`: the shipped settings are parsed only without living clouds (this is
        // asked every frame).
        self.living.as_ref().map_or_else(
            || crate::weather::storms::StormSettings::default().far.enabled,
            |l| l.far_cells.enabled(),
        )
    }

    /// Generates the living clouds around `point_m` and waits for them, without a sky: for
    /// asking about the air ([`Self::air_at`]) where nothing is drawn (the command line, tests).
    pub fn settle_clouds_around(&mut self, point_m: DVec3) -> Result<(), RenderError> {
        self.advance_clouds_around(point_m, 0.0)
    }

    /// The velocity drift `band`'s living clouds over ground point `point_m` drift with: the
    /// air data's wind at the middle of its layer there ([`Self::cloud_drift_at`],
    /// [`Self::band_drift_height_m`]); `None` under a clear sky (the clouds stage's own guess
    /// then).
    fn drift_velocity(&self, point_m: DVec2, band: DriftBand) -> Option<DVec2> {
        let height = self.band_drift_height_m(point_m, band)?;
        Some(self.cloud_drift_at(point_m.extend(height)))
    }

    /// Advances the living clouds by `dt_s` seconds around `point_m` without a sky, waiting for
    /// the blocks that come (the clouds drift on, form and dissipate as a flight's do): for
    /// instruments on the ground (`flight::ceilometer`) and tests.
    pub fn advance_clouds_around(&mut self, point_m: DVec3, dt_s: f64) -> Result<(), RenderError> {
        self.start_living()?;
        let ground_m = point_m.truncate();
        let mut velocities = [None; MAX_DRIFT_BANDS as usize];
        for (velocity, field) in velocities.iter_mut().zip(self.living_fields()) {
            *velocity = self.drift_velocity(ground_m, field.band());
        }
        let (weather_field, version) = (&self.field, self.field_version);
        if let Some(living) = self.living.as_mut() {
            for (band, velocity) in living.bands.iter_mut().zip(velocities) {
                band.field.set_drift_velocity(velocity);
                // With the field's version, as a flight asks: a block of air asked again at
                // the same version drifted onto other ground (quicker to change).
                band.field
                    .update_for(ground_m, &|i| weather_field.block_weather(i), version);
                band.field.wait_for_pending();
                band.field.advance(dt_s);
            }
        }
        Ok(())
    }

    /// Advances the clouds stage's [`CloudField`] around `camera_m` by `dt_s` seconds (blocks
    /// generated in the background, no call waits for them unless clouds are synchronous;
    /// arriving into an empty sky, they fade in; drifting with the wind;
    /// forming and dissipating when the weather changes) and returns what changed for the sky,
    /// as plain data for [`Sky::apply`]: the new generations (moved in, uploaded once), the gone
    /// ones, the fades that moved on, the drift, the far storm cells' changes, and the CPU time
    /// this took ([`SkyUpdate::field_cpu`], for the frame's
    /// [`crate::render::FrameStats::field_us`]). Apply every update, in order, to the same sky:
    /// each says only what changed since the last. Give it the sky's reach first
    /// ([`Self::set_sky_reach`]).
    pub fn advance_sky(&mut self, camera_m: DVec3, dt_s: f64) -> Result<SkyUpdate, RenderError> {
        let start = Stopwatch::start();
        let mut update = SkyUpdate::default();
        if self.start_living()? {
            update.lifecycle = Some(self.clouds_config.lifecycle);
        }
        // A band's blocks around are asked for again only when the camera entered another
        // block of its moving air, its air drifted past a block, or the weather changed: then
        // its drift's wind is looked up again too.
        let version = self.field_version;
        let key_of = |drift: DVec2| {
            (
                BlockIndex::containing(camera_m.truncate() - drift),
                BlockIndex::containing(drift),
                version,
            )
        };
        let mut velocities = [None; MAX_DRIFT_BANDS as usize];
        if let Some(living) = self.living.as_ref() {
            for (velocity, band) in velocities.iter_mut().zip(&living.bands) {
                if band.asked != Some(key_of(band.field.drift_m())) {
                    *velocity = Some(self.drift_velocity(camera_m.truncate(), band.field.band()));
                }
            }
        }
        let weather_field = &self.field;
        let synchronous = self.synchronous_clouds;
        let Some(living) = self.living.as_mut() else {
            return Ok(update);
        };
        let lowest = &living.bands[0];
        let drift = lowest.field.drift_m();
        // Where the block weathers are worked out ahead of the field (`BlockWeathers`): around
        // the lowest band's blocks (the upper bands ask for few blocks, where layers are).
        let around = (camera_m.truncate() - drift, drift, lowest.field.radius_m());
        // A new weather field's block weathers are worked out on the field's pool first; its
        // blocks stay those of the last weather until then (offline frames take it at once).
        let filling = lowest.asked.is_some_and(|asked| asked.2 != version) && !synchronous && {
            let field = &lowest.field;
            living
                .weather
                .fill(weather_field, version, around, |job| field.spawn(job))
        };
        let asking = velocities.iter().any(Option::is_some);
        if asking && !filling {
            let cache = std::cell::RefCell::new(std::mem::take(&mut living.weather));
            // The field's own blocks take their cover at the rim; the storm cells it decides
            // reach well beyond them (a square and an anvil's reach around the radius), and a
            // storm reads a block's layers alone, at a tenth of the cost.
            let own_m = living.lowest().radius_m() + 2.0 * BLOCK_SIZE_M;
            let ground_m = camera_m.truncate();
            let weather = |index: BlockIndex| {
                if (index.centre_m() - ground_m).length() <= own_m {
                    cache.borrow_mut().get(weather_field, version, index)
                } else {
                    weather_field.block_layers_weather(index)
                }
            };
            for (band, velocity) in living.bands.iter_mut().zip(velocities) {
                let Some(velocity) = velocity else {
                    band.field.poll();
                    continue;
                };
                band.field.set_drift_velocity(velocity);
                band.field.update_for(ground_m, &weather, version);
                band.asked = Some(key_of(band.field.drift_m()));
            }
            living.weather = cache.into_inner();
            // The next row's weathers, off the frame thread before the camera brings it in.
            let field = &living.bands[0].field;
            living
                .weather
                .ask_ahead(weather_field, version, around, |job| field.spawn(job));
        } else {
            living.weather.take_ready(version);
            living.bands.iter_mut().for_each(|b| b.field.poll());
        }
        for band in &mut living.bands {
            if synchronous {
                band.field.wait_for_pending();
            }
            band.field.advance(dt_s);
        }
        self.queue_flashes(dt_s);
        let Some(living) = self.living.as_mut() else {
            return Ok(update);
        };
        let lowest = &living.bands[0].field;
        let drift = lowest.drift_m();
        living.far_cells.update(
            &mut update.distant,
            &super::far_cells::FarCellFrame {
                weather: &self.field,
                version: self.field_version,
                storms: (lowest.storms(), lowest.seed()),
                types: &self.types,
                camera_air_m: camera_m.truncate() - drift,
                drift_m: drift,
                field_radius_m: self.clouds_config.field.radius_m,
                band_start_m: (self.sky_reach.hand_over_m).map(|(start, _)| f64::from(start)),
                now_s: lowest.time_s(),
                whole: self.synchronous_clouds,
            },
        );
        // Each band's drift; bands the field is not split into move as its last.
        let offsets: BandOffsets = std::array::from_fn(|k| {
            let band = &living.bands[k.min(living.bands.len() - 1)];
            band.field.drift_m().extend(0.0)
        });
        update.drift_m = Some(offsets);
        let mut hand_over = HandOver {
            fade_in_s: self.settings.arrival_fade_s,
            fade_in: self.settings.arrival_fade_s > 0.0 && !self.synchronous_clouds,
            ring_m: self.sky_reach.ring_radius_m,
            ground_m: camera_m.truncate(),
            budget: match self.synchronous_clouds {
                true => u64::MAX,
                false => u64::from(self.settings.joined_sprites_per_frame),
            },
            spent: 0,
            waiting: (0, 0),
            walked: false,
        };
        super::living::hand_over(&mut living.bands, &offsets, &mut hand_over, &mut update);
        // The field's own time: the sky counts its applying in its own update.
        update.field_cpu = start.spent();
        Ok(update)
    }
}

/// A block's id for the vertex cache: its index packed into 64 bits.
pub fn block_id(index: BlockIndex) -> u64 {
    ((index.i as u32 as u64) << 32) | index.j as u32 as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flight side hands the sky plain data, without a device: a synchronous world's first
    /// update brings every block of its field and the lifecycle; the next, with nothing changed
    /// but time, only the drift.
    #[test]
    fn a_world_hands_the_sky_its_changes_as_plain_data() {
        use crate::weather::field::{CloudTypeRule, FieldSettings};
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("weather/themes/fair_weather_cumulus.toml");
        let input = crate::weather::WeatherInput::load(&path, None).expect("the shipped theme");
        let field = input.field(
            crate::weather::LocalFrame::new(47.0, 8.0),
            &FieldSettings::default(),
            &CloudTypeRule::default(),
        );
        let settings = WorldSettings {
            cloud_radius_m: 6_000.0,
            ..WorldSettings::default()
        };
        let mut world = World::new(field, &settings);
        world.set_synchronous_clouds(true);
        world.set_sky_reach(SkyReach {
            ring_radius_m: Some(20_000.0),
            hand_over_m: None,
        });
        let camera_m = DVec3::new(0.0, 0.0, 1_500.0);
        let first = world.advance_sky(camera_m, 0.0).expect("first update");
        let blocks: usize = world.living_fields().map(|f| f.blocks().count()).sum();
        assert!(first.lifecycle.is_some());
        assert!(blocks > 0);
        assert_eq!(first.came.len(), blocks);
        assert!(first.went.is_empty());
        assert!(first.drift_m.is_some());
        let next = world
            .advance_sky(camera_m, 1.0 / 60.0)
            .expect("next update");
        assert_eq!(next.lifecycle, None);
        assert!(next.came.is_empty() && next.went.is_empty() && next.fades.is_empty());
        assert!(next.drift_m.is_some());
    }
}
