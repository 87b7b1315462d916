//! How the light tracer's frames are cut into submissions: pure arithmetic, tested without a GPU.
//!
//! The bands of the camera paths are sized so that one submission takes about the step's time
//! target (`planner.rs`); the light tracer's frames are sized by the same rule, so that no step
//! of a render, whatever the image's size, holds the GPU (and with it the answer to a signal, a
//! progress line or a viewer's frame) much longer than the target:
//!
//! - A frame whose measured cost (its particles, its gather, its readback and fold) fits the
//!   target goes whole, as many frames to a submission as fit (at most what the buffers hold).
//! - Otherwise the frame goes in pieces: ranges of its particles, then ranges of its gathering
//!   pixels, each sized by that stage's measured cost per invocation to fit the target.
//! - Before a cost is measured, a piece carries [`PROBE_INVOCATIONS`] invocations, the size of the
//!   bands' first, measuring submission; a frame is sent whole only once its cost is known.
//!
//! A piece is a range of invocations, a multiple of the workgroup except at a stage's end, so
//! one submission is never forced to be larger than one workgroup: a piece of an image of any
//! size can be as small as the target needs. Integer atomics add in any order, so a frame's
//! values do not depend on how it was cut.
//!
//! The frame's readback and fold are host work of its pixels that follow its last piece; they
//! are counted in a whole frame's cost, and timed apart from a piece's (`Costs::fold`).

/// Invocations of a piece traced before its stage's cost is known: the bands' probe
/// (`planner.rs`), so that a first measurement costs the same whatever the estimator.
pub(crate) const PROBE_INVOCATIONS: u32 = crate::planner::PROBE_SAMPLES as u32;

/// Invocations per workgroup of the light tracer's and the gather's shaders.
pub(crate) const WORKGROUP: u32 = 64;

/// The stages of a frame traced in pieces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stage {
    /// The frame's particles (the first piece clears the frame's splat and photon grid).
    Particles,
    /// The frame's gathering pixels (with a delta sun).
    Gather,
}

/// What the light tracer has measured of its costs, in seconds (smoothed; `None` until measured).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Costs {
    /// One whole frame: its particles, its gather, its readback and fold.
    pub frame: Option<f64>,
    /// Per invocation of each stage ([`Stage::Particles`], [`Stage::Gather`]).
    pub per_invocation: [Option<f64>; 2],
}

/// How long a submission took, as its caller could tell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Took {
    /// Waited for, or timed by the GPU: these seconds.
    Seconds(f64),
    /// Seen done by a caller that looks every so often and is told late (a browser, a frame
    /// at a time, told by the page's event loop): at most these seconds, and perhaps far less.
    AtMost(f64),
    /// The same, seen done at the first look after its submission.
    WithinOneLook(f64),
}

impl Costs {
    /// Takes a new measurement of `old`: exponential smoothing, as the bands' planner does.
    ///
    /// A bound is no measurement. Were it taken as one, a piece done well within the time it
    /// took to be seen done would be charged all of it, the next piece cut to the target's
    /// share of that, and so on down to one workgroup a look (a browser told a few frames late
    /// traced a frame in hundreds of looks). A bound only lowers the cost to itself; one seen
    /// at the first look halves it too, so that the next submission doubles until one outlasts
    /// a look.
    fn smooth(old: Option<f64>, took: Took) -> Option<f64> {
        let bounded = |bound: f64| old.map_or(bound, |old| old.min(bound));
        match took {
            Took::Seconds(seconds) if seconds.is_finite() && seconds > 0.0 => {
                Some(old.map_or(seconds, |old| 0.5 * old + 0.5 * seconds))
            }
            Took::AtMost(bound) if bound.is_finite() && bound > 0.0 => Some(bounded(bound)),
            Took::WithinOneLook(bound) if bound.is_finite() && bound > 0.0 => Some(0.5 * bounded(bound)),
            _ => old,
        }
    }

    /// Records that `frames` whole frames took `took`.
    pub fn record_frames(&mut self, frames: u32, took: Took) {
        if frames > 0 {
            self.frame = Self::smooth(self.frame, took.per(frames));
        }
    }

    /// Records that a piece of `count` invocations of `stage` took `took`.
    pub fn record_piece(&mut self, stage: Stage, count: u32, took: Took) {
        if count > 0 {
            let i = stage as usize;
            self.per_invocation[i] = Self::smooth(self.per_invocation[i], took.per(count));
        }
    }

    /// Records that a frame traced in pieces took `seconds` in all (its pieces, readback and fold).
    pub fn record_pieced_frame(&mut self, seconds: f64) {
        self.frame = Self::smooth(self.frame, Took::Seconds(seconds));
    }
}

