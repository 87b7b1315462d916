//! Getting frames out of a [`RasterRenderer`]: drawing into its output texture, reading frames
//! back with a wait (whole or in bands of rows) or polled without one ([`PendingFrame`]).

#[cfg(not(target_arch = "wasm32"))]
use std::ops::ControlFlow;

use illum_gpu::readback;
use illum_gpu::{GpuContext, wgpu};
use illum_image::RgbImage32;

use crate::RasterError;
#[cfg(not(target_arch = "wasm32"))]
use crate::frame::MainBand;
use crate::options::Options;
#[cfg(not(target_arch = "wasm32"))]
use crate::pass_times::Frame;
use crate::pass_times::PassTimes;
use crate::renderer::RasterRenderer;

/// Bytes per output pixel (RGBA8), for the frame's readback.
const BYTES_PER_PIXEL: u32 = 4;

impl RasterRenderer {
    /// Renders one frame and reads it back: linear RGB, row 0 at the top, each value one of the
    /// 256 levels k / 255 of the 8-bit output. Waits for the GPU (not on `wasm32`, where a web
    /// page shows [`Self::output_view`] instead).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render(&mut self, options: &Options) -> Result<RgbImage32, RasterError> {
        Ok(self.render_timed(options)?.image)
    }

    /// [`Self::render`] plus the GPU time of each pass.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn render_timed(&mut self, options: &Options) -> Result<Frame, RasterError> {
        let encoder = self.record(options, None)?;
        self.read_frame(encoder)
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// [`Self::render`] for a long render: the main pass in bands of `rows_per_band` rows
    /// (rounded up to a multiple of 64, the tile side of Mesa's llvmpipe, so that no band edge
    /// cuts a tile), each its own submission, waited for before the next; the shadow map and
    /// cube maps are made with the first band. After each band `after_band`, given the rows
    /// done, can show progress, and stop the render by returning [`ControlFlow::Break`], which
    /// returns `Ok(None)`; after the last band (called before the readback, which takes seconds
    /// for a frame of gigabytes) the frame is complete and is returned whatever `after_band`
    /// says. The frame is the one
    /// [`Self::render`] draws, pixel for pixel (`tests/raster/bands.rs`); it has no pass times
    /// (the main pass is timed in pieces).
    pub fn render_in_bands(
        &mut self,
        options: &Options,
        rows_per_band: u32,
        mut after_band: impl FnMut(u32) -> ControlFlow<()>,
    ) -> Result<Option<RgbImage32>, RasterError> {
        let band = rows_per_band.max(1).next_multiple_of(64);
        let mut first_row = 0;
        while first_row < self.height {
            let rows = band.min(self.height - first_row);
            let encoder = self.record(options, Some(MainBand { first_row, rows, width: self.width }))?;
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait_idle("drawing a band of a raster frame")?;
            first_row += rows;
            // After the last band the frame is complete: returned whatever `after_band` says.
            if after_band(first_row).is_break() && first_row < self.height {
                return Ok(None);
            }
        }
        let encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("raster readback") });
        Ok(Some(self.read_frame(encoder)?.image))
    }

    #[cfg(not(target_arch = "wasm32"))]
    /// Copies the output (and the pass times) into the staging buffer, submits `encoder` and
    /// reads the frame back.
    fn read_frame(&mut self, mut encoder: wgpu::CommandEncoder) -> Result<Frame, RasterError> {
        let row = (self.width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let image_bytes = u64::from(row) * u64::from(self.height);
        let staging = self.staging(image_bytes + self.timer.result_size());
        let main = self.main.as_ref().expect("record() made the main targets");
        copy_output(&mut encoder, &main.output, &staging, self.width, self.height, row);
        self.timer.copy_results(&mut encoder, &staging, image_bytes);
        self.gpu.queue.submit([encoder.finish()]);
        let bytes =
            readback::read_mapped(&self.gpu, &staging, staging.size(), "reading back a raster frame")?;
        let (pixels, timestamps) = bytes.split_at(image_bytes as usize);
        let image = decode_frame(self.width, self.height, pixels);
        let pass_times = self.timer.decode(timestamps).map(|named| PassTimes::from_named(&named));
        Ok(Frame { image, pass_times })
    }

    /// Starts reading back the last frame drawn ([`Self::draw`]) without waiting, as a web page
    /// must: [`PendingFrame::poll`], called on later frames, returns the image [`Self::render`]
    /// returns for the same frame. The copy has a staging buffer of its own, so frames drawn
    /// meanwhile neither wait for it nor change it.
    pub fn read_polled(&self) -> Result<PendingFrame, RasterError> {
        let main = self.main.as_ref().ok_or_else(|| {
            RasterError::Unsupported("no raster frame to read back: draw one first".to_owned())
        })?;
        let row = (self.width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let bytes = u64::from(row) * u64::from(self.height);
        let staging = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("raster polled staging"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("raster polled readback"),
        });
        copy_output(&mut encoder, &main.output, &staging, self.width, self.height, row);
        self.gpu.queue.submit([encoder.finish()]);
        Ok(PendingFrame {
            read: readback::PendingRead::start(staging, bytes, "reading back a raster frame"),
            width: self.width,
            height: self.height,
        })
    }

    /// Renders one frame into [`Self::output_view`] without reading it back, waits for the GPU
    /// and returns the pass times (what a benchmark or a viewer needs).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn draw(&mut self, options: &Options) -> Result<Option<PassTimes>, RasterError> {
        let mut encoder = self.record(options, None)?;
        if !self.timer.enabled() {
            self.gpu.queue.submit([encoder.finish()]);
            self.gpu.wait_idle("drawing a raster frame")?;
            return Ok(None);
        }
        let size = self.timer.result_size();
        let staging = self.staging(size);
        self.timer.copy_results(&mut encoder, &staging, 0);
        self.gpu.queue.submit([encoder.finish()]);
        let bytes = readback::read_mapped(&self.gpu, &staging, size, "reading raster pass times")?;
        Ok(self.timer.decode(&bytes).map(|named| PassTimes::from_named(&named)))
    }

    /// Renders one frame into [`Self::output_view`] and submits it, without waiting: in a web
    /// page the browser orders the page's drawing of the output after this submission. No pass
    /// times (reading them back would wait): always `None`.
    #[cfg(target_arch = "wasm32")]
    pub fn draw(&mut self, options: &Options) -> Result<Option<PassTimes>, RasterError> {
        let encoder = self.record(options, None)?;
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.check()?;
        Ok(None)
    }

    /// The last frame (RGBA8, linear values), after [`Self::draw`] or [`Self::render`].
    pub fn output_view(&self) -> Option<&wgpu::TextureView> {
        self.main.as_ref().map(|m| &m.output_view)
    }

    /// A mappable staging buffer of at least `size` bytes (reused between frames).
    #[cfg(not(target_arch = "wasm32"))]
    fn staging(&mut self, size: u64) -> wgpu::Buffer {
        if self.staging.as_ref().is_none_or(|s| s.size() != size) {
            self.staging = Some(self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("raster staging"),
                size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        self.staging.clone().expect("allocated above")
    }
}

/// A raster frame whose readback is under way ([`RasterRenderer::read_polled`]).
pub struct PendingFrame {
    read: readback::PendingRead,
    width: u32,
    height: u32,
}

impl PendingFrame {
    /// `None` while the frame is still being read back; never waits.
    pub fn poll(&self, gpu: &GpuContext) -> Option<Result<RgbImage32, RasterError>> {
        let bytes = self.read.poll(gpu)?;
        Some(bytes.map_err(RasterError::from).map(|bytes| decode_frame(self.width, self.height, &bytes)))
    }

    /// The frame's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

/// The output's RGBA8 rows (each padded to the copy alignment) as linear RGB: each value one of
/// the 256 levels k / 255.
fn decode_frame(width: u32, height: u32, pixels: &[u8]) -> RgbImage32 {
    let row = (width * BYTES_PER_PIXEL).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    RgbImage32::from_fn(width, height, |x, y| {
        let i = (y * row + x * BYTES_PER_PIXEL) as usize;
        [0, 1, 2].map(|c| f32::from(pixels[i + c]) / 255.0)
    })
}

/// Records the copy of the output texture (`width` x `height`) into `staging`, rows `row` bytes
/// apart (a multiple of wgpu's copy alignment).
fn copy_output(
    encoder: &mut wgpu::CommandEncoder,
    output: &wgpu::Texture,
    staging: &wgpu::Buffer,
    width: u32,
    height: u32,
    row: u32,
) {
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: output,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: staging,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
}
