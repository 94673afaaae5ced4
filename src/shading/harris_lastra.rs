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

use glam::Vec3;
use serde::{Deserialize, Serialize};

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
    /// Optical depth of a particle through its centre (the paper's `tau`, 8), 0..=32.
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
    /// Most sprites relit a frame after the sun turned (the nearest blocks first; the others
    /// keep their light a little longer), at least 1.
    pub max_relit_sprites_per_frame: u32,
}

impl Default for HarrisLastra {
    fn default() -> Self {
        Self {
            optical_depth: 8.0,
            albedo: 0.9,
            g: 0.6,
            lobe_weight: 0.25,
            sun_strength: 0.75,
            sky_strength: 0.8,
            ambient: 0.25,
            relight_sun_deg: 1.0,
            max_relit_sprites_per_frame: 8192,
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
    /// towards the light), written into `out` (same order as `particles`). `order` is scratch.
    /// O(n^2) in the cloud's particles, after a sort along the light.
    pub fn light(
        &self,
        particles: &[Particle],
        to_light: Vec3,
        order: &mut Vec<u32>,
        out: &mut Vec<ParticleLight>,
    ) {
        let n = particles.len();
        out.clear();
        out.resize(n, ParticleLight::default());
        order.clear();
        order.extend(0..n as u32);
        // Nearest the light first: the recurrence runs along the light.
        let depth = |i: u32| -particles[i as usize].centre_m.dot(to_light);
        order.sort_by(|&a, &b| depth(a).total_cmp(&depth(b)));
        let opacity = self.opacity();
        let forward = self.forward_fraction();
        for (rank, &k) in order.iter().enumerate() {
            let pk = particles[k as usize].centre_m;
            let (mut direct, mut total) = (1.0f32, 1.0f32);
            for &j in &order[..rank] {
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
        if self.max_relit_sprites_per_frame == 0 {
            return Some((
                "harris_lastra.max_relit_sprites_per_frame",
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
mod tests {
    use super::*;

    fn particle(x: f32, y: f32, z: f32) -> Particle {
        Particle {
            centre_m: Vec3::new(x, y, z),
            radius_m: 100.0,
            density: 1.0,
        }
    }

    fn lit(particles: &[Particle], to_light: Vec3) -> Vec<ParticleLight> {
        let mut order = Vec::new();
        let mut out = Vec::new();
        HarrisLastra::default().light(particles, to_light, &mut order, &mut out);
        out
    }

    #[test]
    fn a_particle_behind_others_gets_less_light_and_more_of_them_less_still() {
        // The sun along +x; particles in a row along x, the first nearest the sun.
        let row: Vec<Particle> = (0..6)
            .map(|i| particle(-120.0 * i as f32, 0.0, 0.0))
            .collect();
        let l = lit(&row, Vec3::X);
        assert_eq!(l[0].direct, 1.0);
        assert_eq!(l[0].total, 1.0);
        for pair in l.windows(2) {
            assert!(pair[1].total < pair[0].total, "{l:?}");
            assert!(pair[1].direct <= pair[0].direct, "{l:?}");
            assert!(pair[1].direct <= pair[1].total);
        }
        // Forward scattering keeps much more light than Beer's law alone, but it still falls.
        assert!(l[5].total > 3.0 * l[5].direct, "{l:?}");
        assert!(l[5].total < 0.7, "{l:?}");
        // The order of the input does not matter.
        let mut rev = row.clone();
        rev.reverse();
        let r = lit(&rev, Vec3::X);
        assert!((r[0].total - l[5].total).abs() < 1e-6);
    }

    #[test]
    fn only_particles_between_a_particle_and_the_light_shade_it() {
        // One beside the ray (farther than its radius), one behind: no shadow.
        let l = lit(
            &[
                particle(0.0, 0.0, 0.0),
                particle(300.0, 150.0, 0.0),
                particle(-200.0, 0.0, 0.0),
            ],
            Vec3::X,
        );
        assert_eq!(l[0].total, 1.0);
        assert!(l[2].total < 1.0);
        // Half a radius off the ray it shades, less than straight on.
        let off = lit(
            &[particle(0.0, 0.0, 0.0), particle(150.0, 50.0, 0.0)],
            Vec3::X,
        );
        let on = lit(
            &[particle(0.0, 0.0, 0.0), particle(150.0, 0.0, 0.0)],
            Vec3::X,
        );
        assert!(
            off[0].total < 1.0 && off[0].total > on[0].total,
            "{off:?} {on:?}"
        );
        // Rain (density 0) casts no shadow.
        let rain = Particle {
            density: 0.0,
            ..particle(150.0, 0.0, 0.0)
        };
        assert_eq!(lit(&[particle(0.0, 0.0, 0.0), rain], Vec3::X)[0].total, 1.0);
    }

    #[test]
    fn forward_fraction_is_the_papers() {
        let h = HarrisLastra::default();
        // tau 8, albedo 0.9, Rayleigh 3/2: 0.9 * 8 * 1.5 / 4 pi = 0.859.
        assert!(
            (h.forward_fraction() - 0.859).abs() < 0.002,
            "{}",
            h.forward_fraction()
        );
        let thin = HarrisLastra {
            optical_depth: 0.0,
            ..h
        };
        assert_eq!(thin.forward_fraction(), 0.0);
    }

    #[test]
    fn phase_peaks_towards_the_sun() {
        let h = HarrisLastra::default();
        let into = h.phase(1.0);
        let side = h.phase(0.0);
        let away = h.phase(-1.0);
        assert!(into > 2.0 * side && side > away, "{into} {side} {away}");
        // Monotonic from the back to the front.
        let mut last = 0.0;
        for i in 0..=20 {
            let p = h.phase(-1.0 + i as f32 * 0.1);
            assert!(p >= last);
            last = p;
        }
        // On average over the sphere it is 1 (no light made or lost): mean over cos in -1..1.
        let n = 20_000;
        let mean: f32 = (0..n)
            .map(|i| h.phase(-1.0 + (i as f32 + 0.5) * 2.0 / n as f32))
            .sum::<f32>()
            / n as f32;
        assert!((mean - 1.0).abs() < 0.01, "{mean}");
    }

    #[test]
    fn relight_only_after_the_sun_turned_past_the_threshold() {
        let mut t = RelightTrigger::new(1.0);
        let at = |deg: f32| {
            let r = deg.to_radians();
            Vec3::new(r.cos(), 0.0, r.sin())
        };
        assert!(t.update(at(10.0)), "first light");
        assert!(!t.update(at(10.0)));
        assert!(!t.update(at(10.5)));
        assert!(!t.update(at(10.95)));
        assert!(t.update(at(11.1)));
        // Measured from the last light, not the last call.
        assert!(!t.update(at(11.9)));
        assert!(t.update(at(12.2)));
    }

    #[test]
    fn light_packs_into_bytes() {
        let sun = ParticleLight {
            direct: 0.25,
            total: 1.0,
        };
        let sky = ParticleLight {
            direct: 0.0,
            total: 0.5,
        };
        let p = pack_light(sun, sky);
        assert_eq!(p & 0xff, 64);
        assert_eq!((p >> 8) & 0xff, 255);
        assert_eq!((p >> 16) & 0xff, 128);
    }

    #[test]
    fn models_are_named_and_settings_checked() {
        assert_eq!(ShadingModel::from_name("wang"), Some(ShadingModel::Wang));
        assert_eq!(
            ShadingModel::from_name("harris-lastra"),
            Some(ShadingModel::HarrisLastra)
        );
        assert_eq!(ShadingModel::from_name("phong"), None);
        assert!(HarrisLastra::default().invalid_field().is_none());
        let bad = HarrisLastra {
            albedo: 1.5,
            ..HarrisLastra::default()
        };
        assert_eq!(bad.invalid_field().unwrap().0, "harris_lastra.albedo");
    }
}
