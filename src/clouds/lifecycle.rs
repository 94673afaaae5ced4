//! Formation and dissipation (Wang 2003 §4) as a transparency factor per sprite, `alpha_morph`,
//! which the renderer multiplies into the shaded colour (§5.3, eq. 3).
//!
//! Formation, progress p = elapsed / formation_s in 0..=1: sprites within
//! `inner_radius_fraction` of the cloud radius fade in first, reaching full opacity at p = 0.5;
//! once they pass `outer_start_opacity` the outer sprites start, reaching full opacity at p = 1.
//! Dissipation, progress q = elapsed / dissipation_s: the outer sprites fade out over the first
//! half; then the inner ones, those nearer the edge faster (the ones at the inner radius are gone
//! at q = 0.75, the centre at q = 1). Both are monotonic in time and complete at their end.

use serde::{Deserialize, Serialize};

use super::block::Cloud;
use super::config::LifecycleConfig;

/// Where a cloud is in its life. A change of the weather in time forms and dissipates over the
/// lifecycle's `formation_s` and `dissipation_s`; one the drift brings (the air crossing onto
/// ground of other weather) is quicker ([`LifecycleConfig::spans_for_drift`]), so each phase
/// carries its own span.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Phase {
    /// Forming since `since_s` (field time, seconds) over `over_s`.
    Forming {
        /// Start time, seconds.
        since_s: f64,
        /// How long it takes to form, seconds.
        over_s: f32,
    },
    /// Fully formed.
    Steady,
    /// Dissipating since `since_s` (field time, seconds) over `over_s`.
    Dissipating {
        /// Start time, seconds.
        since_s: f64,
        /// How long it takes to dissipate, seconds.
        over_s: f32,
    },
    /// Superseded while still forming: going back the way it formed, from formation progress
    /// `from` at `since_s` down to nothing at the rate of a formation over `over_s` (its outer
    /// sprites first, as when dissipating). Dissipating from whole instead showed its
    /// half-formed clouds whole in one frame.
    Unforming {
        /// Start time, seconds.
        since_s: f64,
        /// The formation progress it had then, 0..=1.
        from: f32,
        /// The span of a whole formation at the rate it goes back, seconds.
        over_s: f32,
    },
    /// Dissipated completely: nothing left to draw.
    Gone,
}

impl Phase {
    /// Forming from `since_s` over `config`'s formation time (a change of the weather in time).
    pub fn forming(since_s: f64, config: &LifecycleConfig) -> Self {
        Phase::Forming {
            since_s,
            over_s: config.formation_s,
        }
    }

    /// Dissipating from `since_s` over `config`'s dissipation time.
    pub fn dissipating(since_s: f64, config: &LifecycleConfig) -> Self {
        Phase::Dissipating {
            since_s,
            over_s: config.dissipation_s,
        }
    }
}

/// Opacity factor of a sprite at formation progress `p` (0..=1).
pub fn formation_alpha(p: f32, radius_fraction: f32, config: &LifecycleConfig) -> f32 {
    let p = p.clamp(0.0, 1.0);
    let inner = (p / 0.5).min(1.0);
    if radius_fraction <= config.inner_radius_fraction {
        return inner;
    }
    let start = 0.5 * config.outer_start_opacity;
    ((p - start) / (1.0 - start)).clamp(0.0, 1.0)
}

/// Opacity factor of a sprite at dissipation progress `q` (0..=1).
pub fn dissipation_alpha(q: f32, radius_fraction: f32, config: &LifecycleConfig) -> f32 {
    let q = q.clamp(0.0, 1.0);
    if radius_fraction > config.inner_radius_fraction {
        return 1.0 - (q / 0.5).min(1.0);
    }
    let s = ((q - 0.5) / 0.5).max(0.0);
    let edge = radius_fraction / config.inner_radius_fraction;
    1.0 - (s * (1.0 + edge)).min(1.0)
}

/// The phase `phase` has reached at `now_s` (what [`apply`] returns, without a cloud): a
/// generation without clouds still forms, settles, dissipates and goes.
pub fn phase_at(phase: Phase, now_s: f64) -> Phase {
    match phase {
        Phase::Forming { since_s, over_s } if now_s - since_s >= f64::from(over_s) => Phase::Steady,
        Phase::Dissipating { since_s, over_s } if now_s - since_s >= f64::from(over_s) => {
            Phase::Gone
        }
        Phase::Unforming { .. } if progress(phase, now_s) <= 0.0 => Phase::Gone,
        other => other,
    }
}

