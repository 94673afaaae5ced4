//! The Harris and Lastra light of the resident sprites (`crate::shading::harris_lastra`): per
//! sprite the sun's direct and total light and the skylight that reach it through its cloud,
//! packed into one `u32` of the resident light buffer (`lights` in `shaders/sprite_build.wgsl`,
//! at the sprite's slot). Computed on the CPU when a block is written and again after the sun
//! turned past the threshold, within a budget of sprites a frame, nearest blocks first, a cloud
//! at a time (at least one cloud a frame): a block that arrives past the budget is written with a
//! provisional light and lit cloud by cloud in the next frames; a whole scene written at once
//! (the first frame) is lit at once; a block written again (the buffers grew) keeps the light it
//! had. The skylight, which does not move with the sun, once a block. Never under Wang's model,
//! nor for decks (lit as one slab in the shader; their sprites cost the budget nothing).
//! Its time is part of the frame's `cpu_update_us` and shown as `light_us`.

use glam::Vec3;

use crate::render::scene::{SkyBlock, SkyCloud};
use crate::shading::{
    HarrisLastra, LightScratch, Particle, ParticleLight, RelightTrigger, ShadingModel,
    harris_lastra,
};

/// The light state of the resident set: the model's settings while it is on, the sun
/// direction the sprites are lit for, scratch space.
#[derive(Debug, Clone)]
pub(in crate::render) struct CloudLight {
    /// The model's constants, `None` under Wang's model (nothing computed).
    settings: Option<HarrisLastra>,
    trigger: RelightTrigger,
    /// The direction towards the sun the sprites are lit for (unit).
    pub sun_dir: Vec3,
    particles: Vec<Particle>,
    scratch: LightScratch,
    sun: Vec<ParticleLight>,
    sky: Vec<ParticleLight>,
}

/// A block's light: its packed lights (its sprites' order) and how far they are.
#[derive(Debug, Clone, Default)]
pub(in crate::render) struct BlockLight {
    /// Packed per sprite (empty until first lit).
    pub lights: Vec<u32>,
    /// The sun direction every cloud of it is lit for (none while provisional).
    pub lit_for: Option<Vec3>,
    /// Whether the skylight bytes are computed (not provisional).
    pub sky_exact: bool,
    /// A relight under way: the sun it is for, the next cloud, whether it computes the skylight.
    pub(super) pass: Option<(Vec3, usize, bool)>,
}

impl Default for CloudLight {
    fn default() -> Self {
        Self {
            settings: None,
            trigger: RelightTrigger::new(1.0),
            sun_dir: Vec3::Z,
            particles: Vec::new(),
            scratch: LightScratch::default(),
            sun: Vec::new(),
            sky: Vec::new(),
        }
    }
}

/// Where a block's lights go: the queue, the light buffer and the block's first sprite slot.
pub(in crate::render) type LightTarget<'a> = (&'a wgpu::Queue, &'a wgpu::Buffer, u32);

impl CloudLight {
    /// Sets the model and the sun of this frame; the lit direction follows the sun only when it
    /// turned past the threshold (or the settings changed). True when the model was just
    /// switched on (the blocks already written have no light yet).
    pub fn set(&mut self, model: ShadingModel, settings: &HarrisLastra, sun_dir: Vec3) -> bool {
        if model != ShadingModel::HarrisLastra {
            self.settings = None;
            return false;
        }
        let switched_on = self.settings.is_none();
        if self.settings.as_ref() != Some(settings) {
            self.settings = Some(*settings);
            self.trigger = RelightTrigger::new(settings.relight_sun_deg);
        }
        if self.trigger.update(sun_dir) {
            self.sun_dir = self.trigger.lit_for.unwrap_or(Vec3::Z);
        }
        switched_on
    }

    /// Whether the model is on.
    pub fn enabled(&self) -> bool {
        self.settings.is_some()
    }

    /// Most sprites lit a frame (blocks arriving, and relit after the sun turned).
    pub fn budget(&self) -> u32 {
        self.settings
            .map_or(0, |s| s.max_lit_sprites_per_frame.max(1))
    }

