//! Cloud-type and lifecycle settings, loaded from TOML (`config/cloud_types.toml`,
//! `config/clouds.toml`) with serde; every fault names the file, line and field.
//!
//! The defaults are Wang 2003's numbers (§3.1: 20 to 200 boxes per 16 km2 block, 1 to 100 sprites
//! per box, cull radius 1/3 of the sprite height for typical clouds and 1/5 to 1/6 for dense
//! ones; §3.2: cumulus bottoms rotated -5..5 degrees, others 0..360, non-square sprites not at all;
//! §5.1: five colour levels per cloud; §5.2: shading groups of 1 to 30 sprites). Heights inside a
//! cloud (texture bands, colour levels) are fractions 0 (base) ..= 1 (top) of the cloud thickness.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::CloudsError;
use crate::config::{ConfigError, line_of};
use crate::weather::CloudType;

/// The texture categories of the sheet (Wang 2003 §3.2, figure 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TextureCategory {
    /// Soft, low-contrast, subtly blue-grey: stratus and fog (cells 0..3).
    Foggy,
    /// A puff with a flat underside: cumulus bases (cell 3).
    FlatBottom,
    /// Streaks and curls, used by every type (cells 4..10).
    Wispy,
    /// Heaped cauliflower puffs: cumulus (cells 10..16).
    Puffy,
}

impl TextureCategory {
    /// Every category, in sheet order.
    pub const ALL: [TextureCategory; 4] = [
        TextureCategory::Foggy,
        TextureCategory::FlatBottom,
        TextureCategory::Wispy,
        TextureCategory::Puffy,
    ];

    /// The sheet cells (row-major, 0..16) holding this category.
    pub fn cells(self) -> std::ops::Range<u8> {
        match self {
            TextureCategory::Foggy => 0..3,
            TextureCategory::FlatBottom => 3..4,
            TextureCategory::Wispy => 4..10,
            TextureCategory::Puffy => 10..16,
        }
    }

    /// The category of a sheet cell.
    pub fn of_cell(cell: u8) -> TextureCategory {
        TextureCategory::ALL
            .into_iter()
            .find(|c| c.cells().contains(&cell))
            .unwrap_or(TextureCategory::Puffy)
    }
}

/// Boxes per block by METAR cover (Wang 2003 §3.1: 20 to 200 per 16 km2): the most boxes a layer
/// of this type may spend in one block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxesByCover {
    /// FEW, 1-2 oktas.
    pub few: u32,
    /// SCT, 3-4 oktas.
    pub sct: u32,
    /// BKN, 5-7 oktas.
    pub bkn: u32,
    /// OVC, 8 oktas.
    pub ovc: u32,
}

impl BoxesByCover {
    /// The budget for a coverage in oktas.
    pub fn for_oktas(&self, oktas: f32) -> u32 {
        if oktas <= 2.0 {
            self.few
        } else if oktas <= 4.0 {
            self.sct
        } else if oktas < 8.0 {
            self.bkn
        } else {
            self.ovc
        }
    }
}

/// A factor on the sprites per box, by METAR cover: the distinct, dense heaps of a sparse sky
/// against the looser patches of a scattered one (Wang 2003 §6.3: sparse 170 % overdraw,
/// scattered 200 %, overcast 475 %).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DensityByCover {
    /// FEW, 1-2 oktas.
    pub few: f32,
    /// SCT, 3-4 oktas.
    pub sct: f32,
    /// BKN, 5-7 oktas.
    pub bkn: f32,
    /// OVC, 8 oktas.
    pub ovc: f32,
}

impl DensityByCover {
    /// The factor for a coverage in oktas.
    pub fn for_oktas(&self, oktas: f32) -> f32 {
        if oktas <= 2.0 {
            self.few
        } else if oktas <= 4.0 {
            self.sct
        } else if oktas < 8.0 {
            self.bkn
        } else {
            self.ovc
        }
    }
}

/// Which textures and rotations go at which height in a cloud.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureBand {
    /// The band covers heights from the previous band's `up_to` to this, fraction of thickness.
    pub up_to: f32,
    /// Categories to choose from, at random.
    pub textures: Vec<TextureCategory>,
    /// Rotation range for square sprites, degrees.
    pub rotation_deg: [f32; 2],
}

