//! The window and its frame loop (winit 0.30's `ApplicationHandler`): the window, surface and
//! device made when the event loop resumes, then each redraw flies the aircraft, runs the demo
//! host's frame step (the sky's `update`, ground, sky) and presents.

use std::collections::HashSet;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use skycast::demo::HeightField;
use skycast::flight::SkySystemConfig;
use skycast::render::FrameStats;
use skycast::weather::{METRES_PER_FOOT, WeatherField};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::WindowId;

use super::controls::{Aircraft, KEYS_HELP, Key, TIME_STEP_S};
use super::figures::Figures;
use super::overlay::OverlayImage;
use super::script::Script;
use super::window::Running;

/// Metres per second in a knot.
const KNOT_MPS: f64 = 0.514_444;

/// Everything the viewer is started with (flags loaded and checked).
pub struct Setup {
    /// Window size, pixels.
    pub size: (u32, u32),
    /// Present at the display's refresh.
    pub vsync: bool,
    /// Quit after this many presented frames.
    pub frames: Option<u64>,
    /// Frames to write as PNG.
    pub screenshots: Vec<(u64, PathBuf)>,
    /// Scripted key presses and mouse drags.
    pub script: Script,
    /// UTC time of the first frame, Unix seconds.
    pub start_unix_s: f64,
    /// Where the flight starts.
    pub aircraft: Aircraft,
    /// The demo ground.
    pub ground: HeightField,
    /// The sky's settings.
    pub config: SkySystemConfig,
    /// The weather at the start (moves into the sky when the window opens).
    pub field: Option<WeatherField>,
    /// The weather file to watch and its settle time.
    pub watch: Option<(PathBuf, Duration)>,
}

/// The viewer: the setup, then the running window; the first error ends the loop.
pub struct Viewer {
    setup: Setup,
    running: Option<Running>,
    error: Option<anyhow::Error>,
    held: HashSet<Key>,
    dragging: Option<(f64, f64)>,
    frame: u64,
    last_frame: Option<Instant>,
    clock_s: f64,
    time_offset_s: f64,
    frame_ms: Vec<f64>,
    overlay_at: Option<Instant>,
    fps: f64,
    show_keys: bool,
    screenshot_requested: bool,
    screenshots_taken: u32,
}

impl Viewer {
    /// A viewer that opens its window when the event loop starts.
    pub fn new(setup: Setup) -> Self {
        Self {
            setup,
            running: None,
            error: None,
            held: HashSet::new(),
            dragging: None,
            frame: 0,
            last_frame: None,
            clock_s: 0.0,
            time_offset_s: 0.0,
            frame_ms: Vec::new(),
            overlay_at: None,
            fps: 0.0,
            show_keys: false,
            screenshot_requested: false,
            screenshots_taken: 0,
        }
    }

    /// After the loop: the error that ended it, or the frame rate on standard output.
    pub fn finish(mut self) -> anyhow::Result<()> {
        if let Some(err) = self.error.take() {
            return Err(err);
        }
        // The first frame compiles the shaders and builds the clouds: left out of the rate.
        let mut times: Vec<f64> = self.frame_ms.iter().skip(1).copied().collect();
        times.sort_by(f64::total_cmp);
        if let (Some(running), false) = (&self.running, times.is_empty()) {
            let median_ms = times[times.len() / 2];
            let (w, h) = (running.surface_config.width, running.surface_config.height);
            println!(
                "{} frames presented at {w}x{h} on {} ({:?}); median frame {median_ms:.1} ms, {:.1} fps",
                self.frame,
                running.host.gpu.adapter_info.name,
                running.host.gpu.adapter_info.backend,
                1000.0 / median_ms,
            );
        }
        Ok(())
    }

    /// A key went down (`pressed`) or up, from the keyboard or the script.
    fn key(&mut self, key: Key, pressed: bool, event_loop: &ActiveEventLoop) {
        if !pressed {
            self.held.remove(&key);
            return;
        }
        self.held.insert(key);
        match key {
            Key::Plus => self.time_offset_s += TIME_STEP_S,
            Key::Minus => self.time_offset_s -= TIME_STEP_S,
            Key::F12 => self.screenshot_requested = true,
            Key::I => {
                if let Some(running) = self.running.as_mut() {
                    let enabled = running.host.sky.settings().impostors.enabled;
                    if !running.host.sky.sky_mut().set_impostors(!enabled) {
                        eprintln!(
                            "the impostor ring cannot be turned on: the render settings say impostors.enabled = false"
                        );
                    }
                }
            }
            Key::V => {
                if let Some(running) = self.running.as_mut() {
                    let enabled = running.host.sky.settings().vertex_cache.enabled;
                    running.host.sky.sky_mut().set_vertex_cache(!enabled);
                }
            }
            Key::H => {
                self.show_keys = !self.show_keys;
                self.overlay_at = None;
            }
            Key::Escape => event_loop.exit(),
            _ => self.setup.aircraft.press(key),
        }
    }