    /// The packed light of the sprites of `cloud` into `out` (one per sprite): the sun's always,
    /// the skylight when `with_sky`, else `out`'s sky bytes are kept.
    pub(super) fn cloud(&mut self, cloud: &SkyCloud, with_sky: bool, out: &mut [u32]) {
        let Some(settings) = self.settings else {
            return;
        };
        if lit_in_shader(cloud) {
            out.fill(0);
            return;
        }
        self.particles.clear();
        self.particles
            .extend(cloud.sprites.iter().map(|s| Particle {
                centre_m: s.offset_m,
                radius_m: (0.5 * s.width_m.max(s.height_m)).max(1e-3),
                density: if s.precipitation { 0.0 } else { s.alpha_morph },
            }));
        settings.light(
            &self.particles,
            self.sun_dir,
            &mut self.scratch,
            &mut self.sun,
        );
        if with_sky {
            settings.light(&self.particles, Vec3::Z, &mut self.scratch, &mut self.sky);
        }
        for (i, (packed, sun)) in out.iter_mut().zip(&self.sun).enumerate() {
            let sky = if with_sky {
                self.sky[i]
            } else {
                ParticleLight {
                    direct: 0.0,
                    total: ((*packed >> 16) & 0xff) as f32 / 255.0,
                }
            };
            *packed = harris_lastra::pack_light(*sun, sky);
        }
    }

    /// The packed light of every sprite of `block`, in its sprites' order, into `lights`.
    pub fn block(&mut self, block: &SkyBlock, lights: &mut Vec<u32>) {
        let sprites: usize = block.clouds.iter().map(|c| c.sprites.len()).sum();
        lights.clear();
        lights.resize(sprites, 0);
        let mut at = 0;
        for cloud in &block.clouds {
            let n = cloud.sprites.len();
            self.cloud(cloud, true, &mut lights[at..at + n]);
            at += n;
        }
    }

    /// A first light for a block that arrives when the frame's budget is spent, until its own
    /// replaces it in later frames: each sprite as lit as its place in its cloud's sphere says
    /// (towards the sun and the top brighter), O(n), no shadows.
    pub fn provisional(&self, block: &SkyBlock, lights: &mut Vec<u32>) {
        lights.clear();
        for cloud in &block.clouds {
            let radius = cloud.radius_m().max(1.0);
            lights.extend(cloud.sprites.iter().map(|s| {
                let towards = (0.5 + 0.5 * s.offset_m.dot(self.sun_dir) / radius).clamp(0.0, 1.0);
                let up = (0.5 + 0.5 * s.offset_m.z / radius).clamp(0.0, 1.0);
                let total = 0.3 + 0.7 * towards;
                let sun = ParticleLight {
                    direct: total * total,
                    total,
                };
                let sky = ParticleLight {
                    direct: 0.0,
                    total: 0.4 + 0.6 * up,
                };
                harris_lastra::pack_light(sun, sky)
            }));
        }
    }

    /// The light of block `r` as it is written to its slots: the light it has if it has one
    /// (written again after the buffers grew; a stale one is relit later), else its own when
    /// `budget` (sprites, taken from) allows, else a provisional one. Returns the bytes written
    /// and the sprites lit.
    pub fn written(
        &mut self,
        (block, light): (&SkyBlock, &mut BlockLight),
        to: LightTarget,
        budget: &mut u32,
    ) -> (u64, u32) {
        let n: u32 = block.clouds.iter().map(|c| c.sprites.len() as u32).sum();
        let cost = sprites_to_light(&block.clouds);
        let mut lit = 0;
        if light.lights.len() != n as usize {
            if cost <= *budget {
                self.block(block, &mut light.lights);
                light.lit_for = Some(self.sun_dir);
                light.sky_exact = true;
                *budget -= cost;
                lit = cost;
            } else {
                self.provisional(block, &mut light.lights);
                (light.lit_for, light.sky_exact) = (None, false);
            }
            light.pass = None;
        }
        (write_lights(to, 0, &light.lights), lit)
    }
}

/// Whether `cloud` is a deck (one cloud per lattice cell), lit as one slab corner by corner in
/// the shader (`deck_harris_lastra` in shaders/sprite_build.wgsl): each cell lit alone here
/// would take the sun on its sunward side, a grid seen from above. Its sprites cost the light
/// budget nothing.
pub(super) fn lit_in_shader(cloud: &SkyCloud) -> bool {
    cloud.sunlit_depth_m > 0.0
}

/// The sprites of `clouds` the light is computed for here (not decks').
fn sprites_to_light<'a>(clouds: impl IntoIterator<Item = &'a SkyCloud>) -> u32 {
    clouds
        .into_iter()
        .filter(|c| !lit_in_shader(c))
        .map(|c| c.sprites.len() as u32)
        .sum()
}

/// Writes packed lights at the block's slot `to.2` plus `offset`; returns the bytes.
pub(super) fn write_lights(
    (queue, buffer, first): LightTarget,
    offset: u32,
    lights: &[u32],
) -> u64 {
    if lights.is_empty() {
        return 0;
    }
    let at = (first + offset) as u64 * 4;
    queue.write_buffer(buffer, at, bytemuck::cast_slice(lights));
    lights.len() as u64 * 4
}
