//! The wall-clock time of a render, which a caller may pause.

use std::time::Duration;

use web_time::Instant;

/// Wall-clock time of a render that a caller may pause.
#[derive(Clone, Copy, Debug)]
pub struct RenderClock {
    running_since: Option<Instant>,
    before: Duration,
}

impl RenderClock {
    /// A clock that starts now.
    pub fn started() -> Self {
        RenderClock { running_since: Some(Instant::now()), before: Duration::ZERO }
    }

    pub fn elapsed(&self) -> Duration {
        self.before + self.running_since.map_or(Duration::ZERO, |t| t.elapsed())
    }

    /// Stops counting (a paused render); [`Self::resume`] goes on.
    pub fn pause(&mut self) {
        if let Some(since) = self.running_since.take() {
            self.before += since.elapsed();
        }
    }

    pub fn resume(&mut self) {
        if self.running_since.is_none() {
            self.running_since = Some(Instant::now());
        }
    }

    pub fn is_running(&self) -> bool {
        self.running_since.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_paused_clock_stands_still() {
        let mut clock = RenderClock::started();
        clock.pause();
        let a = clock.elapsed();
        std::thread::sleep(Duration::from_millis(5));
        assert_eq!(clock.elapsed(), a);
        clock.resume();
        std::thread::sleep(Duration::from_millis(2));
        assert!(clock.elapsed() > a);
    }
}
