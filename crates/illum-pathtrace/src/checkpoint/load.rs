//! Reading checkpoints: their headers alone (enough to check a merge), or whole, with every
//! failure naming the file and what is wrong with it.

use std::path::Path;

use illum_image::{ExrMetadata, load_u32_layers};

use super::error::with_causes;
use super::layers::{check_counts, exact_from_layer, statistics_from_layer};
use super::{ALIGNED_LAYER, Checkpoint, CheckpointError, CheckpointHeader, GLINT_LAYER, STATISTICS_LAYER};
use crate::accumulator::ExactPart;

/// A whole number in illum metadata field `field` of the file at `path`.
fn whole_number<T: std::str::FromStr>(
    path: &Path,
    metadata: &ExrMetadata,
    field: &'static str,
) -> Result<T, CheckpointError> {
    let text = metadata
        .get(field)
        .ok_or_else(|| CheckpointError::MissingField { path: path.to_path_buf(), field })?;
    text.parse().map_err(|_| CheckpointError::InvalidField {
        path: path.to_path_buf(),
        field,
        value: format!("{text:?}"),
        allowed: "must be a whole number".to_owned(),
    })
}

/// The checkpoint fields of the illum metadata of the file at `path`: a path-traced,
/// non-adaptive render with whole-number spp, start and partial pass.
fn header_fields(
    path: &Path,
    metadata: ExrMetadata,
    width: u32,
    height: u32,
) -> Result<CheckpointHeader, CheckpointError> {
    let invalid = |field: &'static str, value: String, allowed: &str| CheckpointError::InvalidField {
        path: path.to_path_buf(),
        field,
        value,
        allowed: allowed.to_owned(),
    };
    if metadata.renderer != crate::metadata::RENDERER {
        return Err(invalid(
            "renderer",
            metadata.renderer.clone(),
            "only path-traced images can be continued",
        ));
    }
    if let Some(denoiser) = metadata.get("denoiser") {
        return Err(invalid(
            "denoiser",
            denoiser.to_owned(),
            "a denoised image is not a checkpoint: it holds the denoised pixels, not the sums of the samples a \
             render goes on from, so it cannot be continued or merged (render again with a larger --spp)",
        ));
    }
    if let Some(adaptive) = metadata.get("adaptive").filter(|a| *a != "off") {
        return Err(invalid(
            "adaptive",
            format!("{adaptive:?}"),
            "must be \"off\": an adaptive render's pixels hold different numbers of samples, chosen for its \
             budget, so it cannot be continued or merged (render it again with a larger --spp)",
        ));
    }
    let spp_done = whole_number(path, &metadata, "spp")?;
    let sample_start = whole_number(path, &metadata, "sample_start")?;
    let partial: (u32, u32) = (
        whole_number(path, &metadata, "partial_pass_spp")?,
        whole_number(path, &metadata, "partial_pass_rows")?,
    );
    let partial_pass = (partial.0 > 0 && partial.1 > 0).then_some(partial);
    Ok(CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass })
}

fn unreadable(path: &Path, error: &illum_image::ImageError) -> CheckpointError {
    match error {
        illum_image::ImageError::BadContent { reason, .. } => {
            CheckpointError::NotAnExr { path: path.to_path_buf(), reason: reason.clone() }
        }
        _ => CheckpointError::Unreadable { path: path.to_path_buf(), reason: with_causes(error) },
    }
}

fn no_statistics(path: &Path) -> CheckpointError {
    CheckpointError::NoStatistics { path: path.to_path_buf(), layer: STATISTICS_LAYER }
}

/// Reads a checkpoint's headers only ([`CheckpointHeader`]): every failure of
/// [`load_checkpoint`] that the headers show (not an EXR, not illum's, not the path tracer's,
/// adaptive, a missing or unparsable key, no statistics layer), naming the file. The
/// statistics themselves are checked when the file is read whole.
pub fn load_checkpoint_header(path: &Path) -> Result<CheckpointHeader, CheckpointError> {
    if !path.exists() {
        return Err(CheckpointError::NoSuchFile { path: path.to_path_buf() });
    }
    let header = illum_image::load_exr_header(path).map_err(|e| unreadable(path, &e))?;
    let metadata = ExrMetadata::from_attributes(path, &header.attributes)
        .map_err(CheckpointError::Metadata)?
        .ok_or_else(|| CheckpointError::NotIllum { path: path.to_path_buf() })?;
    let fields = header_fields(path, metadata, header.width, header.height)?;
    if !header.layers.iter().any(|l| l == STATISTICS_LAYER) {
        return Err(no_statistics(path));
    }
    Ok(fields)
}

