//! What a render needs of host memory per pixel, and the check, before anything is allocated,
//! that it fits.

/// Host bytes per pixel of the f64 statistics: sum and sum of squares (3 x f64 each) and the
/// sample count (u64).
pub const STATISTICS_BYTES_PER_PIXEL: u64 = 56;
const _: () = assert!(
    STATISTICS_BYTES_PER_PIXEL as usize == 2 * std::mem::size_of::<[f64; 3]>() + std::mem::size_of::<u64>()
);

/// Host bytes per pixel a whole render needs at its peak, writing a PNG and a checkpoint EXR:
/// the statistics and their EXR layer (2 x 56), the f32 mean image and its copy in the EXR
/// encoder (2 x 12), an 8-bit PNG's pixels (3) and the driver's batch and staging buffers
/// (about 20). Measured: 159 bytes per pixel at 4096 x 4096 (2.67 GB peak).
pub const RENDER_HOST_BYTES_PER_PIXEL: u64 = 2 * STATISTICS_BYTES_PER_PIXEL + 2 * 12 + 3 + 20;

/// Host bytes per pixel that a render ending inside a chunk needs on top: the copy of its
/// statistics at the last chunk boundary and that copy's EXR layer (see `checkpoint.rs`).
pub const ALIGNED_COPY_BYTES_PER_PIXEL: u64 = 2 * STATISTICS_BYTES_PER_PIXEL;

/// Checks, before anything is allocated, that a `width x height` render fits in `available`
/// bytes of host memory (`None`: unknown, not checked), with `extra_per_pixel` bytes per pixel
/// on top of [`RENDER_HOST_BYTES_PER_PIXEL`] (a low-discrepancy render's replicates and their
/// EXR layer: 2 x `Replicates::BYTES_PER_PIXEL`). The error says how much it would need.
pub fn check_host_memory(
    width: u32,
    height: u32,
    extra_per_pixel: u64,
    available: Option<u64>,
) -> Result<(), String> {
    let per_pixel = RENDER_HOST_BYTES_PER_PIXEL + extra_per_pixel;
    let needed = u64::from(width) * u64::from(height) * per_pixel;
    match available {
        Some(available) if needed > available => Err(format!(
            "camera.width x camera.height = {width} x {height}: the render needs {:.1} GiB of host memory \
             ({per_pixel} bytes per pixel: the f64 statistics, the output images and their encoders' copies), \
             but only {:.1} GiB are available",
            gib(needed),
            gib(available)
        )),
        _ => Ok(()),
    }
}

fn gib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 30) as f64
}

/// Host memory available to a new allocation without swapping (Linux: `MemAvailable` in
/// /proc/meminfo); `None` where that is not known.
pub fn available_host_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_render_larger_than_memory_is_refused_with_what_it_needs() {
        let err = check_host_memory(8192, 8192, 0, Some(2 << 30)).unwrap_err();
        assert!(err.contains("8192 x 8192") && err.contains("9.9 GiB") && err.contains("2.0 GiB"), "{err}");
        // With the replicates of a low-discrepancy render: 159 + 512 bytes per pixel.
        let err = check_host_memory(8192, 8192, 512, Some(2 << 30)).unwrap_err();
        assert!(err.contains("41.9 GiB") && err.contains("671 bytes per pixel"), "{err}");
        assert!(check_host_memory(16384, 16384, 0, None).is_ok());
        assert!(check_host_memory(512, 512, 0, Some(1 << 30)).is_ok());
        if cfg!(target_os = "linux") {
            assert!(available_host_memory().is_some_and(|b| b > 0));
        }
    }
}