impl Took {
    /// The same, shared among `count` units.
    fn per(self, count: u32) -> Took {
        let n = f64::from(count);
        match self {
            Took::Seconds(s) => Took::Seconds(s / n),
            Took::AtMost(s) => Took::AtMost(s / n),
            Took::WithinOneLook(s) => Took::WithinOneLook(s / n),
        }
    }
}

/// Where the pass's next frame stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Cursor {
    /// Nothing of it is traced.
    FrameStart,
    /// Its pieces are traced up to invocation `next` of `stage`.
    Within { stage: Stage, next: u32 },
}

/// One submission of the light tracer's work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Submission {
    /// `count` whole frames: clear, particles, gather, read back.
    Frames { count: u32 },
    /// Invocations `first..first + count` of `stage` of the next frame: `clear` for the frame's
    /// first piece, `read` for its last.
    Piece { stage: Stage, first: u32, count: u32, clear: bool, read: bool },
}

impl Submission {
    /// Where the frame stands after this submission.
    pub fn cursor_after(&self, invocations: u32, gather: bool) -> Cursor {
        match *self {
            Submission::Frames { .. } => Cursor::FrameStart,
            Submission::Piece { read: true, .. } => Cursor::FrameStart,
            Submission::Piece { stage, first, count, .. } => {
                let next = first + count;
                match stage {
                    Stage::Particles if next >= invocations && gather => {
                        Cursor::Within { stage: Stage::Gather, next: 0 }
                    }
                    _ => Cursor::Within { stage, next },
                }
            }
        }
    }

    /// Seconds it is planned to take at `costs` (`None` where a cost it needs is not measured).
    #[cfg(test)]
    pub fn predicted_seconds(&self, costs: &Costs) -> Option<f64> {
        match *self {
            Submission::Frames { count } => costs.frame.map(|f| f * f64::from(count)),
            Submission::Piece { stage, count, .. } => {
                costs.per_invocation[stage as usize].map(|c| c * f64::from(count))
            }
        }
    }
}

/// The shape of a render's frames: `invocations` particles per frame (and as many gathering
/// pixels with the gather), and at most `max_frames` frames per submission (its buffers).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FrameShape {
    pub invocations: u32,
    pub gather: bool,
    pub max_frames: u32,
}

