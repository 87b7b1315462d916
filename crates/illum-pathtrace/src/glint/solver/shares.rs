//! How the glint's solve deals its work among the host's threads: in consecutive shares, taken
//! by whichever thread is free, the results in the shares' order.

/// `work(offset, share)` over consecutive shares of `items`, the results in the order of the
/// shares, whatever the threads: each of `threads` threads takes the next share left until none
/// is, so that a share that costs more than others (the chains of one crowded region, the seeds
/// of a sphere seen through many others) does not leave the other threads idle. With one thread
/// it runs on the caller's.
pub(super) fn in_shares<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    work: impl Fn(usize, &[T]) -> R + Sync,
) -> Vec<R> {
    let threads = threads.min(items.len());
    if threads <= 1 {
        return vec![work(0, items)];
    }
    let per_share = items.len().div_ceil(threads * SHARES_PER_THREAD);
    let shares: Vec<&[T]> = items.chunks(per_share).collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let (work, shares, next) = (&work, &shares, &next);
    let mut done: Vec<(usize, R)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(move || {
                    let mut results = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(share) = shares.get(k) else { break };
                        results.push((k, work(k * per_share, share)));
                    }
                    results
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("a glint solver thread")).collect()
    });
    done.sort_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, r)| r).collect()
}

/// Shares per thread in [`in_shares`]: enough that the last ones even out the threads' load.
const SHARES_PER_THREAD: usize = 32;