/// A colour level as configured: height as a fraction of the cloud thickness.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColourLevelConfig {
    /// Height, fraction 0 (base) ..= 1 (top).
    pub height: f32,
    /// Colour and alpha, linear 0..=1.
    pub rgba: [f32; 4],
}

/// The anvil of a cumulonimbus: boxes above `from` spread out wide and flat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnvilConfig {
    /// Height where the anvil starts, fraction of the thickness, 0..1.
    pub from: f32,
    /// Anvil width over the tower's base width, >= 1.
    pub width_scale: f32,
}

/// How a storm cell of the weather field (`weather::storms`) is drawn: a budget of sprites
/// however wide the cell, so a 10 km cell costs about what a 2 km chimney did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StormCellConfig {
    /// Sprites of one whole cell (base, turrets and anvil) before the cull, 50..=4000.
    pub sprites: u32,
    /// Sprite width over the cell's base width, range.
    pub sprite_over_base: [f32; 2],
    /// Share of the sprites that go to the anvil, 0..1.
    pub anvil_share: f32,
    /// The cell's five ambient colour levels, lowest first, heights as fractions of the cell's
    /// height (the type's own levels where absent).
    #[serde(default)]
    pub colour_levels: Option<[ColourLevelConfig; 5]>,
    /// The share of the cell's height, from its base up, in the shadow of the body above (the
    /// type's `shaded_base_m` is for a chimney: a cell's sprites are taller than it), 0..=1.
    #[serde(default)]
    pub shaded_share: f32,
    /// Opacity factor of the anvil's sprites, in its middle and at its rim, 0..=1.
    #[serde(default = "opaque")]
    pub anvil_alpha: [f32; 2],
}

fn opaque() -> [f32; 2] {
    [1.0, 1.0]
}

/// Precipitation falling from a cloud's base where the weather reports it (rain or snow
/// shafts; virga, evaporating before the ground, where the air below is dry).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrecipitationConfig {
    /// Shafts under one cloud (or lattice cell), the range they are drawn from.
    pub shafts: [u32; 2],
    /// A shaft's width over the width of the cloud's base.
    pub width_over_base: f32,
    /// Opacity of a shaft at light (intensity 0) and heavy (1) precipitation.
    pub alpha: [f32; 2],
    /// Temperature-dewpoint spread at the ground, degrees C: below the first the shaft reaches
    /// the ground; from the second on it reaches only `min_reach` of the way down (virga).
    pub virga_spread_c: [f32; 2],
    /// The least fraction of the way from base to ground a shaft falls.
    pub min_reach: f32,
}

