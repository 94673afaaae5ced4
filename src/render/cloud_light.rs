//! The Harris and Lastra light of the resident sprites (`crate::shading::harris_lastra`): per
//! sprite the sun's direct and total light and the skylight that reach it through its cloud,
//! packed into one `u32` of the resident light buffer (`lights` in `shaders/sprite_build.wgsl`,
//! at the sprite's slot). Computed on the CPU when a block is written and again after the sun
//! turned past the threshold, within a budget of sprites a frame, nearest blocks first (a block
//! that arrives past the budget is written with a provisional light and lit in a later frame;
//! a whole scene written at once is lit at once); the skylight only once a block. Never under
//! Wang's model. Its time is part of the frame's `cpu_update_us` and shown as `light_us`.

use glam::Vec3;

use super::scene::SkyBlock;
use crate::shading::{
    HarrisLastra, LightScratch, Particle, ParticleLight, RelightTrigger, ShadingModel,
    harris_lastra,
};

/// The light state of the resident set: the model's settings while it is on, the sun
/// direction the sprites are lit for, scratch space.
#[derive(Debug, Clone)]
pub(super) struct CloudLight {
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

    /// The packed light of every sprite of `block`, in its sprites' order, into `lights`: the
    /// sun's always, the skylight (which does not move with the sun) only when `lights` does not
    /// hold it yet (`sky_known` false), else its sky bytes are kept.
    pub fn block(&mut self, block: &SkyBlock, lights: &mut Vec<u32>, sky_known: bool) {
        let Some(settings) = self.settings else {
            lights.clear();
            return;
        };
        let sprites: usize = block.clouds.iter().map(|c| c.sprites.len()).sum();
        let sky_known = sky_known && lights.len() == sprites;
        if !sky_known {
            lights.clear();
            lights.resize(sprites, 0);
        }
        let mut at = 0;
        for cloud in &block.clouds {
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
            if !sky_known {
                settings.light(&self.particles, Vec3::Z, &mut self.scratch, &mut self.sky);
            }
            for (i, sun) in self.sun.iter().enumerate() {
                let packed = &mut lights[at + i];
                let sky = if sky_known {
                    ParticleLight {
                        direct: 0.0,
                        total: ((*packed >> 16) & 0xff) as f32 / 255.0,
                    }
                } else {
                    self.sky[i]
                };
                *packed = harris_lastra::pack_light(*sun, sky);
            }
            at += cloud.sprites.len();
        }
    }

    /// A first light for a block that arrives when the frame's budget is spent, until
    /// [`Self::block`] replaces it within a later frame's: each sprite as lit as its place in
    /// its cloud's sphere says (towards the sun and the top brighter), O(n), no shadows.
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
}
