//! The weather over the camera as the sky shows it, eased through a change in time. A new report
//! changes the weather field at once, but its clouds form and the old ones dissipate over
//! minutes (the clouds stage's `[lifecycle]`): the cover's light (how much of the sky the layers
//! overhead hide) and the fog's visibility go over with them, across the formation time, instead
//! of snapping to the new report in one frame (the ground went 13/255 darker in one frame under a
//! broken layer, and 93/255 brighter into the fog of a rain report). Moving through the weather
//! (the field interpolated under the camera) is followed at once: only a change in time eases.

/// What a frame showed of the weather overhead.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Shown {
    /// The fraction of the sky hidden by cloud, 0..=1.
    hidden: f32,
    /// The visibility, metres; eased in density (1 / visibility), so a fog thickening from 40 km
    /// to 2 km does not stay thin until the last moment.
    visibility_m: f32,
}

/// A change in time under way: what was shown when it began, and over how long.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Change {
    from: Shown,
    start_s: f64,
    duration_s: f64,
}

/// The cover and fog a frame shows, going over from the last frame's to the weather's after a
/// change in time ([`Self::begin`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct OverheadEase {
    shown: Option<Shown>,
    change: Option<Change>,
}

impl OverheadEase {
    /// The weather overhead changed in time at `now_s` (sky seconds): from the next frame on the
    /// sky goes over from what it showed last to the new weather across `duration_s`. Before any
    /// frame was shown there is nothing to go from: the first frame shows the weather as it is.
    pub(super) fn begin(&mut self, now_s: f64, duration_s: f64) {
        if let Some(from) = self.shown {
            self.change = Some(Change {
                from,
                start_s: now_s,
                duration_s: duration_s.max(0.0),
            });
        }
    }

    /// This frame's hidden fraction and visibility (metres) at `now_s`, given the weather's
    /// own (`hidden`, `visibility_m`); remembered as what was shown.
    pub(super) fn show(&mut self, hidden: f32, visibility_m: f32, now_s: f64) -> (f32, f32) {
        let target = Shown {
            hidden,
            visibility_m: visibility_m.max(1.0),
        };
        let shown = match self.change {
            Some(c) if c.duration_s > 0.0 && now_s < c.start_s + c.duration_s => {
                let w = ((now_s - c.start_s) / c.duration_s).clamp(0.0, 1.0) as f32;
                let density = |s: Shown| 1.0 / s.visibility_m;
                Shown {
                    hidden: c.from.hidden + (target.hidden - c.from.hidden) * w,
                    visibility_m: 1.0 / (density(c.from) + (density(target) - density(c.from)) * w),
                }
            }
            _ => {
                self.change = None;
                target
            }
        };
        self.shown = Some(shown);
        (shown.hidden, shown.visibility_m)
    }

    /// The visibility the last frame showed, metres (`None` before the first).
    pub(super) fn visibility_m(&self) -> Option<f32> {
        self.shown.map(|s| s.visibility_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_change_in_time_the_weather_shows_as_it_is() {
        let mut ease = OverheadEase::default();
        // The first frame has nothing to go over from, even if a change was announced.
        ease.begin(0.0, 600.0);
        assert_eq!(ease.show(0.8, 2_000.0, 0.0), (0.8, 2_000.0));
        // Moving through the weather: followed at once.
        assert_eq!(ease.show(0.3, 40_000.0, 0.1), (0.3, 40_000.0));
        assert_eq!(ease.visibility_m(), Some(40_000.0));
    }

    #[test]
    fn a_change_in_time_goes_over_across_its_duration() {
        let mut ease = OverheadEase::default();
        ease.show(0.0, 40_000.0, 10.0);
        ease.begin(10.0, 600.0);
        // A quarter of the way: a quarter of the cover, a quarter of the fog's density.
        let (hidden, visibility) = ease.show(1.0, 2_000.0, 160.0);
        assert!((hidden - 0.25).abs() < 1e-6, "{hidden}");
        let density = 0.75 / 40_000.0 + 0.25 / 2_000.0;
        assert!((visibility - 1.0 / density).abs() < 1.0, "{visibility}");
        // The weather overhead may move meanwhile: the eased value follows it.
        let (hidden, _) = ease.show(0.6, 2_000.0, 310.0);
        assert!((hidden - 0.3).abs() < 1e-6, "{hidden}");
        // Over: the weather as it is, and the change forgotten.
        assert_eq!(ease.show(1.0, 2_000.0, 610.0), (1.0, 2_000.0));
        assert_eq!(ease.show(0.5, 9_000.0, 611.0), (0.5, 9_000.0));
    }

    #[test]
    fn a_change_during_a_change_starts_from_what_shows() {
        let mut ease = OverheadEase::default();
        ease.show(0.0, 40_000.0, 0.0);
        ease.begin(0.0, 100.0);
        let (half, _) = ease.show(1.0, 40_000.0, 50.0);
        assert!((half - 0.5).abs() < 1e-6);
        // Cleared again half-way: from 0.5 back down, no jump.
        ease.begin(50.0, 100.0);
        let (next, _) = ease.show(0.0, 40_000.0, 51.0);
        assert!((next - 0.495).abs() < 1e-6, "{next}");
    }
}
