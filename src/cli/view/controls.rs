//! The viewer's keys and the aircraft they fly: plain state, no window, so the script mode and
//! the tests drive it the same way as a keyboard. Units: metres, seconds, degrees.

use std::collections::HashSet;

use glam::DVec3;

/// A key the viewer knows, by the name `--help` and scripts use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Key {
    /// Faster (held).
    W,
    /// Slower (held).
    S,
    /// Turn left (held).
    A,
    /// Turn right (held).
    D,
    /// Descend (held).
    Q,
    /// Climb (held).
    E,
    /// Climb (held).
    PageUp,
    /// Descend (held).
    PageDown,
    /// Every rate ten times faster (held).
    Shift,
    /// The time of day 30 minutes later.
    Plus,
    /// The time of day 30 minutes earlier.
    Minus,
    /// Cloud close-up speed.
    Slow,
    /// Cross-country speed.
    Fast,
    /// Stop in the air.
    Stop,
    /// The vertex cache on or off.
    V,
    /// The far-cloud impostor ring on or off.
    I,
    /// PNG screenshot of the current frame.
    F12,
    /// The keys on screen, or not.
    H,
    /// Quit.
    Escape,
}

/// Every key with its name and what it does, in the order `--help` lists them.
pub const KEYS: [(Key, &str, &str); 19] = [
    (Key::W, "W", "faster (hold)"),
    (Key::S, "S", "slower (hold)"),
    (Key::A, "A", "turn left (hold)"),
    (Key::D, "D", "turn right (hold)"),
    (Key::E, "E", "climb (hold)"),
    (Key::Q, "Q", "descend (hold)"),
    (Key::PageUp, "PageUp", "climb (hold)"),
    (Key::PageDown, "PageDown", "descend (hold)"),
    (Key::Shift, "Shift", "every rate ten times faster (hold)"),
    (Key::Plus, "Plus", "time of day +30 minutes (+ or keypad +)"),
    (
        Key::Minus,
        "Minus",
        "time of day -30 minutes (- or keypad -)",
    ),
    (Key::Slow, "1", "cloud close-up speed, 20 m/s"),
    (
        Key::Fast,
        "2",
        "cross-country speed, 600 m/s (100 km in under 3 minutes)",
    ),
    (Key::Stop, "0", "stop in the air"),
    (
        Key::V,
        "V",
        "vertex cache on/off (off: every cloud recomputed every frame)",
    ),
    (
        Key::I,
        "I",
        "impostor ring on/off (off: every block drawn as sprites)",
    ),
    (
        Key::F12,
        "F12",
        "PNG screenshot of the current frame (skycast-view-N.png)",
    ),
    (Key::H, "H", "show or hide these keys"),
    (Key::Escape, "Escape", "quit"),
];

/// The keys as `--help` and the overlay (H) list them.
pub const KEYS_HELP: &str = "\
Keys (mouse: drag with the left button to look around):
  W / S              faster / slower (hold)
  A / D              turn left / right (hold)
  E / Q, PageUp / PageDown   climb / descend (hold)
  Shift              every rate ten times faster (hold)
  1 / 2 / 0          cloud close-up speed (20 m/s) / cross-country (600 m/s) / stop
  + / -              time of day +30 / -30 minutes
  V                  vertex cache on / off (off: every cloud recomputed every frame)
  I                  impostor ring on / off (off: every block drawn as sprites)
  F12                PNG screenshot of the current frame (skycast-view-N.png)
  H                  show or hide these keys
  Escape             quit";

impl Key {
    /// The key a script names (the names of [`KEYS`], case-insensitive).
    pub fn from_name(name: &str) -> Option<Self> {
        KEYS.iter()
            .find(|(_, n, _)| n.eq_ignore_ascii_case(name))
            .map(|(k, _, _)| *k)
    }
}

/// Time of day moved by one press of Plus or Minus, seconds.
pub const TIME_STEP_S: f64 = 30.0 * 60.0;
/// Cloud close-up speed, metres per second.
pub const SLOW_MPS: f64 = 20.0;
/// Cross-country speed, metres per second.
pub const FAST_MPS: f64 = 600.0;
/// Speed change while W or S is held, metres per second per second.
const ACCEL_MPS2: f64 = 40.0;
/// Turn rate while A or D is held, degrees per second.
const TURN_DEG_S: f64 = 30.0;
/// Climb rate while E or Q is held, metres per second.
const CLIMB_MPS: f64 = 15.0;
/// What Shift multiplies every rate by.
const BOOST: f64 = 10.0;
/// Lowest eye height over the ground, metres.
const MIN_AGL_M: f64 = 2.0;
/// Degrees of look per pixel of mouse drag.
pub const LOOK_DEG_PER_PX: f64 = 0.15;