/// The shape of one cloud type (one `[section]` of `config/cloud_types.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudTypeConfig {
    /// Placed on a world-aligned lattice so that layers run on across block borders (stratus,
    /// overcast decks, fog) instead of as separate clouds.
    pub continuous: bool,
    /// Lattice spacing for continuous types, metres (ignored otherwise).
    pub lattice_spacing_m: f32,
    /// How much a layer on the lattice covers beyond the cells it keeps: keeping a share `p` of
    /// its cells it covers `p + k p (1 - p)` of the sky (its clouds' sprites reach past their
    /// cells; below 0 where they leave gaps inside them), so the lattice keeps the share that
    /// covers what the weather asks. Measured per type by the test
    /// `a_layer_on_the_lattice_covers_what_the_weather_asks` (it prints the fit). -1 ..= 2;
    /// absent: 0.
    #[serde(default)]
    pub lattice_overhang: f32,
    /// Candidate centres a scattered cloud of the type is placed at the best of: the one
    /// farthest from the clouds already placed. Cumulus fields are more even than random
    /// (Joseph and Cahalan 1990: neighbouring cumulus lie farther apart than chance would put
    /// them, each cloud's sinking air around it), and a sky of even clouds shows an instrument
    /// that sees a line of it the cover it has over the block. 1..=16; absent: 1 (random).
    #[serde(default = "one_candidate")]
    pub placement_candidates: u32,
    /// Drawn as flat horizontal rectangles (cirrus, Wang 2003 §7.1).
    pub flat: bool,
    /// Cloud thickness range, metres; the layer's reported thickness is clamped into it.
    pub thickness_m: [f32; 2],
    /// Horizontal cloud diameter range, metres.
    pub cloud_size_m: [f32; 2],
    /// Boxes per cloud.
    pub boxes_per_cloud: [u32; 2],
    /// How much narrower the top box is than the bottom one, 0 (column) ..= 1 (cone).
    pub taper: f32,
    /// Tallest a heaped cloud may be over its diameter: smaller clouds of a layer stay lower
    /// (humilis wider than tall, congestus towering), their tops below the layer's.
    pub max_height_over_size: f32,
    /// The anvil, for cumulonimbus.
    #[serde(default)]
    pub anvil: Option<AnvilConfig>,
    /// Cumulonimbus: how the field's storm cells are drawn.
    #[serde(default)]
    pub cell: Option<StormCellConfig>,
    /// Rain or snow shafts under the type's clouds where the weather has precipitation.
    #[serde(default)]
    pub precipitation: Option<PrecipitationConfig>,
    /// Decks (the type's layers placed on the lattice): the depth below the deck's top at which
    /// direct sunlight, along its slanted path, falls to 1/e. Seen from below, the deck takes
    /// the sun diffused through its whole thickness, evenly (Wang's median directional colour,
    /// without the shading groups' sunlit sides), so a low stratus is an even grey ceiling, not
    /// sunlit heaps; from above and inside, each part of it by its depth below the top, the same
    /// everywhere (one slab, not a grid of cells each with a sunlit side), under either shading
    /// model. Absent: lit as Wang does from every side.
    #[serde(default)]
    pub sunlit_depth_m: Option<f32>,
    /// Heaped types: the height above a cloud's base, metres, in which its body above hides the
    /// sun: the base is dark and evenly lit (ambient light only), the sun coming in above it
    /// (a cumulonimbus's one dark, flat base). Absent: lit as Wang does down to the base.
    #[serde(default)]
    pub shaded_base_m: Option<f32>,
    /// Flat types: each cloud is a streak this many times longer than wide, laid along the wind
    /// with every sprite lengthwise along it (cirrus fibres); `cloud_size_m` is its length.
    #[serde(default)]
    pub streak_length_over_width: Option<f32>,
    /// Factor on the extinction inside the type's clouds (`[in_cloud] visibility_m` of
    /// config/air.toml): the optical depth the probes and the shadow map find through its dense
    /// cores. Absent: 1, a water cloud's (cumulus, stratus); below 1 for thin ice cloud
    /// (cirrus: an optical depth of about 0.03-3 through the whole layer).
    #[serde(default)]
    pub optical_density: Option<f32>,
    /// Most boxes per block, by cover.
    pub boxes_per_block: BoxesByCover,
    /// Sprites per box before the cull, 1..=100.
    pub sprites_per_box: [u32; 2],
    /// Factor on `sprites_per_box` by cover (the result is kept within 1..=100).
    pub density_by_cover: DensityByCover,
    /// Sprite width range, metres.
    pub sprite_width_m: [f32; 2],
    /// Sprite height over width; 1 is square, below 1 the wide short sprites of haze (§3.1).
    pub sprite_height_ratio: [f32; 2],
    /// Cull radius as a fraction of the sprite height (1/3 typical, 1/5..1/6 dense).
    pub cull_radius_fraction: f32,
    /// Sprites per shading group, 1..=30.
    pub shading_group_size: [u32; 2],
    /// Texture categories and rotations by height in the cloud, lowest band first.
    pub texture_bands: Vec<TextureBand>,
    /// Five ambient colour levels, lowest first.
    pub colour_levels: [ColourLevelConfig; 5],
}

impl CloudTypeConfig {
    /// The texture band holding a height fraction (the last band above them all; `None` only
    /// for a config with no bands, which [`CloudTypes`] never holds).
    pub fn band_at(&self, height_fraction: f32) -> Option<&TextureBand> {
        self.texture_bands
            .iter()
            .find(|b| height_fraction <= b.up_to)
            .or(self.texture_bands.last())
    }
}

/// All cloud types, validated: one config per [`CloudType`].
#[derive(Debug, Clone, PartialEq)]
pub struct CloudTypes {
    types: Vec<CloudTypeConfig>,
}

/// The shipped `config/cloud_types.toml`.
pub const BUILTIN_CLOUD_TYPES: &str = include_str!("../../config/cloud_types.toml");
/// The shipped `config/clouds.toml`.
pub const BUILTIN_CLOUDS: &str = include_str!("../../config/clouds.toml");