/// The next submission of a pass with `frames_left` frames to trace (at least 1), its next frame
/// at `cursor`, aiming at `target` seconds per submission (see the module documentation).
pub(crate) fn next_submission(
    shape: FrameShape,
    costs: &Costs,
    target: f64,
    cursor: Cursor,
    frames_left: u32,
) -> Submission {
    let target = if target.is_nan() { 0.0 } else { target.max(0.0) };
    let (stage, first) = match cursor {
        Cursor::FrameStart => {
            if let Some(frame) = costs.frame.filter(|&f| f <= target) {
                let fit = (target / frame.max(1e-12)).floor().min(f64::from(u32::MAX)) as u32;
                let count = fit.clamp(1, shape.max_frames.max(1)).min(frames_left.max(1));
                return Submission::Frames { count };
            }
            (Stage::Particles, 0)
        }
        Cursor::Within { stage, next } => (stage, next),
    };
    let left = shape.invocations.saturating_sub(first);
    let wanted = match costs.per_invocation[stage as usize] {
        None => PROBE_INVOCATIONS,
        Some(cost) => {
            let fit = (target / cost.max(1e-15)).floor().min(f64::from(u32::MAX)) as u32;
            // Whole workgroups, at least one.
            (fit / WORKGROUP * WORKGROUP).max(WORKGROUP)
        }
    };
    let count = wanted.min(left).max(1);
    let end = first + count;
    let last_stage = stage == Stage::Gather || !shape.gather;
    Submission::Piece {
        stage,
        first,
        count,
        clear: stage == Stage::Particles && first == 0,
        read: last_stage && end >= shape.invocations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The submissions of a pass, from an empty cursor, at `costs` (updated after each by
    /// `learn`, as the tracer measures), up to `limit` of them.
    fn plan_pass(
        shape: FrameShape,
        mut costs: Costs,
        target: f64,
        frames: u32,
        limit: usize,
        learn: impl Fn(&mut Costs, &Submission),
    ) -> Vec<(Submission, Costs)> {
        let (mut cursor, mut done, mut out) = (Cursor::FrameStart, 0, Vec::new());
        while done < frames && out.len() < limit {
            let s = next_submission(shape, &costs, target, cursor, frames - done);
            out.push((s, costs));
            cursor = s.cursor_after(shape.invocations, shape.gather);
            done += match s {
                Submission::Frames { count } => count,
                Submission::Piece { read, .. } => u32::from(read),
            };
            learn(&mut costs, &s);
        }
        out
    }

    /// The rule of the issue: no submission is planned longer than the target, however large
    /// the image, at any measured cost; before a cost is measured it is the probe's size. And
    /// each frame's pieces cover its particles, then its gathering pixels, exactly once, in
    /// order, cleared by the first and read back by the last.
    #[test]
    fn no_submission_is_planned_longer_than_the_target_however_large_the_image() {
        let target = 0.15;
        // 1 x 1 to 16384 x 16384 (and one beyond a u32 of pixels' reach is not an image).
        for invocations in [1u32, 63, 64, 65, 57_600, 921_600, 3_840 * 2_160, 16_384 * 16_384] {
            for gather in [false, true] {
                // Invented costs per invocation, from cheap (a whole 4K frame fits one submission)
                // to dear (a single workgroup, the least a submission carries, exceeds the target).
                for per in [1e-9, 1e-7, 6.5e-7, 1e-5, 1e-3] {
                    let shape = FrameShape { invocations, gather, max_frames: 16 };
                    // The fold costs what the camera's own fold does, about 10 ns a pixel.
                    let frame_cost =
                        f64::from(invocations) * (per * (1.0 + f64::from(u8::from(gather))) + 1e-8);
                    let learn = |c: &mut Costs, s: &Submission| match *s {
                        Submission::Frames { count } => {
                            c.record_frames(count, Took::Seconds(frame_cost * f64::from(count)))
                        }
                        Submission::Piece { stage, count, read, .. } => {
                            c.record_piece(stage, count, Took::Seconds(per * f64::from(count)));
                            if read {
                                c.record_pieced_frame(frame_cost);
                            }
                        }
                    };
                    // Three frames, or the first 20,000 submissions where the dearest costs make a
                    // frame millions of them: the rule holds for each alike.
                    let plan = plan_pass(shape, Costs::default(), target, 3, 20_000, learn);
                    assert!(!plan.is_empty());
                    let mut expected = (Stage::Particles, 0u32);
                    for (s, costs) in &plan {
                        match (*s, s.predicted_seconds(costs)) {
                            (Submission::Frames { count }, Some(seconds)) => {
                                assert!((1..=16).contains(&count));
                                assert!(
                                    seconds <= target * (1.0 + 1e-12),
                                    "{invocations}: {count} frames planned at {seconds} s"
                                );
                                assert_eq!(expected, (Stage::Particles, 0), "whole frames mid-frame");
                            }
                            (Submission::Frames { .. }, None) => {
                                panic!("a whole frame before its cost is known")
                            }
                            (Submission::Piece { stage, first, count, clear, read }, seconds) => {
                                assert_eq!((stage, first), expected, "{invocations}: pieces out of order");
                                assert!(count >= 1 && first + count <= invocations);
                                assert_eq!(clear, stage == Stage::Particles && first == 0);
                                let end = first + count;
                                assert!(
                                    end == invocations || count % WORKGROUP == 0,
                                    "a ragged piece mid-stage"
                                );
                                match seconds {
                                    None => assert!(
                                        count <= PROBE_INVOCATIONS,
                                        "an unmeasured piece above the probe"
                                    ),
                                    Some(seconds) => assert!(
                                        seconds <= target * (1.0 + 1e-12)
                                            || count == WORKGROUP.min(invocations - first),
                                        "{invocations} x {per}: a piece of {count} planned at {seconds} s"
                                    ),
                                }
                                let stage_done = end == invocations;
                                assert_eq!(read, stage_done && (stage == Stage::Gather || !gather));
                                expected = match (stage_done, stage, gather) {
                                    (false, _, _) => (stage, end),
                                    (true, Stage::Particles, true) => (Stage::Gather, 0),
                                    (true, _, _) => (Stage::Particles, 0),
                                };
                            }
                        }
                    }
                }
            }
        }
    }

    /// A cheap frame goes whole, as many to a submission as fit the target and the buffers; a
    /// dear one in pieces of the target's size.
    #[test]
    fn cheap_frames_go_whole_and_dear_ones_in_pieces_of_the_target() {
        let shape = FrameShape { invocations: 57_600, gather: true, max_frames: 16 };
        let costs = Costs { frame: Some(0.02), per_invocation: [Some(1.5e-7), Some(1.5e-7)] };
        assert_eq!(
            next_submission(shape, &costs, 0.15, Cursor::FrameStart, 100),
            Submission::Frames { count: 7 }
        );
        assert_eq!(
            next_submission(shape, &costs, 10.0, Cursor::FrameStart, 100),
            Submission::Frames { count: 16 }
        );
        assert_eq!(
            next_submission(shape, &costs, 10.0, Cursor::FrameStart, 3),
            Submission::Frames { count: 3 }
        );
        assert_eq!(
            next_submission(shape, &costs, f64::INFINITY, Cursor::FrameStart, 100),
            Submission::Frames { count: 16 }
        );
        let dear = Costs { frame: Some(0.6), per_invocation: [Some(3e-7), Some(3e-7)] };
        let big = FrameShape { invocations: 921_600, ..shape };
        // 0.15 / 3e-7 = 500,000 invocations, 7812 whole workgroups.
        assert_eq!(
            next_submission(big, &dear, 0.15, Cursor::FrameStart, 16),
            Submission::Piece { stage: Stage::Particles, first: 0, count: 499_968, clear: true, read: false }
        );
        let gather_tail = Cursor::Within { stage: Stage::Gather, next: 499_968 };
        assert_eq!(
            next_submission(big, &dear, 0.15, gather_tail, 16),
            Submission::Piece {
                stage: Stage::Gather,
                first: 499_968,
                count: 421_632,
                clear: false,
                read: true
            }
        );
        // Nothing measured: the probe.
        assert_eq!(
            next_submission(big, &Costs::default(), 0.15, Cursor::FrameStart, 16),
            Submission::Piece {
                stage: Stage::Particles,
                first: 0,
                count: PROBE_INVOCATIONS,
                clear: true,
                read: false
            }
        );
        // A target of nothing (or not a number) still makes progress: one workgroup.
        for target in [0.0, f64::NAN, -1.0] {
            assert_eq!(
                next_submission(big, &dear, target, Cursor::FrameStart, 16),
                Submission::Piece {
                    stage: Stage::Particles,
                    first: 0,
                    count: WORKGROUP,
                    clear: true,
                    read: false
                }
            );
        }
    }

    /// A browser looks at its submissions once a frame and is told of their end late (Chrome
    /// on SwiftShader: about 0.16 s), and a look may be longer than the target. A submission's
    /// time as seen is then only a bound on its cost: a frame still takes a few times the looks
    /// its work and that delay fill, not one look per workgroup.
    #[test]
    fn a_caller_that_sees_work_done_late_still_traces_a_frame_in_a_few_times_its_looks() {
        // The browser test's image (156 x 136) with its gather, 0.3 s of work per stage.
        let shape = FrameShape { invocations: 156 * 136, gather: true, max_frames: 16 };
        let per = 0.3 / f64::from(shape.invocations);
        let frames = 8;
        // (seconds between looks, seconds before the end is told, target): SwiftShader's page
        // as measured, a hardware GPU's, and a page slower than the work.
        for (look, delay, target) in [(0.065, 0.16, 0.05), (0.016, 0.016, 0.05), (0.4, 0.0, 0.05)] {
            let (mut costs, mut cursor, mut done) = (Costs::default(), Cursor::FrameStart, 0);
            let (mut looks_total, mut frame_seconds) = (0u64, 0.0);
            let mut submissions = 0u32;
            while done < frames {
                assert!(looks_total < 100_000, "no end in sight at {look} s a look");
                let s = next_submission(shape, &costs, target, cursor, frames - done);
                submissions += 1;
                let work = match s {
                    Submission::Frames { count } => 2.0 * per * f64::from(shape.invocations * count),
                    Submission::Piece { count, .. } => per * f64::from(count),
                };
                let looks = ((delay + work) / look).ceil().max(1.0);
                looks_total += looks as u64;
                let seen = looks * look;
                let took = if looks == 1.0 { Took::WithinOneLook(seen) } else { Took::AtMost(seen) };
                match s {
                    Submission::Frames { count } => {
                        costs.record_frames(count, took);
                        done += count;
                    }
                    Submission::Piece { stage, count, read, .. } => {
                        costs.record_piece(stage, count, took);
                        frame_seconds += seen;
                        if read {
                            costs.record_pieced_frame(frame_seconds);
                            frame_seconds = 0.0;
                            done += 1;
                        }
                    }
                }
                cursor = s.cursor_after(shape.invocations, shape.gather);
            }
            // The looks each stage's work and the delay fill, were each stage one submission.
            let filled = f64::from(2 * frames) * ((delay + 0.3) / look).ceil();
            println!(
                "{look} s a look, told {delay} s late: {frames} frames in {submissions} submissions, \
                 {looks_total} looks; one submission a stage would take {filled}"
            );
            assert!(
                looks_total as f64 <= 5.0 * filled,
                "{frames} frames took {looks_total} looks of {look} s; their work fills {filled}"
            );
        }
    }
}
