//! The viewer's window: a winit window, its wgpu surface, the demo host drawing the frame
//! off-screen on a device that can present there, and the present pass that shows the frame
//! with the overlay over it.

use std::sync::Arc;

use anyhow::Context;
use skycast::demo::{DemoHost, HeadlessGpu};
use skycast::flight::Weather;
use winit::event_loop::ActiveEventLoop;
use winit::window::Window;

use super::app::Setup;
use super::overlay::{self, OverlayImage};
use super::present::PresentPass;

/// The window, its surface and the demo host drawing into it.
pub struct Running {
    pub window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    pub surface_config: wgpu::SurfaceConfiguration,
    surface_view_format: wgpu::TextureFormat,
    present: PresentPass,
    pub host: DemoHost,
    pub overlay: OverlayImage,
    overlay_view: wgpu::TextureView,
    present_group: wgpu::BindGroup,
}

impl Running {
    /// Makes the window, surface, device, ground and sky (the weather of `setup` moves in).
    pub fn open(event_loop: &ActiveEventLoop, setup: &mut Setup) -> anyhow::Result<Self> {
        let (width, height) = setup.size;
        let attributes = Window::default_attributes()
            .with_title("skycast view")
            .with_inner_size(winit::dpi::PhysicalSize::new(width, height));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .context("cannot open a window")?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let surface = instance
            .create_surface(Arc::clone(&window))
            .context("cannot draw into the window (no surface)")?;
        let gpu = HeadlessGpu::with_instance(&instance, Some(&surface))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        let format = *caps
            .formats
            .first()
            .context("the adapter cannot present to this window")?;
        // The present pass writes linear colour through an sRGB view, whatever the surface's
        // own format, so the hardware encodes it as `render`'s PNG is encoded.
        let surface_view_format = format.add_srgb_suffix();
        let size = window.inner_size();
        let surface_config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: if setup.vsync {
                wgpu::PresentMode::AutoVsync
            } else {
                wgpu::PresentMode::AutoNoVsync
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: wgpu::CompositeAlphaMode::Auto,
            view_formats: vec![surface_view_format],
        };
        surface.configure(&gpu.device, &surface_config);
        let present = PresentPass::new(&gpu.device, surface_view_format);
        let mut host = DemoHost::with_gpu(
            gpu,
            surface_config.width,
            surface_config.height,
            &setup.ground,
            setup.config.clone(),
        )?;
        if let Some(field) = setup.field.take() {
            host.sky.set_weather_field(field);
        }
        if let Some((path, settle)) = &setup.watch {
            // A `--model` stays under the watched reports.
            let model = host.sky.world().field().model().map(|(m, _)| m.clone());
            if model.is_some() {
                host.sky.set_model(model);
            }
            host.sky.set_weather(Weather::Watch {
                path,
                settle: *settle,
            })?;
            eprintln!("watching {}", path.display());
        }
        let overlay = OverlayImage::from_lines(&[]);
        let overlay_view = overlay::upload(&host.gpu.device, &host.gpu.queue, &overlay);
        let present_group = present.bind(&host.gpu.device, &host.target.colour_view, &overlay_view);
        Ok(Self {
            window,
            surface,
            surface_config,
            surface_view_format,
            present,
            host,
            overlay,
            overlay_view,
            present_group,
        })
    }

    /// Shows `overlay` from the next present on.
    pub fn set_overlay(&mut self, overlay: OverlayImage) {
        self.overlay_view = overlay::upload(&self.host.gpu.device, &self.host.gpu.queue, &overlay);
        self.overlay = overlay;
        self.rebind();
    }

    /// Copies the drawn frame onto the surface and presents it; false when the surface had no
    /// texture to give this time (resized, occluded), which the next frame retries.
    pub fn present_frame(&mut self) -> anyhow::Result<bool> {
        let texture = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface
                    .configure(&self.host.gpu.device, &self.surface_config);
                return Ok(false);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                anyhow::bail!("the window's surface rejected the frame (a wgpu validation error)")
            }
        };
        let view = texture.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.surface_view_format),
            ..Default::default()
        });
        let device = &self.host.gpu.device;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("view.present"),
        });
        self.present
            .record(&mut encoder, &self.present_group, &view);
        self.host.gpu.queue.submit([encoder.finish()]);
        self.window.pre_present_notify();
        self.host.gpu.queue.present(texture);
        Ok(true)
    }

    /// The window's new size: the surface and the off-screen frame follow.
    pub fn resize(&mut self, width: u32, height: u32) -> anyhow::Result<()> {
        // Minimised (0) or unchanged (the first event of a new window): nothing to rebuild.
        let unchanged = (width, height) == (self.surface_config.width, self.surface_config.height);
        if width == 0 || height == 0 || unchanged {
            return Ok(());
        }
        self.surface_config.width = width;
        self.surface_config.height = height;
        self.surface
            .configure(&self.host.gpu.device, &self.surface_config);
        self.host.resize(width, height)?;
        self.rebind();
        Ok(())
    }

    /// The present pass's inputs changed (the frame's target or the overlay).
    fn rebind(&mut self) {
        self.present_group = self.present.bind(
            &self.host.gpu.device,
            &self.host.target.colour_view,
            &self.overlay_view,
        );
    }
}