/// The camera the viewer flies: a position in the sky's local frame, where it looks, how fast
/// it goes (level, along its heading; climbs and descents on their own keys).
#[derive(Debug, Clone, PartialEq)]
pub struct Aircraft {
    /// Metres east, north and above mean sea level of the local frame's origin.
    pub position_m: DVec3,
    /// Degrees clockwise from true north.
    pub heading_deg: f64,
    /// Degrees above the horizon.
    pub pitch_deg: f64,
    /// Forward speed, metres per second.
    pub speed_mps: f64,
}

impl Aircraft {
    /// Applies a one-shot key (speeds); the rest are the window's business.
    pub fn press(&mut self, key: Key) {
        match key {
            Key::Slow => self.speed_mps = SLOW_MPS,
            Key::Fast => self.speed_mps = FAST_MPS,
            Key::Stop => self.speed_mps = 0.0,
            _ => {}
        }
    }

    /// Turns the view by a mouse drag of `dx_px`, `dy_px` pixels (pitch kept within +-89).
    pub fn look(&mut self, dx_px: f64, dy_px: f64) {
        self.heading_deg = (self.heading_deg + dx_px * LOOK_DEG_PER_PX).rem_euclid(360.0);
        self.pitch_deg = (self.pitch_deg - dy_px * LOOK_DEG_PER_PX).clamp(-89.0, 89.0);
    }

    /// Flies `dt_s` seconds with `held` keys down, kept `MIN_AGL_M` over `ground_m`.
    pub fn advance(&mut self, held: &HashSet<Key>, dt_s: f64, ground_m: impl Fn(DVec3) -> f64) {
        let down = |k| held.contains(&k);
        let axis = |plus: bool, minus: bool| (plus as i32 - minus as i32) as f64;
        let boost = if down(Key::Shift) { BOOST } else { 1.0 };
        let accel = axis(down(Key::W), down(Key::S));
        self.speed_mps = (self.speed_mps + accel * ACCEL_MPS2 * boost * dt_s).max(0.0);
        let turn = axis(down(Key::D), down(Key::A));
        self.heading_deg = (self.heading_deg + turn * TURN_DEG_S * boost * dt_s).rem_euclid(360.0);
        let climb = axis(
            down(Key::E) || down(Key::PageUp),
            down(Key::Q) || down(Key::PageDown),
        );
        let heading = self.heading_deg.to_radians();
        let forward = DVec3::new(heading.sin(), heading.cos(), 0.0);
        self.position_m += forward * self.speed_mps * dt_s;
        self.position_m.z += climb * CLIMB_MPS * boost * dt_s;
        self.position_m.z = self.position_m.z.max(ground_m(self.position_m) + MIN_AGL_M);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aircraft() -> Aircraft {
        Aircraft {
            position_m: DVec3::new(0.0, 0.0, 1000.0),
            heading_deg: 90.0,
            pitch_deg: 0.0,
            speed_mps: 100.0,
        }
    }

    #[test]
    fn flies_along_its_heading_and_climbs_on_e() {
        let mut a = aircraft();
        a.advance(&HashSet::from([Key::E]), 2.0, |_| 0.0);
        assert!((a.position_m.x - 200.0).abs() < 1e-9, "{a:?}");
        assert!(a.position_m.y.abs() < 1e-9);
        assert_eq!(a.position_m.z, 1030.0);
    }

    #[test]
    fn shift_multiplies_turns_and_the_ground_stops_a_descent() {
        let mut a = aircraft();
        a.advance(
            &HashSet::from([Key::D, Key::Shift, Key::PageDown]),
            1.0,
            |_| 900.0,
        );
        // 90 + 300 degrees, wrapped.
        assert!((a.heading_deg - 30.0).abs() < 1e-9, "{a:?}");
        assert_eq!(a.position_m.z, 902.0);
    }

    #[test]
    fn script_names_find_their_keys_in_any_case() {
        assert_eq!(Key::from_name("pageup"), Some(Key::PageUp));
        assert_eq!(Key::from_name("plus"), Some(Key::Plus));
        assert_eq!(Key::from_name("2"), Some(Key::Fast));
        assert_eq!(Key::from_name("Ctrl"), None);
    }
}