    /// The scripted presses, releases and drags of this frame.
    fn run_script(&mut self, event_loop: &ActiveEventLoop) {
        let frame = self.frame;
        for look in self.setup.script.looks.iter().filter(|l| l.frame == frame) {
            self.setup.aircraft.look(look.dx_px, look.dy_px);
        }
        let events: Vec<(Key, bool)> = self
            .setup
            .script
            .presses
            .iter()
            .filter_map(|p| {
                if p.from == frame {
                    Some((p.key, true))
                } else if p.until == frame {
                    Some((p.key, false))
                } else {
                    None
                }
            })
            .collect();
        for (key, pressed) in events {
            self.key(key, pressed, event_loop);
        }
    }

    /// The overlay's figures of this frame.
    fn figures(
        setup: &Setup,
        fps: f64,
        running: &Running,
        stats: &FrameStats,
        utc_unix_s: f64,
    ) -> Figures {
        let a = &setup.aircraft;
        let (lat_deg, lon_deg) = running
            .host
            .sky
            .frame()
            .to_lat_lon_deg(a.position_m.truncate());
        let ground_m = setup.ground.height_at_m(a.position_m.truncate());
        Figures {
            lat_deg,
            lon_deg,
            msl_ft: a.position_m.z / METRES_PER_FOOT,
            agl_ft: (a.position_m.z - ground_m) / METRES_PER_FOOT,
            heading_deg: a.heading_deg,
            pitch_deg: a.pitch_deg,
            speed_kt: a.speed_mps / KNOT_MPS,
            utc_unix_s,
            fps,
            sky_cpu_ms: stats.sky_cpu_us() as f64 / 1000.0,
            gpu_ms: running.host.last_gpu_ms(),
            sprites: stats.sprites_drawn,
            clouds: stats.clouds_drawn,
            impostor_blocks: stats.blocks_far,
            vertex_cache: running.host.sky.settings().vertex_cache.enabled,
            impostors: running.host.sky.settings().impostors.enabled,
            weather: running.host.sky.world().weather_over(a.position_m),
        }
    }

