//! How much of each frame the path tracer gets.
//!
//! A frame is the path tracer's submission plus everything else: egui's layout, the display
//! pass, drawing and presenting the window (on lavapipe most of it, and growing with the
//! window's size). The pacer measures the rest of the frame and gives the path tracer what is
//! left of [`TARGET_FRAME_SECONDS`], and at least as much as the rest takes (up to
//! [`LONGEST_SHARE`]): with the view still, the path tracer has at least half of each frame, so
//! that it gathers about half of `render`'s throughput or more, and where drawing the window
//! takes less than half the target frame the window keeps the target's rate. While the view changes (a camera drag, a new
//! setting) it gets [`MOVING_SECONDS`], so that the window follows the mouse with a fresh
//! low-spp image every frame.

use web_time::Instant;

/// Frame time aimed at with the view still: 12 fps, a margin above the 10 fps a window needs
/// to feel responsive.
pub const TARGET_FRAME_SECONDS: f64 = 1.0 / 12.0;
/// The path tracer's share of a frame while the view changes, and its least share ever.
pub const MOVING_SECONDS: f64 = 0.015;
/// Longest share of a frame the path tracer takes with the view still: on a machine so loaded
/// that drawing the window takes longer than this, the window still repaints a few times a
/// second.
pub const LONGEST_SHARE: f64 = 0.1;
/// Frames after the last change during which the view counts as moving (a drag's events do
/// not arrive every frame).
const SETTLE_FRAMES: u32 = 3;
/// Weight of the newest frame in the smoothed time of the rest of the frame.
const SMOOTHING: f64 = 0.3;
/// Longest gap between frames that counts as frame time (a longer one is the window hidden,
/// the mode switched away, or the path tracer paused: not the cost of a frame).
const LONGEST_FRAME: f64 = 0.5;

#[derive(Debug, Default)]
pub struct FramePacer {
    /// When the last frame's path-tracing step began, and how long it took.
    last_step: Option<(Instant, f64)>,
    /// Smoothed seconds of each frame spent outside the path tracer's step.
    other_seconds: Option<f64>,
    /// Frames since the view last changed.
    still_frames: u32,
}

impl FramePacer {
    /// The wall time to aim at for this frame's submission; `changed`: the view or a setting
    /// changed since the last frame (the accumulation restarted).
    pub fn submission_seconds(&mut self, changed: bool) -> f64 {
        let now = Instant::now();
        if let Some((started, step)) = self.last_step {
            let interval = now.duration_since(started).as_secs_f64();
            if interval <= LONGEST_FRAME {
                let other = (interval - step).max(0.0);
                self.other_seconds =
                    Some(self.other_seconds.map_or(other, |o| (1.0 - SMOOTHING) * o + SMOOTHING * other));
            }
        }
        self.still_frames = if changed { 0 } else { self.still_frames.saturating_add(1) };
        share(self.other_seconds, self.still_frames >= SETTLE_FRAMES)
    }

    /// Wall seconds per second of path tracing once the view is still: a frame is the path
    /// tracer's share plus the rest of the frame as measured so far (`None` before two frames).
    /// What a prediction of the viewer's time to some spp multiplies the GPU's time by.
    pub fn wall_per_traced_second(&self) -> Option<f64> {
        let other = self.other_seconds?;
        let share = share(Some(other), true);
        Some((share + other) / share)
    }

    /// Records that this frame's step began at `started` and took `seconds`.
    pub fn stepped(&mut self, started: Instant, seconds: f64) {
        self.last_step = Some((started, seconds));
    }
}

/// The path tracer's share of a frame whose other work takes `other` seconds (unknown before
/// the second frame): once the view is `still`, what is left of the target frame and at least
/// as much as `other` (at most [`LONGEST_SHARE`]); never less than [`MOVING_SECONDS`].
fn share(other: Option<f64>, still: bool) -> f64 {
    match other {
        Some(other) if still => {
            (TARGET_FRAME_SECONDS - other).max(other.min(LONGEST_SHARE)).max(MOVING_SECONDS)
        }
        _ => MOVING_SECONDS,
    }
}

/// The Auto pilot's path tracing is paced as the path-tracer mode's frames are; the view is
/// still while it runs (it shows the progress).
impl illum_auto::pilot::Pace for FramePacer {
    fn slice_seconds(&mut self) -> f64 {
        self.submission_seconds(false)
    }
    fn stepped(&mut self, started: Instant, seconds: f64) {
        FramePacer::stepped(self, started, seconds);
    }
    fn wall_per_traced_second(&self) -> f64 {
        FramePacer::wall_per_traced_second(self).unwrap_or(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_path_tracer_gets_what_the_frame_leaves() {
        assert_eq!(share(None, true), MOVING_SECONDS);
        assert_eq!(share(Some(0.03), false), MOVING_SECONDS, "a moving view gets short submissions");
        assert!((share(Some(0.03), true) - (TARGET_FRAME_SECONDS - 0.03)).abs() < 1e-12);
        assert!(share(Some(0.005), true) > 0.07, "a cheap frame leaves most of it to the path tracer");
        assert_eq!(share(Some(0.06), true), 0.06, "at least as much as the rest of the frame");
        let pacer = FramePacer { other_seconds: Some(0.06), ..FramePacer::default() };
        assert_eq!(pacer.wall_per_traced_second(), Some(2.0), "the rest of the frame doubles the time");
        assert_eq!(FramePacer::default().wall_per_traced_second(), None);
        assert_eq!(share(Some(0.5), true), LONGEST_SHARE, "a loaded machine still repaints");
        assert_eq!(share(Some(0.0), false), MOVING_SECONDS);
    }

    #[test]
    fn a_change_restarts_the_settling() {
        let mut pacer = FramePacer::default();
        let now = Instant::now();
        pacer.stepped(now, 0.0);
        for _ in 0..SETTLE_FRAMES {
            pacer.submission_seconds(false);
        }
        assert!(pacer.submission_seconds(false) > MOVING_SECONDS, "still: the larger share");
        assert_eq!(pacer.submission_seconds(true), MOVING_SECONDS, "changed: the moving share");
    }
}
