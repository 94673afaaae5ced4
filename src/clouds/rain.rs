//! Precipitation under a cloud: shafts of rain or snow falling from its base, where the weather
//! reports precipitation. Each shaft is a column of soft, upright sprites stacked from the base
//! down: darker grey (the cloud's base colour), as opaque as the precipitation is heavy, reaching
//! the ground in moist air and fading out on the way down (virga) as the air below the base
//! gets drier (the surface temperature-dewpoint spread). Snow falls in wider, fainter shafts.
//! Part of the cloud, so they form, dissipate, drift and are drawn with it.

use glam::{DVec2, Vec3};

use super::block::{Cloud, ShadingGroup, Sprite};
use super::config::{PrecipitationConfig, TextureCategory};
use super::rng::SplitMix64;
use crate::weather::BlockWeather;

/// At or below this surface temperature, degrees C, the precipitation is snow.
const SNOW_BELOW_C: f32 = 1.0;
/// Most sprites in one shaft.
const MOST_PER_SHAFT: u32 = 24;

/// How far down a shaft falls, as a fraction of base to ground: all the way in moist air, down to
/// `min_reach` as the surface spread grows through `virga_spread_c`.
pub fn reach(config: &PrecipitationConfig, spread_c: f32) -> f32 {
    let [moist, dry] = config.virga_spread_c;
    let dryness = ((spread_c - moist) / (dry - moist)).clamp(0.0, 1.0);
    1.0 - (1.0 - config.min_reach) * dryness
}

/// Adds the shafts of `config` under `cloud`, whose base is `base_m` above mean sea level, for
/// the block's `weather` (nothing without precipitation, or with the base on the ground).
pub fn add_shafts(
    cloud: &mut Cloud,
    config: &PrecipitationConfig,
    weather: &BlockWeather,
    base_m: f64,
    rng: &mut SplitMix64,
) {
    let intensity = weather.precipitation.clamp(0.0, 1.0);
    let fall_m = (base_m - weather.ground_elevation_m as f64) as f32;
    if intensity <= 0.0 || fall_m < 50.0 || cloud.sprites.is_empty() {
        return;
    }
    let base_radius = base_radius_m(cloud);
    let base_rel = (base_m - cloud.centre_m.z) as f32;
    let length = fall_m * reach(config, weather.temperature_c - weather.dewpoint_c);
    let snow = weather.temperature_c <= SNOW_BELOW_C;
    let mut alpha = config.alpha[0] + (config.alpha[1] - config.alpha[0]) * intensity;
    let mut width_scale = 1.0;
    if snow {
        (alpha, width_scale) = (alpha * 0.7, 1.3);
    }
    let ground_reached = length >= fall_m * 0.999;
    let foggy = TextureCategory::Foggy.cells();
    let shafts = rng.range_u32(config.shafts[0], config.shafts[1]);
    for _ in 0..shafts {
        let at = loop {
            let p = DVec2::new(rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0));
            if p.length_squared() <= 1.0 {
                break p.as_vec2() * base_radius * 0.55;
            }
        };
        let width =
            config.width_over_base * 2.0 * base_radius * width_scale * rng.range_f32(0.8, 1.2);
        // Soft sprites at most 0.6 of the fall tall, a third of their height apart: a curtain,
        // even from just inside the base to where the shaft ends, not a few puffs. The lowest is
        // centred on the shaft's end, so one reaching the ground is opaque down to it (its lower
        // half is under the ground), and virga frays out there.
        let height = (width * 1.2).min(length * 0.6).max(width * 0.2);
        let top = base_rel + height * 0.2 - height * 0.5;
        let bottom = (base_rel - length).min(top);
        let count = (((top - bottom) / (height * 0.33)).ceil() as u32 + 1).min(MOST_PER_SHAFT);
        let step = (top - bottom) / (count.max(2) - 1) as f32;
        let group = cloud.shading_groups.len() as u16;
        cloud.shading_groups.push(ShadingGroup {
            centre_m: Vec3::new(at.x, at.y, base_rel - length * 0.5).to_array(),
        });
        for k in 0..count {
            let down = k as f32 / count as f32;
            // A shaft that reaches the ground stays nearly even; virga thins out as it falls.
            let fade = if ground_reached {
                1.0 - 0.2 * down
            } else {
                (1.0 - down) * (1.0 - down)
            };
            let z = top - k as f32 * step;
            // Each a little aside and wider or narrower: ragged sides, not a pillar's.
            let aside = glam::Vec2::new(rng.range_f32(-0.12, 0.12), rng.range_f32(-0.12, 0.12));
            let (x, y) = (at.x + aside.x * width, at.y + aside.y * width);
            cloud.sprites.push(Sprite {
                offset_m: [x, y, z],
                width_m: width * rng.range_f32(0.75, 1.15),
                height_m: height,
                rotation_deg: 0.0,
                texture: rng.range_u32(foggy.start as u32, foggy.end as u32 - 1) as u8,
                shading_group: group,
                // The outermost part of the cloud: the last to form, the first to go.
                radius_fraction: 1.0,
                alpha_morph: (alpha * fade).clamp(0.0, 1.0),
                upright: true,
                precipitation: true,
                base: false,
            });
            let reach_m = Vec3::new(x, y, z).length() + 0.6 * width.max(height);
            cloud.radius_m = cloud.radius_m.max(reach_m);
        }
    }
}

