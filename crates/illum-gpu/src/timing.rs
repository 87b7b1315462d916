//! GPU pass timing with timestamp queries.
//!
//! A [`PassTimer`] owns a query set with two slots per named pass. Passes write their begin and
//! end timestamps through [`PassTimer::compute_writes`] / [`PassTimer::render_writes`]; after
//! submission [`PassTimer::read`] resolves them into milliseconds (natively; a web page copies
//! them with [`PassTimer::copy_results`] and decodes the polled bytes). Without `TIMESTAMP_QUERY` the
//! timer is inert and `read` returns `None`.

use crate::GpuContext;

pub struct PassTimer {
    queries: Option<Queries>,
    names: Vec<String>,
}

struct Queries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    period_ns: f64,
}

impl PassTimer {
    pub fn new(gpu: &GpuContext, pass_names: &[&str]) -> Self {
        let names: Vec<String> = pass_names.iter().map(|s| (*s).to_owned()).collect();
        // A query set cannot be empty: with no passes to time the timer is inert.
        let queries = (gpu.timestamps && !names.is_empty()).then(|| {
            let count = 2 * names.len() as u32;
            Queries {
                set: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("illum pass timer"),
                    ty: wgpu::QueryType::Timestamp,
                    count,
                }),
                resolve: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("illum pass timer resolve"),
                    size: 8 * count as u64,
                    usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                    mapped_at_creation: false,
                }),
                period_ns: gpu.queue.get_timestamp_period() as f64,
            }
        });
        Self { queries, names }
    }

    pub fn enabled(&self) -> bool {
        self.queries.is_some()
    }

    fn index(&self, pass: &str) -> u32 {
        self.names.iter().position(|n| n == pass).unwrap_or_else(|| {
            panic!("pass {pass:?} was not declared to PassTimer::new (a programming error)")
        }) as u32
    }

    /// The query set and the (beginning, end) query indices of `pass`, with timestamp queries.
    fn writes(&self, pass: &str) -> Option<(&wgpu::QuerySet, Option<u32>, Option<u32>)> {
        let i = self.index(pass);
        self.queries.as_ref().map(|q| (&q.set, Some(2 * i), Some(2 * i + 1)))
    }

    pub fn compute_writes(&self, pass: &str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.writes(pass).map(|(query_set, beginning_of_pass_write_index, end_of_pass_write_index)| {
            wgpu::ComputePassTimestampWrites {
                query_set,
                beginning_of_pass_write_index,
                end_of_pass_write_index,
            }
        })
    }

    pub fn render_writes(&self, pass: &str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.writes(pass).map(|(query_set, beginning_of_pass_write_index, end_of_pass_write_index)| {
            wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index,
                end_of_pass_write_index,
            }
        })
    }

    /// Records the copy of all timestamps into the resolve buffer; call once per frame, after
    /// the timed passes and before `finish()`.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(q) = &self.queries {
            encoder.resolve_query_set(&q.set, 0..2 * self.names.len() as u32, &q.resolve, 0);
        }
    }

    /// Bytes that [`Self::copy_results`] writes.
    pub fn result_size(&self) -> u64 {
        16 * self.names.len() as u64
    }

    /// Resolves the timestamps and copies them into `destination` at `offset` (which needs
    /// `COPY_DST`), so they can come back with a readback the caller already makes.
    pub fn copy_results(&self, encoder: &mut wgpu::CommandEncoder, destination: &wgpu::Buffer, offset: u64) {
        if let Some(q) = &self.queries {
            self.resolve(encoder);
            encoder.copy_buffer_to_buffer(&q.resolve, 0, destination, offset, self.result_size());
        }
    }

    /// Milliseconds per pass from the bytes [`Self::copy_results`] copied; `None` when inert.
    pub fn decode(&self, bytes: &[u8]) -> Option<Vec<(String, f64)>> {
        let q = self.queries.as_ref()?;
        // The staging copy is a Vec<u8> with no alignment guarantee, so decode rather than cast.
        let ticks: Vec<u64> = bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("chunks_exact yields 8 bytes")))
            .collect();
        Some(
            self.names
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let elapsed = ticks[2 * i + 1].wrapping_sub(ticks[2 * i]) as f64;
                    (name.clone(), elapsed * q.period_ns * 1e-6)
                })
                .collect(),
        )
    }

    /// Milliseconds per pass, in declaration order, after the submission that resolved them.
    /// Blocks until they are read back (not on `wasm32`: there copy them with
    /// [`Self::copy_results`] into a buffer read by a [`crate::readback::PendingRead`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn read(&self, gpu: &GpuContext) -> Result<Option<Vec<(String, f64)>>, crate::GpuError> {
        let Some(q) = &self.queries else { return Ok(None) };
        let bytes =
            crate::readback::read_buffer(gpu, &q.resolve, 0, q.resolve.size(), "reading GPU timestamps")?;
        Ok(self.decode(&bytes))
    }
}