/// The field time at which `phase` ends by itself (where [`phase_at`] moves it on: forming
/// becomes steady, dissipating or unforming becomes gone); `None` for Steady and Gone, which
/// last until something else changes them.
pub fn ends_at(phase: Phase) -> Option<f64> {
    match phase {
        Phase::Forming { since_s, over_s } | Phase::Dissipating { since_s, over_s } => {
            Some(since_s + f64::from(over_s))
        }
        Phase::Unforming {
            since_s,
            from,
            over_s,
        } => Some(since_s + f64::from(from) * f64::from(over_s)),
        Phase::Steady | Phase::Gone => None,
    }
}

/// Progress of a formation or dissipation at field time `now_s`, 0..=1 (1 for Steady and Gone);
/// of an unforming generation, the formation progress it is back at.
pub fn progress(phase: Phase, now_s: f64) -> f32 {
    let frac = |since_s: f64, span_s: f32| ((now_s - since_s) / span_s as f64).clamp(0.0, 1.0);
    match phase {
        Phase::Forming { since_s, over_s } | Phase::Dissipating { since_s, over_s } => {
            frac(since_s, over_s) as f32
        }
        Phase::Unforming {
            since_s,
            from,
            over_s,
        } => {
            let back = ((now_s - since_s) / over_s as f64).max(0.0);
            (from as f64 - back).clamp(0.0, 1.0) as f32
        }
        Phase::Steady | Phase::Gone => 1.0,
    }
}

/// The opacity factor of a sprite at `radius_fraction` in a cloud of phase `phase` at field time
/// `now_s` (what [`apply`] sets; the renderer works the same out on the GPU).
pub fn alpha_at(phase: Phase, now_s: f64, radius_fraction: f32, config: &LifecycleConfig) -> f32 {
    let p = progress(phase, now_s);
    match phase {
        Phase::Steady => 1.0,
        Phase::Gone => 0.0,
        Phase::Forming { .. } | Phase::Unforming { .. } => {
            formation_alpha(p, radius_fraction, config)
        }
        Phase::Dissipating { .. } => dissipation_alpha(p, radius_fraction, config),
    }
}