impl CloudTypes {
    /// Reads and validates a cloud-types file.
    pub fn load(path: &Path) -> Result<Self, CloudsError> {
        let text = read(path)?;
        Self::parse(&text, path)
    }

    /// The shipped defaults (`config/cloud_types.toml`, compiled in).
    pub fn builtin() -> Self {
        Self::parse(BUILTIN_CLOUD_TYPES, Path::new("config/cloud_types.toml"))
            .expect("the shipped config/cloud_types.toml is valid (tested)")
    }

    /// Parses and validates cloud-types TOML; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, CloudsError> {
        // First pass: section names only, so a misspelt type is named before its fields are.
        let sections: std::collections::BTreeMap<String, toml::Spanned<toml::Value>> =
            toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        for (name, spanned) in &sections {
            if CloudType::from_name(name).is_none() {
                return Err(CloudsError::Parse {
                    path: path.to_owned(),
                    line: line_of(text, spanned.span().start),
                    field: name.clone(),
                    message: format!(
                        "unknown cloud type; expected one of: {}",
                        CloudType::ALL.map(CloudType::name).join(", ")
                    ),
                });
            }
        }
        let table: std::collections::BTreeMap<String, CloudTypeConfig> =
            toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        let mut types = Vec::with_capacity(CloudType::ALL.len());
        for cloud_type in CloudType::ALL {
            let Some(config) = table.get(cloud_type.name()) else {
                return Err(CloudsError::MissingType {
                    path: path.to_owned(),
                    cloud_type,
                });
            };
            validate(config, cloud_type.name(), text, path)?;
            types.push(config.clone());
        }
        Ok(Self { types })
    }

    /// The config of a type.
    pub fn get(&self, cloud_type: CloudType) -> &CloudTypeConfig {
        let i = CloudType::ALL
            .iter()
            .position(|&t| t == cloud_type)
            .unwrap_or(0);
        &self.types[i]
    }
}

/// Formation and dissipation timings (Wang 2003 §4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LifecycleConfig {
    /// Time for a cloud to form completely, seconds.
    pub formation_s: f32,
    /// Time for a cloud to dissipate completely, seconds.
    pub dissipation_s: f32,
    /// Sprites nearer the centre than this fraction of the cloud radius form first (paper: 0.5).
    pub inner_radius_fraction: f32,
    /// Opacity the inner sprites reach before the outer ones start to fade in, 0..1.
    pub outer_start_opacity: f32,
    /// A weather change the drift brings (the air crossing onto ground of other weather, the
    /// weather field itself unchanged) forms and dissipates while the air drifts this far,
    /// metres, where that is quicker than `formation_s` and `dissipation_s`
    /// ([`Self::spans_for_drift`]).
    #[serde(default = "default_drift_change_m")]
    pub drift_change_m: f32,
}

/// [`LifecycleConfig::drift_change_m`] where a settings file does not set it.
fn default_drift_change_m() -> f32 {
    1_000.0
}

impl LifecycleConfig {
    /// How long a change the drift brings takes to form and to dissipate, seconds, for air
    /// drifting at `speed_m_s`: the time it takes to drift [`Self::drift_change_m`], at most
    /// `formation_s` and `dissipation_s`. The weather field is fixed to the ground, so the
    /// clouds over a place show its weather once the air has come `drift_change_m` into it;
    /// forming over Wang's ten minutes instead, clouds in a 40 kt wind were still forming
    /// 12 km on, and an overcast over a windy station showed holes.
    pub fn spans_for_drift(&self, speed_m_s: f64) -> (f32, f32) {
        let crossing_s = (f64::from(self.drift_change_m) / speed_m_s.max(1e-6)) as f32;
        (
            self.formation_s.min(crossing_s),
            self.dissipation_s.min(crossing_s),
        )
    }
}

/// Settings of the field of blocks around the camera.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldConfig {
    /// Blocks whose centre lies within this distance of the field centre exist, metres.
    pub radius_m: f64,
    /// World seed; block content is a pure function of it, the block index and the weather.
    pub seed: u64,
    /// Layer wind over surface wind (clouds drift faster than the surface wind), >= 0.
    pub wind_factor: f64,
    /// How many drift bands the layers are split into, 1..=[`MAX_DRIFT_BANDS`]: a block's
    /// lowest layer is band 0, the next band 1, and so on, the last band taking the rest. Each
    /// band drifts with the wind at its own height (one field of blocks each, see
    /// [`super::field::CloudField`]); 1: every layer drifts as one.
    #[serde(default = "default_drift_bands")]
    pub drift_bands: u8,
}

