//! The light of the resident set's blocks: every written block given a provisional light when
//! the Harris and Lastra model is switched on, and the blocks lit for an old sun relit, nearest
//! first, within the frame's budget. The per-block and per-cloud light itself is
//! [`cloud_light`](super::cloud_light)'s, which knows nothing of the resident set.

use glam::DVec3;

use super::cloud_light::{lit_in_shader, write_lights};
use super::resident::{Resident, ResidentSet};

impl ResidentSet {
    /// Gives every written block a provisional light (the model was just switched on;
    /// [`Self::relight`] gives them their own, a budget a frame); returns the bytes.
    pub fn provisional_all(&mut self, queue: &wgpu::Queue) -> u64 {
        let start = std::time::Instant::now();
        let mut bytes = 0;
        for r in self.blocks.values_mut() {
            let Some((s, _)) = r.place.clone() else {
                continue;
            };
            if !r.uploaded {
                continue;
            }
            self.light.provisional(&r.block, &mut r.light.lights);
            (r.light.lit_for, r.light.sky_exact, r.light.pass) = (None, false, None);
            bytes += write_lights((queue, &self.light_buffer, s.start), 0, &r.light.lights);
        }
        self.light_us += start.elapsed().as_micros() as u64;
        bytes
    }

    /// Computes again the light of written blocks not lit for the current lit direction,
    /// nearest to `camera_m` first, a cloud at a time, until what this frame's arrivals left of
    /// the budget is spent (at least one cloud a frame); returns the bytes written.
    pub fn relight(&mut self, queue: &wgpu::Queue, camera_m: DVec3) -> u64 {
        if !self.light.enabled() {
            return 0;
        }
        let start = std::time::Instant::now();
        let target = self.light.sun_dir;
        let mut stale: Vec<(f64, &mut Resident)> = self
            .blocks
            .values_mut()
            .filter(|r| r.place.is_some() && r.uploaded && r.light.lit_for != Some(target))
            .map(|r| ((r.centre_m() - camera_m).length_squared(), r))
            .collect();
        if stale.is_empty() {
            return 0;
        }
        stale.sort_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.tie_order(b.1)));
        let budget = self.light.budget().saturating_sub(self.lit_sprites);
        let (mut lit, mut bytes) = (0u32, 0u64);
        for (_, r) in stale {
            let Some((s, _)) = r.place.clone() else {
                continue;
            };
            let n = r.sprite_count() as usize;
            let light = &mut r.light;
            if light.lights.len() != n {
                self.light.provisional(&r.block, &mut light.lights);
                light.sky_exact = false;
            }
            let (mut next, with_sky) = match light.pass {
                Some((sun, next, with_sky)) if sun == target => (next, with_sky),
                _ => (0, !light.sky_exact),
            };
            // The clouds lit this frame are next to each other: one write a run of them (a deck,
            // lit in the shader, ends a run and is neither lit nor written).
            let at = (queue, &self.light_buffer, s.start);
            let mut from = r.clouds.get(next).map_or(0, |c| c.sprite_base - s.start) as usize;
            let mut to = from;
            let mut done = true;
            while next < r.block.clouds.len() {
                if lit > 0 && lit >= budget {
                    light.pass = Some((target, next, with_sky));
                    done = false;
                    break;
                }
                let cloud = &r.block.clouds[next];
                let first = (r.clouds[next].sprite_base - s.start) as usize;
                let end = first + cloud.sprites.len();
                next += 1;
                if lit_in_shader(cloud) {
                    bytes += write_lights(at, from as u32, &light.lights[from..to]);
                    (from, to) = (end, end);
                    continue;
                }
                self.light
                    .cloud(cloud, with_sky, &mut light.lights[first..end]);
                lit += cloud.sprites.len() as u32;
                to = end;
            }
            bytes += write_lights(at, from as u32, &light.lights[from..to]);
            if !done {
                break;
            }
            (light.lit_for, light.pass) = (Some(target), None);
            light.sky_exact |= with_sky;
        }
        self.lit_sprites += lit;
        self.light_us += start.elapsed().as_micros() as u64;
        bytes
    }
}
