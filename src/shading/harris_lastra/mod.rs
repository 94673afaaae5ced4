//! A second, physically based cloud shading model after Harris and Lastra 2001 ("Real-Time
//! Cloud Rendering", Eurographics), switchable with Wang's artist model (`[shading] model` of
//! `config/time_of_day.toml`, `--shading` on the command line).
//!
//! In: a cloud's particles (the sprites: centre, radius, opacity), a direction towards a light.
//! Out: per particle the light that reaches it through the particles between it and the light,
//! as fractions of the light outside the cloud: the direct part (not scattered on the way) and
//! the total (direct plus what the particles in front scattered forward).
//!
//! - Multiple forward scattering, section 2.2.1, recurrence (4): `I_k = g_{k-1} + T_{k-1} I_{k-1}`
//!   with `g_j = a_j tau_j p(l, -l) I_j / 4 pi`. The paper splats the particles, sorted towards
//!   the light, into a frame buffer and reads back the pixel under each particle's centre; here
//!   the same recurrence is evaluated for the one ray through each particle's centre: the
//!   particles nearer the light that the ray passes through (a sphere of the sprite's mean half
//!   size, with a smooth splat profile) attenuate it by their opacity `1 - exp(-tau)` times the
//!   profile and add back what they scatter forward. The forward phase is Rayleigh's
//!   `3/4 (1 + cos^2)` at 0 degrees, as the paper; with its `tau = 8`, albedo 0.9 a particle sends
//!   on 0.86 of the light it stops.
//! - Eye scattering, 2.2.2 (5), is the renderer's back-to-front blending; a particle's colour is
//!   the light it received times the phase function towards the eye ([`HarrisLastra::phase`]).
//!   Phase: Henyey-Greenstein (forward lobe `g`) for the direct light, mixed with an isotropic
//!   part, not the paper's Rayleigh: Rayleigh is symmetric, so a cloud with the sun behind the
//!   camera would glow as much as one against the sun, and the paper itself says cloud droplets
//!   are Mie scatterers with a strong forward peak (its "silver lining"). The light a particle
//!   got by forward scattering (total minus direct) has been scattered already and is treated as
//!   isotropic, so a thick body against a low sun is dark while its thin rim glows.
//! - Skylight, 2.3.1: a second light straight down from the sky, attenuated the same way, with
//!   the time-of-day table's sky colours; plus the paper's small ambient term.
//! - When: the light is computed when a block arrives and again only after the sun has turned
//!   more than `relight_sun_deg` ([`RelightTrigger`]), a budget of sprites a frame.
//!
//! Plain data, no wgpu. Units: metres, degrees; light as fractions 0..=1.

mod grid;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use grid::Grid;
pub use grid::LightScratch;

/// Which cloud shading model the renderer uses (`[shading] model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadingModel {
    /// Wang 2003: artist colour levels by height and directional shading groups (the default).
    #[default]
    Wang,
    /// Harris and Lastra 2001: light through the cloud's particles, phase function, skylight.
    HarrisLastra,
}

impl ShadingModel {
    /// The model named `name`: `wang`, or `harris_lastra` (also `harris-lastra`).
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "wang" => Some(Self::Wang),
            "harris_lastra" | "harris-lastra" => Some(Self::HarrisLastra),
            _ => None,
        }
    }
}

/// The `[shading]` table of `config/time_of_day.toml`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadingSettings {
    /// `"wang"` or `"harris_lastra"`.
    pub model: ShadingModel,
}

/// The `[harris_lastra]` table of `config/time_of_day.toml`: the model's constants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HarrisLastra {
    /// Optical depth of a particle through its centre, 0..=32 (the paper's `tau` is 8; with
    /// the paper's albedo a particle then sends on 0.86 of the light it stops, which leaves
    /// the thick body of a cumulus of Wang's sprites almost as bright as its sunlit side; 5
    /// sends on 0.54).
    pub optical_depth: f32,
    /// Albedo: the part of the stopped light that is scattered, not absorbed (0.9), 0..=1.
    pub albedo: f32,
    /// Henyey-Greenstein asymmetry of the eye scattering, 0..=0.95.
    pub g: f32,
    /// Weight of the Henyey-Greenstein lobe in the phase function; the rest is isotropic, 0..=1.
    pub lobe_weight: f32,
    /// The sun's light on a cloud: this x the time-of-day directional colour, 0..=4.
    pub sun_strength: f32,
    /// The skylight: this x the sky's mean colour (zenith and horizon), 0..=4.
    pub sky_strength: f32,
    /// The ambient term: this x the time-of-day ambient percentage, grey, 0..=1.
    pub ambient: f32,
    /// Recompute the light after the sun has turned this far, degrees, 0.01..=30.
    pub relight_sun_deg: f32,
    /// Most sprites lit a frame, blocks arriving and relit after the sun turned (the nearest
    /// blocks first; the others keep their light a little longer), at least 1.
    pub max_lit_sprites_per_frame: u32,
}