/// The most drift bands a field may have (a METAR reports at most six layers; past the fourth
/// they are rare).
pub const MAX_DRIFT_BANDS: u8 = 4;

/// [`FieldConfig::drift_bands`] where a settings file does not set it.
fn default_drift_bands() -> u8 {
    MAX_DRIFT_BANDS
}

/// `config/clouds.toml`: lifecycle and field settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudsConfig {
    /// Formation and dissipation.
    pub lifecycle: LifecycleConfig,
    /// The field of blocks.
    pub field: FieldConfig,
}

impl CloudsConfig {
    /// Reads and validates `config/clouds.toml`.
    pub fn load(path: &Path) -> Result<Self, CloudsError> {
        let text = read(path)?;
        Self::parse(&text, path)
    }

    /// The shipped defaults (`config/clouds.toml`, compiled in).
    pub fn builtin() -> Self {
        Self::parse(BUILTIN_CLOUDS, Path::new("config/clouds.toml"))
            .expect("the shipped config/clouds.toml is valid (tested)")
    }

    /// Parses and validates; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, CloudsError> {
        let config: CloudsConfig = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        let v = Validator {
            text,
            path,
            section: "lifecycle",
        };
        let l = &config.lifecycle;
        v.check(l.formation_s > 0.0, "formation_s", "must be > 0 seconds")?;
        v.check(
            l.dissipation_s > 0.0,
            "dissipation_s",
            "must be > 0 seconds",
        )?;
        v.check(
            l.inner_radius_fraction > 0.0 && l.inner_radius_fraction < 1.0,
            "inner_radius_fraction",
            "must be between 0 and 1 (exclusive)",
        )?;
        v.check(
            l.outer_start_opacity > 0.0 && l.outer_start_opacity < 1.0,
            "outer_start_opacity",
            "must be between 0 and 1 (exclusive)",
        )?;
        v.check(
            l.drift_change_m > 0.0 && l.drift_change_m.is_finite(),
            "drift_change_m",
            "must be > 0 metres",
        )?;
        let v = Validator {
            section: "field",
            ..v
        };
        let f = &config.field;
        v.check(f.radius_m > 0.0, "radius_m", "must be > 0 metres")?;
        v.check(f.wind_factor >= 0.0, "wind_factor", "must be >= 0")?;
        v.check(
            (1..=MAX_DRIFT_BANDS).contains(&f.drift_bands),
            "drift_bands",
            "must be within 1..=4",
        )?;
        Ok(config)
    }
}

fn read(path: &Path) -> Result<String, CloudsError> {
    std::fs::read_to_string(path).map_err(|source| CloudsError::Read {
        path: path.to_owned(),
        source,
    })
}

/// The `[section]` header before a byte offset, if any.
fn section_before(text: &str, offset: usize) -> Option<String> {
    let head = text.get(..offset.min(text.len()))?;
    head.lines().rev().find_map(|l| {
        let t = l.trim();
        (t.starts_with('[') && !t.starts_with("[[") && t.ends_with(']'))
            .then(|| t.trim_matches(|c| c == '[' || c == ']').trim().to_owned())
    })
}

/// Turns a toml error into one naming the line and the field, qualified by its `[section]`.
fn toml_error(path: &Path, text: &str, err: &toml::de::Error) -> CloudsError {
    let base = ConfigError::from_toml(path, text, err);
    let offset = err.span().map_or(0, |s| s.start);
    let key = base.field.unwrap_or_else(|| "?".to_owned());
    let field = match section_before(text, offset + 1) {
        Some(section) if section != key => format!("{section}.{key}"),
        _ => key,
    };
    CloudsError::Parse {
        path: path.to_owned(),
        line: base.line.unwrap_or(1),
        field,
        message: base.message,
    }
}

struct Validator<'a> {
    text: &'a str,
    path: &'a Path,
    section: &'a str,
}

