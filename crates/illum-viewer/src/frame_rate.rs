//! Frames per second over a sliding window of recent frames.

use std::collections::VecDeque;
use web_time::Instant;

/// Frames averaged.
const WINDOW: usize = 30;

#[derive(Debug, Default)]
pub struct FrameRate {
    starts: VecDeque<Instant>,
}

impl FrameRate {
    /// Records that a frame starts now.
    pub fn tick(&mut self) {
        self.starts.push_back(Instant::now());
        while self.starts.len() > WINDOW {
            self.starts.pop_front();
        }
    }

    /// Frames per second over the recorded window (needs two frames).
    pub fn fps(&self) -> Option<f64> {
        let (first, last) = (self.starts.front()?, self.starts.back()?);
        let seconds = last.duration_since(*first).as_secs_f64();
        (self.starts.len() > 1 && seconds > 0.0).then(|| (self.starts.len() - 1) as f64 / seconds)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn needs_two_frames() {
        let mut rate = FrameRate::default();
        assert_eq!(rate.fps(), None);
        rate.tick();
        assert_eq!(rate.fps(), None);
        std::thread::sleep(std::time::Duration::from_millis(5));
        rate.tick();
        assert!(rate.fps().is_some_and(|fps| fps > 0.0 && fps < 1000.0));
    }
}