impl Default for HarrisLastra {
    fn default() -> Self {
        Self {
            optical_depth: 5.0,
            albedo: 0.9,
            g: 0.6,
            lobe_weight: 0.2,
            sun_strength: 0.7,
            sky_strength: 0.55,
            ambient: 0.18,
            relight_sun_deg: 1.0,
            max_lit_sprites_per_frame: 256,
        }
    }
}

/// One particle of a cloud, as the light pass sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Particle {
    /// Centre, metres (any frame shared by the cloud's particles).
    pub centre_m: Vec3,
    /// Radius, metres (> 0).
    pub radius_m: f32,
    /// Factor on its opacity, 0..=1 (its `alpha_morph`; 0 for rain, which casts no shadow).
    pub density: f32,
}

/// The light that reaches one particle, fractions of the light outside the cloud.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ParticleLight {
    /// Not scattered on the way (Beer's law through the particles in front).
    pub direct: f32,
    /// Direct plus scattered forward by the particles in front (the paper's `I_k / I_0`).
    pub total: f32,
}

/// The three numbers a sprite is shaded with, packed for the GPU: direct sun, total sun and
/// skylight, 8 bits each (bytes 0, 1, 2), as WGSL's `unpack4x8unorm` reads them.
pub fn pack_light(sun: ParticleLight, sky: ParticleLight) -> u32 {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u32;
    q(sun.direct) | (q(sun.total) << 8) | (q(sky.total) << 16)
}

/// Smooth splat profile: 1 at the centre, 0 at `radius` and beyond (`b2` the squared impact
/// parameter over the squared radius).
fn splat(b2: f32) -> f32 {
    let t = (1.0 - b2).max(0.0);
    t * t
}

impl HarrisLastra {
    /// A particle's opacity at its centre, `1 - exp(-tau)`.
    pub fn opacity(&self) -> f32 {
        1.0 - (-self.optical_depth).exp()
    }

    /// The part of the light a particle stops that it sends on in the light's direction: the
    /// paper's `g = a tau p(l, -l) / 4 pi` over the opacity, with Rayleigh's `p = 3/2` straight
    /// ahead; at most the albedo.
    pub fn forward_fraction(&self) -> f32 {
        let opacity = self.opacity();
        if opacity <= 0.0 {
            return 0.0;
        }
        let g = self.albedo * self.optical_depth * 1.5 / (4.0 * std::f32::consts::PI);
        (g / opacity).min(self.albedo)
    }

