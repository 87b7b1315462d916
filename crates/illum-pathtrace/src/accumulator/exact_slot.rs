//! The accumulator's exact part as far as it is known: ready, or still being solved on a thread
//! of its own while the first samples are traced. Nothing needs it before an image is read (it
//! is no sample, and has no variance), so a render's set-up does not wait for it: the first
//! reader does, and every later one reads the same part.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
#[cfg(not(target_arch = "wasm32"))]
use std::sync::{Mutex, OnceLock};
#[cfg(not(target_arch = "wasm32"))]
use std::thread::JoinHandle;

use super::ExactPart;

/// An exact part, or the solve that will give it (shared by an accumulator's clones).
#[derive(Clone, Debug)]
pub(super) enum ExactSlot {
    Ready(ExactPart),
    #[cfg(not(target_arch = "wasm32"))]
    Solving(Arc<Solving>),
}

impl ExactSlot {
    /// `solve` on a thread of its own; it should return early once its flag is set (the slot was
    /// dropped or replaced unread: a viewer's camera moved again), with any part, which is then
    /// never read. Where there are no threads (a web page), or the host will not start one,
    /// `solve` runs here and now.
    pub(super) fn solving(solve: impl FnOnce(&StopFlag) -> ExactPart + Send + 'static) -> Self {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let cancel = Arc::new(AtomicBool::new(false));
            // Shared with the thread, so that the solve is still here if the thread never starts.
            let job = Arc::new(Mutex::new(Some(solve)));
            let (thread_job, flag) = (Arc::clone(&job), StopFlag(Arc::clone(&cancel)));
            let started = std::thread::Builder::new().name("illum exact part".into()).spawn(move || {
                let solve = thread_job.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take();
                solve.map(|solve| solve(&flag)).unwrap_or_default()
            });
            match started {
                Ok(thread) => ExactSlot::Solving(Arc::new(Solving {
                    part: OnceLock::new(),
                    thread: Mutex::new(Some(thread)),
                    cancel,
                })),
                Err(_) => {
                    let solve = job.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take();
                    let flag = StopFlag(cancel);
                    ExactSlot::Ready(solve.map(|solve| solve(&flag)).unwrap_or_default())
                }
            }
        }
        #[cfg(target_arch = "wasm32")]
        {
            ExactSlot::Ready(solve(&StopFlag(Arc::new(AtomicBool::new(false)))))
        }
    }

    /// Whether [`Self::get`] would return at once: the part is known, or its solve has ended.
    pub(super) fn is_ready(&self) -> bool {
        match self {
            ExactSlot::Ready(_) => true,
            #[cfg(not(target_arch = "wasm32"))]
            ExactSlot::Solving(solving) => solving.has_ended(),
        }
    }

    /// The part, waiting for its solve if it is still running.
    pub(super) fn get(&self) -> &ExactPart {
        match self {
            ExactSlot::Ready(part) => part,
            #[cfg(not(target_arch = "wasm32"))]
            ExactSlot::Solving(solving) => solving.wait(),
        }
    }
}

/// Set when nobody will read a solve's result: the solve may stop.
pub struct StopFlag(Arc<AtomicBool>);

impl StopFlag {
    /// Whether the solve's result will never be read.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// A solve on its own thread, and its result once the first reader has waited for it.
#[cfg(not(target_arch = "wasm32"))]
pub(super) struct Solving {
    part: OnceLock<ExactPart>,
    thread: Mutex<Option<JoinHandle<ExactPart>>>,
    cancel: Arc<AtomicBool>,
}

#[cfg(not(target_arch = "wasm32"))]
impl Solving {
    fn has_ended(&self) -> bool {
        self.part.get().is_some()
            || self
                .thread
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .as_ref()
                .is_none_or(|thread| thread.is_finished())
    }

    fn wait(&self) -> &ExactPart {
        self.part.get_or_init(|| {
            let thread = self.thread.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).take();
            // A panic in the solve is the caller's, as it would be had the solve run inline.
            thread
                .map(|t| t.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
                .unwrap_or_default()
        })
    }
}

#[cfg(not(target_arch = "wasm32"))]
impl Drop for Solving {
    /// Nobody holds the slot any more: its solve may stop (its thread ends on its own).
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

#[cfg(not(target_arch = "wasm32"))]
impl std::fmt::Debug for Solving {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.part.get() {
            Some(part) => f.debug_tuple("Solved").field(part).finish(),
            None => f.write_str("Solving"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part(value: f64) -> ExactPart {
        ExactPart::new(&[(0, [value; 3])], 1).expect("one pixel")
    }

    #[test]
    fn every_reader_gets_the_solved_part_and_clones_share_it() {
        let slot = ExactSlot::solving(|_| {
            std::thread::sleep(std::time::Duration::from_millis(20));
            part(2.5)
        });
        let copy = slot.clone();
        assert_eq!(slot.get(), &part(2.5));
        assert!(slot.is_ready() && copy.is_ready(), "read once, known to every clone");
        assert_eq!(copy.get(), &part(2.5));
        assert_eq!(ExactSlot::Ready(part(1.0)).get(), &part(1.0));
    }

    #[test]
    #[cfg(not(target_arch = "wasm32"))]
    fn a_slot_is_ready_once_its_solve_has_ended_and_not_before() {
        let (go, told) = std::sync::mpsc::channel::<()>();
        let slot = ExactSlot::solving(move |_| {
            told.recv().expect("the test says go");
            part(1.5)
        });
        assert!(!slot.is_ready(), "its solve waits for the test");
        go.send(()).expect("the solve listens");
        let waited = std::time::Instant::now();
        while !slot.is_ready() {
            assert!(waited.elapsed().as_secs() < 60, "the solve never ended");
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        assert_eq!(slot.get(), &part(1.5));
    }

    #[test]
    #[cfg(not(target_arch = "wasm32"))]
    fn a_slot_dropped_unread_tells_its_solve_to_stop() {
        let (sender, receiver) = std::sync::mpsc::channel();
        let (start_sender, start) = std::sync::mpsc::channel::<()>();
        let slot = ExactSlot::solving(move |flag| {
            start.recv().expect("the test says go");
            let mut waited = 0;
            while !flag.is_set() && waited < 1000 {
                std::thread::sleep(std::time::Duration::from_millis(5));
                waited += 1;
            }
            sender.send(flag.is_set()).expect("the test listens");
            ExactPart::default()
        });
        drop(slot);
        start_sender.send(()).expect("the solve listens");
        let stopped = receiver.recv_timeout(std::time::Duration::from_secs(10)).expect("the solve ends");
        assert!(stopped, "the solve never saw that nobody will read it");
    }

    #[test]
    #[cfg(not(target_arch = "wasm32"))]
    fn a_panic_in_the_solve_reaches_the_reader() {
        let slot = ExactSlot::solving(|_| panic!("no glint today"));
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| slot.get().entries().len()));
        assert!(caught.is_err(), "the reader went on as if the solve had given a part");
    }
}