impl Validator<'_> {
    /// Line of `key = ...` inside `[section]` (the header line when not found).
    fn line(&self, key: &str) -> usize {
        let header = format!("[{}]", self.section);
        let lines: Vec<&str> = self.text.lines().collect();
        let Some(start) = lines.iter().position(|l| l.trim() == header) else {
            return 1;
        };
        for (n, l) in lines.iter().enumerate().skip(start + 1) {
            let t = l.trim_start();
            if t.starts_with('[') && !t.starts_with("[[") {
                break;
            }
            if let Some(rest) = t.strip_prefix(key)
                && rest.trim_start().starts_with('=')
            {
                return n + 1;
            }
        }
        start + 1
    }

    fn check(&self, ok: bool, key: &str, message: &str) -> Result<(), CloudsError> {
        if ok {
            return Ok(());
        }
        Err(CloudsError::Invalid {
            path: self.path.to_owned(),
            line: self.line(key),
            field: format!("{}.{key}", self.section),
            message: message.to_owned(),
        })
    }

    fn range_f32(&self, r: [f32; 2], key: &str, lo: f32, hi: f32) -> Result<(), CloudsError> {
        self.check(
            r[0] >= lo && r[0] <= r[1] && r[1] <= hi,
            key,
            &format!("must be [min, max] with {lo} <= min <= max <= {hi}"),
        )
    }

    fn range_u32(&self, r: [u32; 2], key: &str, lo: u32, hi: u32) -> Result<(), CloudsError> {
        self.check(
            r[0] >= lo && r[0] <= r[1] && r[1] <= hi,
            key,
            &format!("must be [min, max] with {lo} <= min <= max <= {hi}"),
        )
    }
}

/// [`CloudTypeConfig::placement_candidates`] when a type does not say.
fn one_candidate() -> u32 {
    1
}

