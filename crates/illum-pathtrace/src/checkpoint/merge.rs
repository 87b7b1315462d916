//! Merging partial renders (files from `render --sample-range`) into one: what is refused, and
//! the order the parts are added in (see the parent module for why the result equals one
//! render up to f64 rounding).

use std::path::{Path, PathBuf};

use super::settings::shown;
use super::{Checkpoint, CheckpointError, CheckpointHeader, load_checkpoint, load_checkpoint_header};

/// The keys two partial renders must agree on to be merged. The scene is known by its content
/// (`scene_hash`), not its name, as a resumed render's is.
const MERGE_KEYS: [&str; 10] = [
    "scene_hash",
    "width",
    "height",
    "bounces",
    "seed",
    "sampling",
    "sequence",
    "caustics",
    crate::metadata::ESTIMATORS,
    "glint_hash",
];

/// Checks that partial renders can be merged, from their headers alone, and sorts them into
/// sample order (the order the merge adds them in). Refused, with the files named: a file
/// stopped inside a pass or stopped early (resume it first: the message gives the command), a
/// range not starting on a chunk, a setting that differs, overlapping ranges (the same samples
/// twice would count double) and gaps (the result would not be one range that can be
/// continued). Returns the merged spp.
fn check_mergeable<T>(parts: &mut [(PathBuf, CheckpointHeader, T)]) -> Result<u32, CheckpointError> {
    if parts.is_empty() {
        return Err(CheckpointError::NothingToMerge);
    }
    for (path, c, _) in parts.iter() {
        let range = c.sample_range();
        let resume = || match c.metadata.get(crate::metadata::SAMPLE_END) {
            Some(end) => format!(
                "finish it first with `render SCENE.toml --resume {} --sample-range {}..{end}`",
                path.display(),
                range.start
            ),
            None => format!(
                "finish it first with `render SCENE.toml --resume {} --sample-range {}..END` (END: the end of its range)",
                path.display(),
                range.start
            ),
        };
        if let Some((spp, rows)) = c.partial_pass {
            return Err(CheckpointError::Unfinished {
                path: path.clone(),
                reason: format!(
                    "stopped inside a pass ({rows} rows of {spp} spp done after {} complete spp)",
                    c.spp_done
                ),
                finish: resume(),
            });
        }
        if c.spp_done == 0 {
            return Err(CheckpointError::NoCompletePass { path: path.clone() });
        }
        if let Some(reason @ ("cancelled" | "time_budget")) = c.metadata.get("stopped_by") {
            return Err(CheckpointError::Unfinished {
                path: path.clone(),
                reason: format!(
                    "stopped early (illum.stopped_by = {reason}) at sample {} of its range, so it may not hold the \
                     whole range",
                    range.end
                ),
                finish: resume(),
            });
        }
        // Parts must name their estimators by this build's tokens (compared between the parts
        // below): a part of an older form holds light of unknown estimators.
        let (stored, legacy) =
            (c.metadata.get(crate::metadata::ESTIMATORS), c.metadata.get(crate::metadata::LEGACY_ESTIMATORS));
        if let Err(mismatch) = crate::estimators::stored_tokens(stored, legacy) {
            return Err(CheckpointError::OlderEstimators {
                path: path.clone(),
                reason: mismatch.to_string(),
            });
        }
        if !range.start.is_multiple_of(u64::from(crate::CHUNK_SAMPLES)) {
            return Err(CheckpointError::OffChunk {
                path: path.clone(),
                start: range.start,
                chunk: crate::CHUNK_SAMPLES,
            });
        }
    }
    let (first_path, first, _) = &parts[0];
    for (path, c, _) in &parts[1..] {
        let differences: Vec<String> = MERGE_KEYS
            .iter()
            .filter_map(|key| {
                let (a, b) = (first.setting(key), c.setting(key));
                (a != b).then(|| {
                    let (a, b) = (shown(a.as_deref()), shown(b.as_deref()));
                    let (a_path, b_path) = (first_path.display(), path.display());
                    if *key == "scene_hash" {
                        let (a_name, b_name) = (&first.metadata.scene, &c.metadata.scene);
                        format!("{key}: {a} ({a_name:?}) in {a_path}, {b} ({b_name:?}) in {b_path}")
                    } else {
                        format!("{key}: {a} in {a_path}, {b} in {b_path}")
                    }
                })
            })
            .collect();
        if !differences.is_empty() {
            return Err(CheckpointError::DifferentImages { differences });
        }
    }
    parts.sort_by_key(|(_, c, _)| c.sample_start);
    for pair in parts.windows(2) {
        let ((pa, a, _), (pb, b, _)) = (&pair[0], &pair[1]);
        let (ra, rb) = (a.sample_range(), b.sample_range());
        if rb.start < ra.end {
            return Err(CheckpointError::Overlap {
                first: pa.clone(),
                first_range: ra,
                second: pb.clone(),
                second_range: rb,
            });
        }
        if rb.start > ra.end {
            return Err(CheckpointError::Gap {
                before: pa.clone(),
                after: pb.clone(),
                missing: ra.end..rb.start,
            });
        }
    }
    let total = parts.iter().map(|(_, c, _)| u64::from(c.spp_done)).sum::<u64>();
    u32::try_from(total).map_err(|_| CheckpointError::TooManySamples { total })
}