/// The radius of the cloud's base: how far out its sprites reach horizontally in its lowest
/// sixth.
fn base_radius_m(cloud: &Cloud) -> f32 {
    let (lo, hi) = cloud
        .sprites
        .iter()
        .map(|s| s.offset_m[2])
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), z| {
            (lo.min(z), hi.max(z))
        });
    let near_base = lo + (hi - lo) / 6.0;
    cloud
        .sprites
        .iter()
        .filter(|s| s.offset_m[2] <= near_base)
        .map(|s| glam::Vec2::new(s.offset_m[0], s.offset_m[1]).length() + 0.5 * s.width_m)
        .fold(0.0, f32::max)
        .max(100.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::{CloudTypes, generate::generate_block};
    use crate::weather::{BlockIndex, BlockLayer, CloudType, TypeSource, Wind};

    /// Scattered cumulonimbus, base 3,000 ft over ground at 100 m, in `precipitation` with a
    /// surface spread of `spread_c`.
    fn storm(precipitation: f32, spread_c: f32) -> BlockWeather {
        BlockWeather {
            layers: vec![BlockLayer {
                cloud_type: CloudType::Cumulonimbus,
                type_source: TypeSource::Reported,
                coverage_oktas: 4.0,
                base_ft_agl: 3000.0,
                thickness_ft: 30000.0,
            }],
            visibility_m: 8000.0,
            obscuration: None,
            wind: Wind::default(),
            temperature_c: 24.0,
            dewpoint_c: 24.0 - spread_c,
            precipitation,
            thunder: 0.0,
            ground_elevation_m: 100.0,
            cover: None,
        }
    }

    /// Per cloud, where its rain ends: the lowest centre of its shafts' sprites, metres above
    /// mean sea level (None: dry). Below it a sprite's lower half frays out (virga) or is under
    /// the ground.
    fn rain_bottoms(weather: &BlockWeather) -> Vec<Option<f64>> {
        let block = generate_block(BlockIndex::new(3, -2), weather, 7, &CloudTypes::builtin());
        block
            .clouds
            .iter()
            .map(|c| {
                c.sprites
                    .iter()
                    .filter(|s| s.precipitation)
                    .map(|s| c.centre_m.z + s.offset_m[2] as f64)
                    .reduce(f64::min)
            })
            .collect()
    }

    #[test]
    fn rain_falls_from_every_storm_cell_to_the_ground_and_only_when_reported() {
        let base_m = 100.0 + 3000.0 * 0.3048;
        let wet = rain_bottoms(&storm(0.8, 2.0));
        assert!(!wet.is_empty());
        for bottom in &wet {
            let bottom = bottom.expect("every cell rains");
            // Reaches the ground: its lowest sprite centred there (opaque down to it), not above
            // or below it.
            assert!(
                (bottom - 100.0).abs() < 30.0,
                "rain ends at {bottom} m, ground 100 m"
            );
        }
        assert!(rain_bottoms(&storm(0.0, 2.0)).iter().all(Option::is_none));
        // Dry air below the base: virga, ending well above the ground.
        for bottom in rain_bottoms(&storm(0.8, 25.0)) {
            let bottom = bottom.expect("virga");
            let fell = (base_m - bottom) / (base_m - 100.0);
            assert!((0.2..0.5).contains(&fell), "virga fell {fell} of the way");
        }
    }

    #[test]
    fn rain_adds_to_the_clouds_and_changes_none_of_them() {
        let types = CloudTypes::builtin();
        let index = BlockIndex::new(3, -2);
        let dry = generate_block(index, &storm(0.0, 2.0), 7, &types);
        let wet = generate_block(index, &storm(0.8, 2.0), 7, &types);
        assert_eq!(dry.clouds.len(), wet.clouds.len());
        for (d, w) in dry.clouds.iter().zip(&wet.clouds) {
            let cloud: Vec<&Sprite> = w.sprites.iter().filter(|s| !s.precipitation).collect();
            assert_eq!(cloud, d.sprites.iter().collect::<Vec<_>>());
            let rain = w.sprites.iter().filter(|s| s.precipitation);
            assert!(rain.clone().all(|s| s.upright && s.alpha_morph > 0.0));
            assert!(rain.count() >= 2);
        }
    }

    #[test]
    fn shafts_reach_down_less_as_the_air_dries() {
        let config = CloudTypes::builtin()
            .get(CloudType::Cumulonimbus)
            .precipitation
            .expect("cumulonimbus rains");
        assert_eq!(reach(&config, 2.0), 1.0);
        assert!(reach(&config, 14.0) < 1.0 && reach(&config, 14.0) > reach(&config, 19.0));
        assert_eq!(reach(&config, 40.0), config.min_reach);
    }
}