fn validate(c: &CloudTypeConfig, name: &str, text: &str, path: &Path) -> Result<(), CloudsError> {
    let v = Validator {
        text,
        path,
        section: name,
    };
    v.range_f32(c.thickness_m, "thickness_m", 1.0, 20_000.0)?;
    v.range_f32(c.cloud_size_m, "cloud_size_m", 10.0, 20_000.0)?;
    v.check(
        !c.continuous || (100.0..=4_000.0).contains(&c.lattice_spacing_m),
        "lattice_spacing_m",
        "must be 100..=4000 metres for a continuous type",
    )?;
    v.check(
        (-1.0..=2.0).contains(&c.lattice_overhang),
        "lattice_overhang",
        "must be -1..=2 (the share of the sky a lattice keeping half its cells covers beyond \
         half, times 4)",
    )?;
    v.check(
        (1..=16).contains(&c.placement_candidates),
        "placement_candidates",
        "must be 1..=16 (1: a scattered cloud where the first random centre falls)",
    )?;
    v.range_u32(c.boxes_per_cloud, "boxes_per_cloud", 1, 50)?;
    v.check(
        (0.0..=1.0).contains(&c.taper),
        "taper",
        "must be 0..=1 (0 column, 1 cone)",
    )?;
    v.check(
        c.max_height_over_size > 0.0 && c.max_height_over_size <= 20.0,
        "max_height_over_size",
        "must be above 0 and at most 20",
    )?;
    if let Some(anvil) = c.anvil {
        v.check(
            anvil.from > 0.0 && anvil.from < 1.0 && anvil.width_scale >= 1.0,
            "anvil",
            "needs 0 < from < 1 and width_scale >= 1",
        )?;
    }
    if let Some(cell) = c.cell {
        v.check(
            (50..=4000).contains(&cell.sprites)
                && cell.sprite_over_base[0] > 0.0
                && cell.sprite_over_base[0] <= cell.sprite_over_base[1]
                && cell.sprite_over_base[1] <= 1.0
                && cell.anvil_share > 0.0
                && cell.anvil_share < 1.0
                && (0.0..=1.0).contains(&cell.shaded_share)
                && cell.anvil_alpha.iter().all(|a| (0.0..=1.0).contains(a)),
            "cell",
            "needs sprites 50..=4000, 0 < sprite_over_base low <= high <= 1, 0 < anvil_share < 1, 0 <= shaded_share <= 1, anvil_alpha within 0..=1",
        )?;
    }
    if let Some(p) = c.precipitation {
        v.check(
            p.shafts[0] >= 1 && p.shafts[0] <= p.shafts[1] && p.shafts[1] <= 12,
            "precipitation",
            "shafts must be 1..=12, the first at most the second",
        )?;
        v.check(
            p.width_over_base > 0.0
                && p.width_over_base <= 1.0
                && (0.0..=1.0).contains(&p.alpha[0])
                && p.alpha[0] <= p.alpha[1]
                && p.alpha[1] <= 1.0
                && p.virga_spread_c[0] < p.virga_spread_c[1]
                && p.min_reach > 0.0
                && p.min_reach <= 1.0,
            "precipitation",
            "needs width_over_base in (0, 1], alpha ascending within 0..=1, virga_spread_c ascending and min_reach in (0, 1]",
        )?;
    }
    if let Some(depth) = c.sunlit_depth_m {
        v.check(
            (1.0..=10_000.0).contains(&depth),
            "sunlit_depth_m",
            "must be 1..=10000 metres",
        )?;
    }
    if let Some(height) = c.shaded_base_m {
        v.check(
            (1.0..=10_000.0).contains(&height) && !c.continuous && !c.flat,
            "shaded_base_m",
            "must be 1..=10000 metres, on a heaped type (not continuous, not flat)",
        )?;
    }
    if let Some(density) = c.optical_density {
        v.check(
            (0.001..=1.0).contains(&density),
            "optical_density",
            "must be 0.001..=1 (a factor on the in-cloud extinction)",
        )?;
    }
    if let Some(aspect) = c.streak_length_over_width {
        v.check(
            c.flat && (1.0..=50.0).contains(&aspect),
            "streak_length_over_width",
            "must be 1..=50, on a flat type",
        )?;
    }
    let b = c.boxes_per_block;
    v.check(
        [b.few, b.sct, b.bkn, b.ovc]
            .iter()
            .all(|n| (20..=200).contains(n))
            && b.few <= b.sct
            && b.sct <= b.bkn
            && b.bkn <= b.ovc,
        "boxes_per_block",
        "each of few, sct, bkn, ovc must be 20..=200 boxes per block, not decreasing",
    )?;
    v.range_u32(c.sprites_per_box, "sprites_per_box", 1, 100)?;
    let dc = c.density_by_cover;
    v.check(
        [dc.few, dc.sct, dc.bkn, dc.ovc]
            .iter()
            .all(|f| (0.1..=10.0).contains(f)),
        "density_by_cover",
        "each of few, sct, bkn, ovc must be 0.1..=10",
    )?;
    v.range_f32(c.sprite_width_m, "sprite_width_m", 1.0, 10_000.0)?;
    v.range_f32(c.sprite_height_ratio, "sprite_height_ratio", 0.05, 1.0)?;
    v.check(
        (0.0..=1.0).contains(&c.cull_radius_fraction),
        "cull_radius_fraction",
        "must be 0..=1 (1/3 typical, 1/5..1/6 dense)",
    )?;
    v.range_u32(c.shading_group_size, "shading_group_size", 1, 30)?;
    let bands = &c.texture_bands;
    v.check(
        !bands.is_empty(),
        "texture_bands",
        "needs at least one band",
    )?;
    let mut last = 0.0;
    for band in bands {
        v.check(
            band.up_to > last && band.up_to <= 1.0,
            "texture_bands",
            "up_to must rise from band to band within (0, 1]",
        )?;
        v.check(
            !band.textures.is_empty(),
            "texture_bands",
            "every band needs at least one texture category",
        )?;
        v.check(
            band.rotation_deg[0] <= band.rotation_deg[1],
            "texture_bands",
            "rotation_deg must be [min, max] with min <= max",
        )?;
        last = band.up_to;
    }
    v.check(
        last == 1.0,
        "texture_bands",
        "the last band must reach up_to = 1.0",
    )?;
    let mut last = 0.0;
    for level in &c.colour_levels {
        v.check(
            level.height >= last && level.height <= 1.0,
            "colour_levels",
            "heights must rise within 0..=1",
        )?;
        v.check(
            level.rgba.iter().all(|x| (0.0..=1.0).contains(x)),
            "colour_levels",
            "rgba components must be 0..=1",
        )?;
        last = level.height;
    }
    Ok(())
}

#[cfg(test)]
#[path = "config_tests.rs"]
mod tests;
