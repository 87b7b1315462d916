//! Work spread over threads with results in a fixed order: every renderer of the oracle keys its
//! random numbers by (seed, pixel, sample), so an image does not depend on how many threads
//! computed it or which took which row.

use std::sync::atomic::{AtomicU32, Ordering};

/// `pixel(x, y)` for every pixel of a `width` x `height` image, row-major from the top-left,
/// computed on `threads` threads (at least one) that take rows one at a time. The result does
/// not depend on `threads`.
pub(crate) fn rows_in_parallel<T: Send>(
    width: u32,
    height: u32,
    threads: usize,
    pixel: impl Fn(u32, u32) -> T + Sync,
) -> Vec<T> {
    in_parallel(height, threads, |y| (0..width).map(|x| pixel(x, y)).collect::<Vec<T>>())
        .into_iter()
        .flatten()
        .collect()
}

/// `item(i)` for i in 0..count, in that order, computed on `threads` threads (at least one)
/// that take the next index one at a time; the result does not depend on `threads`.
pub(crate) fn in_parallel<T: Send>(count: u32, threads: usize, item: impl Fn(u32) -> T + Sync) -> Vec<T> {
    let next = AtomicU32::new(0);
    let threads = threads.clamp(1, count.max(1) as usize);
    let mut items: Vec<(u32, T)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= count {
                            break done;
                        }
                        done.push((i, item(i)));
                    }
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().expect("oracle worker panicked")).collect()
    });
    items.sort_unstable_by_key(|(i, _)| *i);
    items.into_iter().map(|(_, item)| item).collect()
}