/// Reads a checkpoint. Every failure names the file and what is wrong with it: not an EXR,
/// truncated or corrupt (with the decoder's error), not illum's, not the path tracer's, no
/// statistics layer, a missing or unparsable key, or statistics that do not add up to the spp
/// the metadata claims.
pub fn load_checkpoint(path: &Path) -> Result<Checkpoint, CheckpointError> {
    let corrupt = |reason: String| CheckpointError::Corrupt { path: path.to_path_buf(), reason };
    let CheckpointHeader { metadata, width, height, spp_done, sample_start, partial_pass } =
        load_checkpoint_header(path)?;
    let dropped = match metadata.get("dropped_samples") {
        Some(_) => whole_number(path, &metadata, "dropped_samples")?,
        None => 0,
    };
    // The sun's glint as metadata text: the form before it had its own layer.
    if metadata.get("glint").is_some_and(|glint| glint != "none") {
        return Err(CheckpointError::OlderGlint { path: path.to_path_buf() });
    }
    // One read of the file for its layers (the mean image is recomputed from the statistics).
    let [statistics, aligned, glint] = <[Option<illum_image::U32Layer>; 3]>::try_from(
        load_u32_layers(path, &[STATISTICS_LAYER, ALIGNED_LAYER, GLINT_LAYER])
            .map_err(|e| unreadable(path, &e))?,
    )
    .expect("one entry per layer asked for");
    let statistics_of = |layer: Option<illum_image::U32Layer>| {
        layer.map(|layer| statistics_from_layer(&layer, width, height, dropped).map_err(corrupt)).transpose()
    };
    let mut accumulator = statistics_of(statistics)?.ok_or_else(|| no_statistics(path))?;
    // Samples of the low-discrepancy sequence without replicates have no error estimate.
    let estimates_error = metadata
        .get("sequence")
        .and_then(crate::TracerOptions::parse_sequence_label)
        .is_none_or(|(sequence, replicates)| {
            crate::TracerOptions { sequence, replicates, ..Default::default() }.estimates_error()
        });
    accumulator.set_estimates_error(estimates_error);
    let exact = match glint {
        Some(layer) => exact_from_layer(&layer, width as usize * height as usize)
            .map_err(|e| corrupt(format!("layer {GLINT_LAYER}: {e}")))?,
        None => ExactPart::default(),
    };
    accumulator.set_exact(exact.clone());
    check_counts(&accumulator, spp_done, partial_pass).map_err(corrupt)?;
    let aligned_prefix = match statistics_of(aligned)? {
        Some(prefix) => {
            let spp: u32 = whole_number(path, &metadata, "aligned_spp")?;
            let chunk = crate::CHUNK_SAMPLES;
            if spp > spp_done || !(sample_start + spp).is_multiple_of(chunk) {
                return Err(CheckpointError::InvalidField {
                    path: path.to_path_buf(),
                    field: "aligned_spp",
                    value: spp.to_string(),
                    allowed: format!(
                        "must be a chunk boundary (sample_start + it a multiple of {chunk}) at most illum.spp = {spp_done}"
                    ),
                });
            }
            check_counts(&prefix, spp, None).map_err(|e| corrupt(format!("layer {ALIGNED_LAYER}: {e}")))?;
            let mut prefix = prefix;
            prefix.set_exact(exact);
            prefix.set_estimates_error(estimates_error);
            Some((prefix, spp))
        }
        None => None,
    };
    Ok(Checkpoint { metadata, accumulator, spp_done, sample_start, partial_pass, aligned_prefix })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metadata(fields: &[(&str, &str)]) -> ExrMetadata {
        ExrMetadata {
            renderer: crate::metadata::RENDERER.to_owned(),
            scene: "cornell".to_owned(),
            render_seconds: 1.0,
            fields: fields.iter().map(|&(k, v)| (k.to_owned(), v.to_owned())).collect(),
        }
    }

    #[test]
    fn errors_name_the_file_the_field_the_value_and_what_is_allowed() {
        let path = Path::new("out/part.exr");
        let good =
            [("spp", "32"), ("sample_start", "0"), ("partial_pass_spp", "0"), ("partial_pass_rows", "0")];
        let header = header_fields(path, metadata(&good), 4, 4).expect("a good header");
        assert_eq!((header.spp_done, header.sample_start, header.partial_pass), (32, 0, None));

        let mut bad = good;
        bad[0].1 = "3.5";
        let error = header_fields(path, metadata(&bad), 4, 4).unwrap_err();
        assert!(
            matches!(&error, CheckpointError::InvalidField { field: "spp", value, .. } if value == "\"3.5\""),
            "{error:?}"
        );
        assert_eq!(error.to_string(), "out/part.exr: illum.spp = \"3.5\": must be a whole number");

        let error = header_fields(path, metadata(&good[1..]), 4, 4).unwrap_err();
        assert!(matches!(error, CheckpointError::MissingField { field: "spp", .. }), "{error:?}");
        assert_eq!(error.to_string(), "out/part.exr: illum.spp is missing");

        let mut raster = metadata(&good);
        raster.renderer = "raster".to_owned();
        let error = header_fields(path, raster, 4, 4).unwrap_err().to_string();
        assert_eq!(error, "out/part.exr: illum.renderer = raster: only path-traced images can be continued");

        let mut adaptive = good.to_vec();
        adaptive.push(("adaptive", "8x8 blocks"));
        let error = header_fields(path, metadata(&adaptive), 4, 4).unwrap_err().to_string();
        assert!(
            error.starts_with("out/part.exr: illum.adaptive = \"8x8 blocks\": must be \"off\""),
            "{error}"
        );

        let mut denoised = good.to_vec();
        denoised.push(("denoiser", "atrous"));
        denoised[1].1 = "0 and 2147483648 (two halves)";
        let error = header_fields(path, metadata(&denoised), 4, 4).unwrap_err().to_string();
        assert!(
            error.starts_with("out/part.exr: illum.denoiser = atrous: a denoised image is not a checkpoint"),
            "{error}"
        );

        let missing = Path::new("no/such/checkpoint.exr");
        let error = load_checkpoint(missing).unwrap_err();
        assert!(matches!(error, CheckpointError::NoSuchFile { .. }), "{error:?}");
        assert_eq!(error.to_string(), "no/such/checkpoint.exr: no such file");
        // The viewer shows errors as text.
        assert_eq!(String::from(error), "no/such/checkpoint.exr: no such file");
    }
}