/// Adds checked parts (in sample order) one at a time: per pixel, the f64 sums and counts in
/// the order of their ranges, so that only the running total and the part being added are in
/// memory. The merged metadata is the first part's, with the union's spp, the summed times and
/// dropped samples, and the error of the merged statistics.
fn fold_parts(
    parts: impl ExactSizeIterator<Item = Result<Checkpoint, CheckpointError>>,
    spp_done: u32,
) -> Result<Checkpoint, CheckpointError> {
    let last = parts.len() - 1;
    let mut merged: Option<Checkpoint> = None;
    let mut aligned_prefix = None;
    for (i, part) in parts.enumerate() {
        let part = part?;
        if i == last {
            // Every range but the last ends where the next starts, on a chunk boundary; the last
            // may end inside a chunk, and then its statistics at its last boundary, added to the
            // others' (in the same order as the merge), are the merged render's (what
            // `render --resume` goes on from).
            aligned_prefix = part.aligned_prefix.as_ref().map(|(prefix, spp)| match &merged {
                Some(earlier) => {
                    let mut sum = earlier.accumulator.clone();
                    sum.merge(prefix);
                    (sum, earlier.spp_done + spp)
                }
                None => (prefix.clone(), *spp),
            });
        }
        match &mut merged {
            None => merged = Some(part),
            Some(merged) => {
                merged.accumulator.merge(&part.accumulator);
                merged.metadata.render_seconds += part.metadata.render_seconds;
                merged.spp_done += part.spp_done;
            }
        }
    }
    let mut merged = merged.expect("at least one part (checked)");
    merged.spp_done = spp_done;
    merged.aligned_prefix = aligned_prefix;
    let accumulator = &merged.accumulator;
    let union_end = u64::from(merged.sample_start) + u64::from(spp_done);
    for (key, value) in [
        (crate::metadata::SAMPLE_END, union_end.to_string()),
        ("spp", spp_done.to_string()),
        ("estimated_relative_error", accumulator.estimated_relative_error().to_string()),
        ("dropped_samples", accumulator.dropped_samples().to_string()),
        ("stopped_by", "spp".to_owned()),
        ("source", "merge example".to_owned()),
    ] {
        match merged.metadata.fields.iter_mut().find(|(k, _)| k == key) {
            Some(field) => field.1 = value,
            None => merged.metadata.fields.push((key.to_owned(), value)),
        }
    }
    Ok(merged)
}

/// Combines partial renders of the same scene and settings (files from `render --sample-range`)
/// into one, all already in memory: see [`merge_checkpoint_files`], which reads them one at a
/// time, for what is refused and how they are added.
pub fn merge_checkpoints(inputs: Vec<(PathBuf, Checkpoint)>) -> Result<Checkpoint, CheckpointError> {
    let mut parts: Vec<_> = inputs.into_iter().map(|(path, c)| (path, c.header(), c)).collect();
    let spp_done = check_mergeable(&mut parts)?;
    fold_parts(parts.into_iter().map(|(_, _, c)| Ok(c)), spp_done)
}