    /// The light reaching each of `particles` from a light in direction `to_light` (unit,
    /// towards the light), written into `out` (same order as `particles`); `scratch` is kept
    /// between calls. The particles are sorted along the light; a particle's occluders are
    /// looked for in a grid across the light (cells as wide as the largest particle), so a
    /// deck of thousands of sprites costs about as much a sprite as a small cumulus.
    pub fn light(
        &self,
        particles: &[Particle],
        to_light: Vec3,
        scratch: &mut LightScratch,
        out: &mut Vec<ParticleLight>,
    ) {
        let n = particles.len();
        out.clear();
        out.resize(n, ParticleLight::default());
        let to_light = to_light.normalize_or_zero();
        if to_light == Vec3::ZERO {
            out.fill(ParticleLight {
                direct: 1.0,
                total: 1.0,
            });
            return;
        }
        let LightScratch {
            order,
            cell_of,
            cell_start,
            in_cell,
            candidates,
        } = scratch;
        order.clear();
        order.extend(0..n as u32);
        // Nearest the light first: the recurrence runs along the light.
        let depth = |i: u32| -particles[i as usize].centre_m.dot(to_light);
        order.sort_by(|&a, &b| depth(a).total_cmp(&depth(b)).then(a.cmp(&b)));
        let grid = Grid::new(particles, order, to_light, cell_of, cell_start, in_cell);
        let opacity = self.opacity();
        let forward = self.forward_fraction();
        for (rank, &k) in order.iter().enumerate() {
            let pk = particles[k as usize].centre_m;
            grid.candidates(rank as u32, cell_of, cell_start, in_cell, candidates);
            let (mut direct, mut total) = (1.0f32, 1.0f32);
            for &r in candidates.iter() {
                let j = order[r as usize];
                let p = &particles[j as usize];
                let d = p.centre_m - pk;
                let along = d.dot(to_light);
                if along <= 0.0 {
                    continue;
                }
                let r2 = p.radius_m * p.radius_m;
                let b2 = (d - to_light * along).length_squared();
                if b2 >= r2 {
                    continue;
                }
                let alpha = opacity * p.density.clamp(0.0, 1.0) * splat(b2 / r2);
                let lit = out[j as usize].total;
                direct *= 1.0 - alpha;
                total = forward * alpha * lit + (1.0 - alpha) * total;
            }
            out[k as usize] = ParticleLight {
                direct,
                total: total.max(direct),
            };
        }
    }

    /// The phase function towards the eye, 1 on average over the sphere: the
    /// Henyey-Greenstein lobe (weight `lobe_weight`) plus an isotropic rest. `cos_angle` is the
    /// cosine between the view (camera to particle) and the direction towards the light: 1
    /// looking straight into the light.
    pub fn phase(&self, cos_angle: f32) -> f32 {
        let g = self.g;
        let c = cos_angle.clamp(-1.0, 1.0);
        let hg = (1.0 - g * g) / (1.0 + g * g - 2.0 * g * c).powf(1.5);
        (1.0 - self.lobe_weight) + self.lobe_weight * hg
    }

    /// The first field out of range, with why.
    pub fn invalid_field(&self) -> Option<(&'static str, String)> {
        let checks: [(&'static str, f32, f32, f32); 8] = [
            ("harris_lastra.optical_depth", self.optical_depth, 0.0, 32.0),
            ("harris_lastra.albedo", self.albedo, 0.0, 1.0),
            ("harris_lastra.g", self.g, 0.0, 0.95),
            ("harris_lastra.lobe_weight", self.lobe_weight, 0.0, 1.0),
            ("harris_lastra.sun_strength", self.sun_strength, 0.0, 4.0),
            ("harris_lastra.sky_strength", self.sky_strength, 0.0, 4.0),
            ("harris_lastra.ambient", self.ambient, 0.0, 1.0),
            (
                "harris_lastra.relight_sun_deg",
                self.relight_sun_deg,
                0.01,
                30.0,
            ),
        ];
        for (field, value, lo, hi) in checks {
            if !(lo..=hi).contains(&value) {
                return Some((field, format!("must be {lo}..={hi}, is {value}")));
            }
        }
        if self.max_lit_sprites_per_frame == 0 {
            return Some((
                "harris_lastra.max_lit_sprites_per_frame",
                "must be at least 1".to_owned(),
            ));
        }
        None
    }
}

/// Decides when the light must be computed again: when the sun has turned more than the
/// threshold from where it was when the clouds were last lit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelightTrigger {
    /// Direction towards the sun the clouds are lit for (unit), if lit yet.
    pub lit_for: Option<Vec3>,
    /// Cosine of the threshold angle.
    cos_threshold: f32,
}

impl RelightTrigger {
    /// A trigger that fires after the sun turned more than `threshold_deg`.
    pub fn new(threshold_deg: f32) -> Self {
        Self {
            lit_for: None,
            cos_threshold: threshold_deg.to_radians().cos(),
        }
    }

    /// True (and the sun is taken as the new lit direction) when `sun_dir` is more than the
    /// threshold from the lit direction, or nothing is lit yet.
    pub fn update(&mut self, sun_dir: Vec3) -> bool {
        let sun = sun_dir.normalize_or_zero();
        let fire = match self.lit_for {
            None => true,
            Some(lit) => lit.dot(sun) < self.cos_threshold,
        };
        if fire {
            self.lit_for = Some(sun);
        }
        fire
    }
}

#[cfg(test)]
mod tests;
