//! The sky's passes into the host's encoder ([`Sky::record`], [`Sky::record_view`]): the
//! sky background and sun, the ring, the distant and the near sprites (off-screen below full
//! resolution, then composited), the far field and the in-cloud fog. Encodes only; what they
//! read was written by the frame's prepare.

use super::Sky;
use crate::render::RenderError;
use crate::render::cloud_target::can_test_against;
use crate::render::pass_timing::Stamp;
use crate::render::pipeline::frame_group;
use crate::render::sprites::build::chunks;
use crate::render::stats::Stopwatch;
use crate::render::view::ViewId;

impl Sky {
    /// Records the sky's passes into the host's encoder: sky background, then the ring, sprites
    /// and in-cloud fog, straight into the host's colour or, below full resolution, into the
    /// sky's cloud target composited over it (`cloud_target`; it follows the host's frame size).
    /// `depth_view` is the host's depth (the format of [`HostTargets::depth_format`], with
    /// `TEXTURE_BINDING`), only read.
    ///
    /// Before anything is recorded the host's textures are checked against the targets the sky
    /// was made for, and the last prepared projection against their depth convention
    /// ([`HostTargets::check_textures`], [`HostTargets::check_projection`]): a mismatch is
    /// [`RenderError::Targets`] naming both sides, and nothing is recorded.
    ///
    /// [`HostTargets::depth_format`]: crate::render::HostTargets::depth_format
    /// [`HostTargets::check_textures`]: crate::render::HostTargets::check_textures
    /// [`HostTargets::check_projection`]: crate::render::HostTargets::check_projection
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        self.record_view(ViewId::MAIN, encoder, colour_view, depth_view)
    }

    /// [`Self::record`] for one view, with that view's targets (the same formats and samples;
    /// any size). Several views record into one encoder, each drawing its own prepared frame.
    /// An unknown view is an error.
    pub fn record_view(
        &self,
        id: ViewId,
        encoder: &mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        depth_view: &wgpu::TextureView,
    ) -> Result<(), RenderError> {
        let v = self.views.get(id.0).ok_or_else(|| {
            RenderError::Targets(format!(
                "view {} does not exist (the sky has {})",
                id.0,
                self.views.len()
            ))
        })?;
        let start = Stopwatch::start();
        self.targets
            .check_textures(colour_view.texture(), depth_view.texture())?;
        if let Some(projection) = v.projection {
            self.targets.check_projection(projection)?;
        }
        let frame_group = {
            let mut kept = v.frame_group.borrow_mut();
            match kept.as_ref().filter(|(depth, _)| depth == depth_view) {
                Some((_, group)) => group.clone(),
                None => {
                    let group = frame_group(
                        &self.device,
                        "sky.frame_group",
                        &self.frame_layout,
                        &v.frame_buffer,
                        depth_view,
                    );
                    *kept = Some((depth_view.clone(), group.clone()));
                    group
                }
            }
        };
        // The patch of changed orders, then the sky, the ring, the sprites a chunk at a time
        // (the first built before the sky, each later one just before it is drawn; one pass
        // when they fit one chunk), the in-cloud fog.
        let timer = self.pass_timer.as_ref();
        let stamp = |encoder: &mut wgpu::CommandEncoder, at: Stamp| {
            if let Some(timer) = timer {
                timer.write(encoder, at as u32);
            }
        };
        stamp(encoder, Stamp::Start);
        self.sprites.scatter.record(encoder);
        // The impostors this view's frame (and any frames prepared since its last recorded
        // one) rebuilt: in the host's submission, never in one of the sky's own, which could
        // hold the host's frame thread while the device is busy.
        v.ring.record_builds(
            encoder,
            &self.sheet_group,
            &self.sprites.build,
            &self.sprites.resident.group,
            &self.sprites.quads.0,
        );
        let view_group = v.view.group().filter(|_| v.sprites_to_draw > 0);
        let parts: Vec<(u32, u32, u32)> = view_group
            .map(|_| chunks(v.sprites_to_draw).collect())
            .unwrap_or_default();
        // The first chunk is built here, before the background, the far field and the ring
        // (none of which reads the corners): with one chunk the distant cells drawn behind the
        // ring need it, and with several the timed build holds a chunk's build either way, not
        // nothing (the later chunks are built between their draws, in the sprites' time).
        if let (Some(&(c, _, n)), Some(group)) = (parts.first(), view_group) {
            self.sprites.record_build(encoder, group, (c, n));
        }
        // Below full resolution the clouds go to the cloud target, composited at the end with
        // the sky background; at full resolution they are drawn over the sky in the host's colour.
        stamp(encoder, Stamp::Build);
        let offscreen = v.clouds.frame(&self.device, &v.frame_buffer, depth_view);
        let mut pass = match &offscreen {
            Some(target) => {
                target.downsample(encoder, &frame_group);
                stamp(encoder, Stamp::Background);
                target.pass(encoder, true)
            }
            None => {
                let tested = self
                    .sky_tested_pipeline
                    .as_ref()
                    .filter(|_| can_test_against(depth_view));
                if let Some(tested) = tested {
                    // The background in a pass of its own, the host's depth attached.
                    let mut pass =
                        self.sky_pass(encoder, colour_view, &frame_group, Some(depth_view));
                    pass.set_pipeline(tested);
                    pass.draw(0..3, 0..1);
                }
                let mut pass = self.sky_pass(encoder, colour_view, &frame_group, None);
                if tested.is_none() {
                    pass.set_pipeline(&self.sky_pipeline);
                    pass.draw(0..3, 0..1);
                }
                if timer.is_some() {
                    drop(pass);
                    stamp(encoder, Stamp::Background);
                    pass = self.sky_pass(encoder, colour_view, &frame_group, None);
                }
                pass
            }
        };
        let (sprite_pipeline, in_cloud_pipeline) = match &offscreen {
            Some(target) => (target.sprite_pipeline(), target.in_cloud_pipeline()),
            None => self.sprites.pipelines(),
        };
        // The far field behind the distant cells, they behind the ring, it behind the sprites
        // (blended over, back to front). The distant cells' sprites come first in the draw
        // list; split off when the frame's sprites are built in one part (with more, they are
        // drawn with the others, over the ring).
        self.far_field.draw(&mut pass, offscreen.is_some());
        if timer.is_some() {
            drop(pass);
            stamp(encoder, Stamp::FarField);
            pass = self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
        }
        let distant = if parts.len() == 1 {
            v.distant_sprites.min(v.sprites_to_draw)
        } else {
            0
        };
        if distant > 0 {
            self.sprites
                .draw(&mut pass, (sprite_pipeline, &self.sheet_group), 0..distant);
        }
        let size = offscreen.as_ref().map_or_else(
            || {
                (
                    colour_view.texture().width(),
                    colour_view.texture().height(),
                )
            },
            |target| target.size(),
        );
        v.ring.draw(&mut pass, offscreen.is_some(), size);
        if timer.is_some() {
            drop(pass);
            stamp(encoder, Stamp::Ring);
            pass = self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
        }
        for (i, &(c, _, n)) in parts.iter().enumerate() {
            if i > 0 {
                drop(pass);
                if let Some(group) = view_group {
                    self.sprites.record_build(encoder, group, (c, n));
                }
                pass =
                    self.clouds_pass_again(encoder, offscreen.as_ref(), colour_view, &frame_group);
            }
            self.sprites.draw(
                &mut pass,
                (sprite_pipeline, &self.sheet_group),
                distant.min(n)..n,
            );
        }
        if v.in_cloud > 0.0 {
            pass.set_pipeline(in_cloud_pipeline);
            pass.draw(0..3, 0..1);
        }
        drop(pass);
        stamp(encoder, Stamp::Sprites);
        if let Some(target) = &offscreen {
            target.composite(encoder, colour_view, depth_view, &frame_group);
        }
        stamp(encoder, Stamp::Composite);
        if let Some(timer) = timer {
            timer.resolve(encoder);
        }
        v.recorded.set(true);
        v.record.set(start.spent());
        Ok(())
    }

    /// The clouds' pass taken up again after a break between passes (a timestamp while timing,
    /// a chunk's corner build): into the cloud target below full resolution, else over the
    /// host's colour, nothing cleared.
    fn clouds_pass_again<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        offscreen: Option<&crate::render::cloud_target::CloudFrame<'_>>,
        colour_view: &wgpu::TextureView,
        frame_group: &wgpu::BindGroup,
    ) -> wgpu::RenderPass<'e> {
        match offscreen {
            Some(target) => target.pass(encoder, false),
            None => self.sky_pass(encoder, colour_view, frame_group, None),
        }
    }

    /// A pass over the host's colour (kept), with the frame's group 0 bound, and the host's
    /// depth as a read-only attachment when `depth` is given.
    fn sky_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        colour_view: &wgpu::TextureView,
        frame_group: &wgpu::BindGroup,
        depth: Option<&wgpu::TextureView>,
    ) -> wgpu::RenderPass<'e> {
        let mut pass = crate::render::cloud_target::begin_with_depth(
            encoder,
            "sky",
            &[colour_view],
            wgpu::LoadOp::Load,
            depth,
        );
        pass.set_bind_group(0, frame_group, &[]);
        pass
    }
}