/// Merges the partial renders in `paths` into one, holding one part and the running total in
/// memory, never all parts (256 parts of a 1024 x 1024 render are 14 GB of statistics). First
/// every file's headers are read and checked together ([`check_mergeable`]: nothing is read in
/// full if, say, the last file is of another scene); then the files are read and added in
/// sample order, each checked whole ([`load_checkpoint`]) and against what its header said.
/// `on_part` is called with each file as it is added (progress for a long merge).
pub fn merge_checkpoint_files(
    paths: &[PathBuf],
    mut on_part: impl FnMut(&Path, &CheckpointHeader),
) -> Result<Checkpoint, CheckpointError> {
    let mut parts = Vec::with_capacity(paths.len());
    for path in paths {
        parts.push((path.clone(), load_checkpoint_header(path)?, ()));
    }
    let spp_done = check_mergeable(&mut parts)?;
    let loaded = parts.into_iter().map(|(path, header, ())| {
        let part = load_checkpoint(&path)?;
        if part.header() != header {
            return Err(CheckpointError::Changed { path });
        }
        on_part(&path, &header);
        Ok(part)
    });
    fold_parts(loaded, spp_done)
}

#[cfg(test)]
mod tests {
    use illum_image::ExrMetadata;

    use super::*;

    fn header(scene: &str, hash: &str, glint: String, sample_start: u32) -> CheckpointHeader {
        let fields = [
            ("scene_hash", hash.to_owned()),
            ("bounces", "8".to_owned()),
            ("seed", "1".to_owned()),
            ("glint_hash", glint),
            ("stopped_by", "spp".to_owned()),
            // The estimators of a scene with no caustic: both parts name them alike.
            (crate::metadata::ESTIMATORS, "estimators.v1 camera-paths".to_owned()),
        ];
        CheckpointHeader {
            metadata: ExrMetadata {
                renderer: crate::metadata::RENDERER.to_owned(),
                scene: scene.to_owned(),
                render_seconds: 1.0,
                fields: fields.into_iter().map(|(k, v)| (k.to_owned(), v)).collect(),
            },
            width: 4,
            height: 4,
            spp_done: 16,
            sample_start,
            partial_pass: None,
        }
    }

    /// Parts of two scenes: the refusal names each key that differs, with a value too long to
    /// show whole shortened (here an edited file's), and no key that agrees.
    #[test]
    fn parts_of_different_scenes_are_refused_naming_only_the_differing_keys_shortened() {
        let mut parts = vec![
            (
                PathBuf::from("a.exr"),
                header("whitted", "00000000000000aa", "0123456789abcdef".to_owned(), 0),
                (),
            ),
            (PathBuf::from("b.exr"), header("cornell", "00000000000000bb", "none".to_owned(), 16), ()),
        ];
        let error = check_mergeable(&mut parts).unwrap_err().to_string();
        for part in [
            "scene_hash: 00000000000000aa (\"whitted\") in a.exr, 00000000000000bb (\"cornell\") in b.exr",
            "glint_hash: 0123456789abcdef in a.exr, none in b.exr",
        ] {
            assert!(error.contains(part), "the refusal lacks {part:?}: {error}");
        }
        assert!(!error.contains("bounces") && !error.contains("seed"), "keys that agree: {error}");
        parts[1].1 = header("whitted", "00000000000000aa", "x".repeat(3000), 16);
        let error = check_mergeable(&mut parts).unwrap_err().to_string();
        assert!(error.contains("... (3000 characters) in b.exr"), "{error}");
        assert!(error.len() < 600, "{} characters: {error}", error.len());
    }

    /// The scene is known by its content: parts of one scene under two names merge.
    #[test]
    fn parts_of_one_scene_under_two_names_merge() {
        let mut parts = vec![
            (PathBuf::from("a.exr"), header("cornell", "00000000000000aa", "none".to_owned(), 0), ()),
            (
                PathBuf::from("b.exr"),
                header("cornell-renamed", "00000000000000aa", "none".to_owned(), 16),
                (),
            ),
        ];
        assert_eq!(check_mergeable(&mut parts).map_err(|e| e.to_string()), Ok(32));
    }
}