    /// One frame: fly, step the sky, draw, screenshot, present.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        self.run_script(event_loop);
        let now = Instant::now();
        // The first frame is the start pose, as `render` draws it (dt 0). The flight and the
        // clouds step at most a quarter second a frame (a stall is not a jump); the frame rate
        // counts the real interval.
        let interval_s = self
            .last_frame
            .map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        let dt_s = interval_s.min(0.25);
        self.last_frame = Some(now);
        let Some(running) = self.running.as_mut() else {
            return Ok(());
        };
        let ground = &self.setup.ground;
        self.setup
            .aircraft
            .advance(&self.held, dt_s, |p| ground.height_at_m(p.truncate()));
        self.clock_s += dt_s;
        let a = &self.setup.aircraft;
        let camera = running
            .host
            .camera(a.position_m, a.heading_deg, a.pitch_deg);
        let utc_unix_s = self.setup.start_unix_s + self.clock_s + self.time_offset_s;
        // The first frame is the warm-up, as in `render`: it waits for the clouds around.
        // After it no frame waits: blocks arrive as they are generated.
        let first = self.frame == 0;
        running.host.sky.world_mut().set_synchronous_clouds(first);
        let (stats, changes) = running.host.step(&camera, utc_unix_s, dt_s, true)?;
        for change in changes {
            match change {
                Ok(path) => eprintln!("weather applied: {}", path.display()),
                Err(why) => eprintln!("weather rejected, the last good sky stays: {why}"),
            }
        }
        if interval_s > 0.0 {
            // Smoothed over about ten frames, from the first measured one.
            let weight = if self.fps == 0.0 { 1.0 } else { 0.1 };
            self.fps += weight * (1.0 / interval_s - self.fps);
        }
        // The figures four times a second (the GPU time waits for the frame), the keys on H.
        if self
            .overlay_at
            .is_none_or(|t| t.elapsed() > Duration::from_millis(250))
        {
            self.overlay_at = Some(Instant::now());
            let mut lines =
                Self::figures(&self.setup, self.fps, running, &stats, utc_unix_s).lines();
            if self.show_keys {
                lines.extend(KEYS_HELP.lines().map(str::to_string));
            }
            running.set_overlay(OverlayImage::from_lines(&lines));
        }
        let shots: Vec<PathBuf> = self
            .setup
            .screenshots
            .iter()
            .filter(|(k, _)| *k == self.frame)
            .map(|(_, p)| p.clone())
            .collect();
        if !shots.is_empty() {
            // The sky's frame as `render` writes it, no overlay (what tests compare).
            let frame = running.host.target.read_back(&running.host.gpu)?;
            for path in shots {
                frame.write_png(&path)?;
                eprintln!("screenshot: {}", path.display());
            }
        }
        if std::mem::take(&mut self.screenshot_requested) {
            // What the window shows, overlay included.
            // The first free name: screenshots of earlier runs stay.
            let path = loop {
                self.screenshots_taken += 1;
                let path = PathBuf::from(format!("skycast-view-{}.png", self.screenshots_taken));
                if !path.exists() {
                    break path;
                }
            };
            let mut frame = running.host.target.read_back(&running.host.gpu)?;
            running.overlay.composite(&mut frame);
            frame.write_png(&path)?;
            eprintln!("screenshot: {}", path.display());
        }
        let presented = running.present_frame()?;
        if presented {
            self.frame_ms.push(now.elapsed().as_secs_f64() * 1000.0);
            self.frame += 1;
        }
        if self.setup.frames.is_some_and(|n| self.frame >= n) {
            event_loop.exit();
        }
        Ok(())
    }
}

/// The viewer's key for a key of the keyboard.
fn key_for(code: KeyCode) -> Option<Key> {
    Some(match code {
        KeyCode::KeyW => Key::W,
        KeyCode::KeyS => Key::S,
        KeyCode::KeyA => Key::A,
        KeyCode::KeyD => Key::D,
        KeyCode::KeyQ => Key::Q,
        KeyCode::KeyE => Key::E,
        KeyCode::PageUp => Key::PageUp,
        KeyCode::PageDown => Key::PageDown,
        KeyCode::ShiftLeft | KeyCode::ShiftRight => Key::Shift,
        KeyCode::Equal | KeyCode::NumpadAdd => Key::Plus,
        KeyCode::Minus | KeyCode::NumpadSubtract => Key::Minus,
        KeyCode::Digit1 => Key::Slow,
        KeyCode::Digit2 => Key::Fast,
        KeyCode::Digit0 => Key::Stop,
        KeyCode::KeyV => Key::V,
        KeyCode::KeyI => Key::I,
        KeyCode::F12 => Key::F12,
        KeyCode::KeyH => Key::H,
        KeyCode::Escape => Key::Escape,
        _ => return None,
    })
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match Running::open(event_loop, &mut self.setup) {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
            }
            Err(err) => {
                self.error = Some(err);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => self
                .running
                .as_mut()
                .map_or(Ok(()), |r| r.resize(size.width, size.height)),
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent {
                        physical_key: PhysicalKey::Code(code),
                        state,
                        repeat: false,
                        ..
                    },
                ..
            } => {
                if let Some(key) = key_for(code) {
                    self.key(key, state == ElementState::Pressed, event_loop);
                }
                Ok(())
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                // The drag starts at the next cursor position.
                self.dragging = (state == ElementState::Pressed).then_some((f64::NAN, f64::NAN));
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = self.dragging {
                    if x.is_finite() {
                        self.setup.aircraft.look(position.x - x, position.y - y);
                    }
                    self.dragging = Some((position.x, position.y));
                }
                Ok(())
            }
            WindowEvent::RedrawRequested => {
                let result = self.redraw(event_loop);
                if let Some(r) = &self.running {
                    r.window.request_redraw();
                }
                result
            }
            _ => Ok(()),
        };
        if let Err(err) = result {
            self.error = Some(err);
            event_loop.exit();
        }
    }
}