/// Sets every sprite's `alpha_morph` for a phase at field time `now_s` (for CPU pictures; the
/// living field leaves the sprites alone and the renderer fades them on the GPU); returns the
/// phase after (Forming becomes Steady once complete, Dissipating becomes Gone).
pub fn apply(cloud: &mut Cloud, phase: Phase, now_s: f64, config: &LifecycleConfig) -> Phase {
    match phase {
        Phase::Steady => {
            cloud.sprites.iter_mut().for_each(|s| s.alpha_morph = 1.0);
            Phase::Steady
        }
        Phase::Gone => {
            cloud.sprites.iter_mut().for_each(|s| s.alpha_morph = 0.0);
            Phase::Gone
        }
        Phase::Forming { .. } => {
            let p = progress(phase, now_s);
            for s in &mut cloud.sprites {
                s.alpha_morph = formation_alpha(p, s.radius_fraction, config);
            }
            if p >= 1.0 { Phase::Steady } else { phase }
        }
        Phase::Dissipating { .. } => {
            let q = progress(phase, now_s);
            for s in &mut cloud.sprites {
                s.alpha_morph = dissipation_alpha(q, s.radius_fraction, config);
            }
            if q >= 1.0 { Phase::Gone } else { phase }
        }
        Phase::Unforming { .. } => {
            let p = progress(phase, now_s);
            for s in &mut cloud.sprites {
                s.alpha_morph = formation_alpha(p, s.radius_fraction, config);
            }
            if p <= 0.0 { Phase::Gone } else { phase }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clouds::CloudsConfig;

    fn config() -> LifecycleConfig {
        CloudsConfig::builtin().lifecycle
    }

    const FRACTIONS: [f32; 6] = [0.0, 0.2, 0.5, 0.51, 0.8, 1.0];

    #[test]
    fn formation_is_monotonic_complete_and_inner_first() {
        let c = config();
        for rf in FRACTIONS {
            let mut last = 0.0;
            assert_eq!(formation_alpha(0.0, rf, &c), 0.0);
            for k in 0..=200 {
                let a = formation_alpha(k as f32 / 200.0, rf, &c);
                assert!(a >= last && (0.0..=1.0).contains(&a), "rf {rf} step {k}");
                last = a;
            }
            assert_eq!(last, 1.0, "rf {rf} does not finish");
        }
        // Outer sprites stay invisible until the inner ones reach the threshold opacity.
        for k in 0..=200 {
            let p = k as f32 / 200.0;
            if formation_alpha(p, 0.9, &c) > 0.0 {
                assert!(formation_alpha(p, 0.1, &c) >= c.outer_start_opacity);
            }
        }
        // And they start as soon as the inner ones pass it: within a step (0.01 of opacity).
        let first = (0..=200)
            .map(|k| k as f32 / 200.0)
            .find(|&p| formation_alpha(p, 0.9, &c) > 0.0)
            .unwrap();
        let inner = formation_alpha(first, 0.1, &c);
        assert!(
            inner - c.outer_start_opacity <= 0.011,
            "outer sprites start at inner opacity {inner}, not {}",
            c.outer_start_opacity
        );
    }

    /// The largest cloud of a generated cumulus block.
    fn a_cloud() -> Cloud {
        use crate::weather::{BlockIndex, BlockLayer, BlockWeather, CloudType, TypeSource};
        let weather = BlockWeather {
            layers: vec![BlockLayer {
                cloud_type: CloudType::CumulusMediocris,
                type_source: TypeSource::HeightRule,
                coverage_oktas: 4.0,
                base_ft_agl: 3000.0,
                thickness_ft: 2000.0,
            }],
            ..Default::default()
        };
        let types = crate::clouds::CloudTypes::builtin();
        let block = crate::clouds::generate_block(BlockIndex::new(0, 0), &weather, 7, &types);
        block
            .clouds
            .into_iter()
            .max_by_key(|c| c.sprites.len())
            .unwrap()
    }

    /// `apply` (the CPU pictures, `skycast preview --lifecycle`) sets each sprite's opacity for
    /// the progress since the phase's own start, and moves on only at the end: Forming becomes
    /// Steady at `formation_s`, Dissipating becomes Gone at `dissipation_s`. `alpha_at` says the
    /// same without a cloud.
    #[test]
    fn apply_fades_the_sprites_and_ends_the_phase_on_time() {
        let c = config();
        let mut cloud = a_cloud();
        let (f, d) = (c.formation_s as f64, c.dissipation_s as f64);
        let forming = Phase::forming(100.0, &c);
        assert_eq!(apply(&mut cloud, forming, 100.0 + 0.3 * f, &c), forming);
        for s in &cloud.sprites {
            let want = formation_alpha(0.3, s.radius_fraction, &c);
            assert!(
                (s.alpha_morph - want).abs() < 1e-5,
                "{} vs {want}",
                s.alpha_morph
            );
            let at = alpha_at(forming, 100.0 + 0.3 * f, s.radius_fraction, &c);
            assert!((at - want).abs() < 1e-5, "{at} vs {want}");
        }
        assert!(
            cloud
                .sprites
                .iter()
                .any(|s| s.alpha_morph > 0.0 && s.alpha_morph < 1.0)
        );
        assert_eq!(apply(&mut cloud, forming, 99.0 + f, &c), forming);
        assert_eq!(apply(&mut cloud, forming, 100.0 + f, &c), Phase::Steady);
        assert!(cloud.sprites.iter().all(|s| s.alpha_morph == 1.0));
        let dissipating = Phase::dissipating(100.0, &c);
        assert_eq!(
            apply(&mut cloud, dissipating, 100.0 + 0.6 * d, &c),
            dissipating
        );
        for s in &cloud.sprites {
            let want = dissipation_alpha(0.6, s.radius_fraction, &c);
            assert!(
                (s.alpha_morph - want).abs() < 1e-5,
                "{} vs {want}",
                s.alpha_morph
            );
        }
        assert_eq!(apply(&mut cloud, dissipating, 99.0 + d, &c), dissipating);
        assert_eq!(apply(&mut cloud, dissipating, 100.0 + d, &c), Phase::Gone);
        assert!(cloud.sprites.iter().all(|s| s.alpha_morph == 0.0));
        assert_eq!(alpha_at(Phase::Steady, 0.0, 0.9, &c), 1.0);
        assert_eq!(alpha_at(Phase::Gone, 0.0, 0.1, &c), 0.0);
    }

    /// What the renderer fades by (`Fade::Forming(progress)`): from the phase's own start to its
    /// end, 1 once settled or gone.
    #[test]
    fn a_phase_ends_where_phase_at_moves_it_on() {
        let c = config();
        for phase in [
            Phase::forming(100.0, &c),
            Phase::dissipating(100.0, &c),
            Phase::Unforming {
                since_s: 100.0,
                from: 0.4,
                over_s: c.formation_s,
            },
            // A drift's change, quicker than the lifecycle's.
            Phase::Forming {
                since_s: 100.0,
                over_s: 45.0,
            },
        ] {
            let end = ends_at(phase).expect("a fading phase ends");
            assert!(end > 100.0, "{phase:?} ends at {end}");
            assert_eq!(phase_at(phase, end - 0.01), phase, "{phase:?}");
            assert_ne!(phase_at(phase, end + 1e-6), phase, "{phase:?}");
        }
        assert_eq!(ends_at(Phase::Steady), None);
        assert_eq!(ends_at(Phase::Gone), None);
    }

    #[test]
    fn progress_runs_from_the_phase_start_to_its_end() {
        let c = config();
        let (f, d) = (c.formation_s as f64, c.dissipation_s as f64);
        let forming = Phase::forming(100.0, &c);
        assert_eq!(progress(forming, 100.0), 0.0);
        assert_eq!(progress(forming, 100.0 + 0.25 * f), 0.25);
        assert_eq!(progress(forming, 100.0 + 2.0 * f), 1.0);
        let dissipating = Phase::dissipating(100.0, &c);
        assert_eq!(progress(dissipating, 100.0 + 0.5 * d), 0.5);
        assert_eq!(progress(Phase::Steady, 0.0), 1.0);
        assert_eq!(progress(Phase::Gone, 0.0), 1.0);
        // Each phase by its own span, whatever the lifecycle's.
        let quick = Phase::Dissipating {
            since_s: 100.0,
            over_s: 40.0,
        };
        assert_eq!(progress(quick, 110.0), 0.25);
    }

    #[test]
    fn dissipation_is_monotonic_complete_outer_first_and_edges_faster() {
        let c = config();
        for rf in FRACTIONS {
            let mut last = 1.0;
            assert_eq!(dissipation_alpha(0.0, rf, &c), 1.0);
            for k in 0..=200 {
                let a = dissipation_alpha(k as f32 / 200.0, rf, &c);
                assert!(a <= last && (0.0..=1.0).contains(&a), "rf {rf} step {k}");
                last = a;
            }
            assert_eq!(last, 0.0, "rf {rf} does not finish");
        }
        let mut fading = 0;
        for k in 0..=200 {
            let q = k as f32 / 200.0;
            // Inner sprites only start once the outer ones are gone.
            if dissipation_alpha(q, 0.2, &c) < 1.0 {
                assert_eq!(dissipation_alpha(q, 0.9, &c), 0.0);
            }
            // Nearer the edge, more transparent: strictly, while the inner sprites fade (before
            // that both are 1, after it both are 0). Fails without the `edge` term.
            let (outer, inner) = (dissipation_alpha(q, 0.4, &c), dissipation_alpha(q, 0.1, &c));
            if inner > 0.0 && inner < 1.0 {
                assert!(outer < inner, "q {q}: rf 0.4 {outer}, rf 0.1 {inner}");
                fading += 1;
            } else {
                assert_eq!(outer.min(1.0 - outer), 0.0, "q {q}: rf 0.4 {outer}");
            }
        }
        // The inner sprites fade over the last half of the dissipation: about 100 of 200 steps.
        assert!(fading >= 80, "only {fading} steps fade the inner sprites");
        // The ones at the inner radius (inner ones: untouched over the first half) are gone at
        // q = 0.75, the centre at q = 1.
        let at_inner = c.inner_radius_fraction;
        assert_eq!(dissipation_alpha(0.45, at_inner, &c), 1.0);
        assert!(dissipation_alpha(0.74, at_inner, &c) > 0.0);
        assert_eq!(dissipation_alpha(0.75, at_inner, &c), 0.0);
        assert!(dissipation_alpha(0.99, 0.0, &c) > 0.0);
    }
}
