//! The statistics layers of a checkpoint: per pixel the f64 sum and sum of squares of each
//! channel and the u64 count, each 64-bit number stored as two 32-bit words (`hi`, `lo`), since
//! EXR has no 64-bit samples; and the checks that what is read back adds up. A low-discrepancy
//! render's layer also holds its replicates (`replicates.rs`): per replicate r the channels
//! `replicate{r}.sum.{R,G,B}.{hi,lo}` and `replicate{r}.count.{hi,lo}`, so that a resumed or
//! merged render keeps its honest error estimate.

use illum_image::U32Layer;

use super::STATISTICS_LAYER;
use crate::Accumulator;
use crate::accumulator::ExactPart;
use crate::replicates::{REPLICATES, Replicates};

const CHANNELS: [&str; 3] = ["R", "G", "B"];

fn split(bits: u64) -> (u32, u32) {
    ((bits >> 32) as u32, bits as u32)
}

fn join(hi: u32, lo: u32) -> u64 {
    (u64::from(hi) << 32) | u64::from(lo)
}

/// The statistics layer of `accumulator`.
pub fn statistics_layer(accumulator: &Accumulator) -> U32Layer {
    layer_named(STATISTICS_LAYER, accumulator)
}

pub(super) fn layer_named(name: &str, accumulator: &Accumulator) -> U32Layer {
    let state = accumulator.state();
    let mut channels = Vec::new();
    for (prefix, data) in [("sum", state.sum), ("sum_sq", state.sum_sq)] {
        for (c, name) in CHANNELS.iter().enumerate() {
            let (hi, lo): (Vec<u32>, Vec<u32>) = data.iter().map(|v| split(v[c].to_bits())).unzip();
            channels.push((format!("{prefix}.{name}.hi"), hi));
            channels.push((format!("{prefix}.{name}.lo"), lo));
        }
    }
    let (hi, lo): (Vec<u32>, Vec<u32>) = state.count.iter().map(|&n| split(n)).unzip();
    channels.push(("count.hi".to_owned(), hi));
    channels.push(("count.lo".to_owned(), lo));
    if let Some(replicates) = accumulator.replicates() {
        for r in 0..REPLICATES {
            let slots = || (r..replicates.count.len()).step_by(REPLICATES);
            for (c, name) in CHANNELS.iter().enumerate() {
                let (hi, lo): (Vec<u32>, Vec<u32>) =
                    slots().map(|i| split(replicates.sum[i][c].to_bits())).unzip();
                channels.push((format!("replicate{r}.sum.{name}.hi"), hi));
                channels.push((format!("replicate{r}.sum.{name}.lo"), lo));
            }
            let (hi, lo): (Vec<u32>, Vec<u32>) = slots().map(|i| split(replicates.count[i])).unzip();
            channels.push((format!("replicate{r}.count.hi"), hi));
            channels.push((format!("replicate{r}.count.lo"), lo));
        }
    }
    U32Layer { name: name.to_owned(), channels }
}

/// The [`super::GLINT_LAYER`] of `accumulator`: its exact part per pixel (zero elsewhere), or
/// `None` when it has none.
pub(super) fn exact_layer(accumulator: &Accumulator) -> Option<U32Layer> {
    let exact = accumulator.exact().entries();
    if exact.is_empty() {
        return None;
    }
    let pixels = accumulator.width as usize * accumulator.height as usize;
    let mut values = vec![[0.0f64; 3]; pixels];
    for &(p, v) in exact {
        values[p] = v;
    }
    let mut channels = Vec::new();
    for (c, name) in CHANNELS.iter().enumerate() {
        let (hi, lo): (Vec<u32>, Vec<u32>) = values.iter().map(|v| split(v[c].to_bits())).unzip();
        channels.push((format!("{name}.hi"), hi));
        channels.push((format!("{name}.lo"), lo));
    }
    Some(U32Layer { name: super::GLINT_LAYER.to_owned(), channels })
}

/// Reads [`exact_layer`] back: the exact part of an image of `pixels` pixels.
pub(super) fn exact_from_layer(layer: &U32Layer, pixels: usize) -> Result<ExactPart, String> {
    let values = f64_channels(layer, "", pixels)?;
    if values.iter().flatten().any(|v| !v.is_finite()) {
        return Err(format!("layer {} holds a NaN or infinite radiance: the file is corrupt", layer.name));
    }
    let entries: Vec<_> =
        values.into_iter().enumerate().filter(|(_, v)| v.iter().any(|&c| c != 0.0)).collect();
    ExactPart::new(&entries, pixels)
}

/// The channel `name` of `layer`, which must hold `pixels` values.
fn channel<'a>(layer: &'a U32Layer, name: &str, pixels: usize) -> Result<&'a Vec<u32>, String> {
    let values = layer
        .channels
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, v)| v)
        .ok_or_else(|| format!("layer {} has no channel {name}", layer.name))?;
    if values.len() != pixels {
        return Err(format!("channel {name} has {} values for {pixels} pixels", values.len()));
    }
    Ok(values)
}

/// The f64 rgb of channels `{prefix}R.hi`, `{prefix}R.lo`, ... of `layer`, per pixel.
fn f64_channels(layer: &U32Layer, prefix: &str, pixels: usize) -> Result<Vec<[f64; 3]>, String> {
    let mut out = vec![[0.0; 3]; pixels];
    for (c, name) in CHANNELS.iter().enumerate() {
        let hi = channel(layer, &format!("{prefix}{name}.hi"), pixels)?;
        let lo = channel(layer, &format!("{prefix}{name}.lo"), pixels)?;
        for (p, v) in out.iter_mut().enumerate() {
            v[c] = f64::from_bits(join(hi[p], lo[p]));
        }
    }
    Ok(out)
}

/// Rebuilds an accumulator from a statistics layer of a `width x height` image.
pub(super) fn statistics_from_layer(
    layer: &U32Layer,
    width: u32,
    height: u32,
    dropped: u64,
) -> Result<Accumulator, String> {
    let pixels = width as usize * height as usize;
    let channel = |name: String| channel(layer, &name, pixels);
    let pair = |prefix: &str| f64_channels(layer, &format!("{prefix}."), pixels);
    let sum = pair("sum")?;
    let sum_sq = pair("sum_sq")?;
    let (hi, lo) = (channel("count.hi".into())?, channel("count.lo".into())?);
    let count: Vec<u64> = hi.iter().zip(lo).map(|(&h, &l)| join(h, l)).collect();
    if sum.iter().chain(&sum_sq).flatten().any(|v| !v.is_finite()) {
        return Err("the statistics hold a NaN or infinite sum: the file is corrupt".into());
    }
    let replicates = if layer.channels.iter().any(|(n, _)| n == "replicate0.count.hi") {
        let mut replicates = Replicates::new(pixels);
        for r in 0..REPLICATES {
            let sums = pair(&format!("replicate{r}.sum"))?;
            let (hi, lo) =
                (channel(format!("replicate{r}.count.hi"))?, channel(format!("replicate{r}.count.lo"))?);
            for p in 0..pixels {
                replicates.sum[p * REPLICATES + r] = sums[p];
                replicates.count[p * REPLICATES + r] = join(hi[p], lo[p]);
            }
        }
        if replicates.sum.iter().flatten().any(|v| !v.is_finite()) {
            return Err("the replicate statistics hold a NaN or infinite sum: the file is corrupt".into());
        }
        // Each pixel's replicates hold its samples, no more and no fewer.
        for (p, (counts, &n)) in replicates.count.chunks_exact(REPLICATES).zip(&count).enumerate() {
            let total: u64 = counts.iter().sum();
            if total != n {
                return Err(format!(
                    "pixel {p}'s replicates hold {total} samples but its count is {n}: the file is corrupt"
                ));
            }
        }
        Some(replicates)
    } else {
        None
    };
    let mut accumulator = Accumulator::from_state(width, height, sum, sum_sq, count, dropped)?;
    accumulator.set_replicates(replicates)?;
    Ok(accumulator)
}

/// Checks that the per-pixel sample counts are what `spp_done` complete passes and a pass
/// stopped inside (`partial`: its spp and the rows done from row 0) give: no pixel has more,
/// and the samples missing in all are at most the dropped (NaN or infinite) ones.
pub(super) fn check_counts(
    accumulator: &Accumulator,
    spp_done: u32,
    partial: Option<(u32, u32)>,
) -> Result<(), String> {
    let width = accumulator.width as usize;
    let mut missing = 0u64;
    for p in 0..width * accumulator.height as usize {
        let row = (p / width) as u32;
        let expected = u64::from(spp_done)
            + partial.filter(|&(_, rows)| row < rows).map_or(0, |(spp, _)| u64::from(spp));
        let count = accumulator.pixel_count(p);
        if count > expected {
            return Err(format!(
                "pixel ({}, {row}) has {count} samples, more than the {expected} the metadata's spp gives: the file is \
                 corrupt or was edited",
                p % width
            ));
        }
        missing += expected - count;
    }
    if missing > accumulator.dropped_samples() {
        return Err(format!(
            "the statistics hold {missing} samples fewer than illum.spp = {spp_done} gives, and only {} were dropped: \
             the file is corrupt or was edited",
            accumulator.dropped_samples()
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact part's layer gives back every entry bit for bit, and none for an image without
    /// one.
    #[test]
    fn the_exact_layer_reads_back_exactly() {
        let mut accumulator = Accumulator::new(8, 6);
        assert!(exact_layer(&accumulator).is_none());
        let glint = vec![(3, [0.1, 1.0 / 3.0, 2e-300]), (40, [6.02e23, 0.0, 1.0]), (47, [5e-324, 0.0, 0.0])];
        accumulator.set_exact(ExactPart::new(&glint, 48).unwrap());
        let layer = exact_layer(&accumulator).expect("a glint");
        assert_eq!(layer.name, super::super::GLINT_LAYER);
        let back = exact_from_layer(&layer, 48).unwrap();
        assert_eq!(back.entries().len(), glint.len());
        for ((p, v), (q, w)) in back.entries().iter().zip(&glint) {
            assert_eq!((p, v.map(f64::to_bits)), (q, w.map(f64::to_bits)));
        }
        let mut corrupt = layer.clone();
        corrupt.channels[0].1[3] = 0x7ff0_0000; // R.hi of pixel 3: infinity
        corrupt.channels[1].1[3] = 0;
        assert!(exact_from_layer(&corrupt, 48).unwrap_err().contains("NaN or infinite"));
        assert!(exact_from_layer(&layer, 49).unwrap_err().contains("49 pixels"));
    }

    #[test]
    fn f64_and_u64_survive_the_two_word_split() {
        for v in [0.0f64, -0.0, 1.0 / 3.0, f64::MAX, f64::MIN_POSITIVE, 5e-324] {
            let (hi, lo) = split(v.to_bits());
            assert_eq!(f64::from_bits(join(hi, lo)).to_bits(), v.to_bits());
        }
        let (hi, lo) = split(u64::MAX - 7);
        assert_eq!(join(hi, lo), u64::MAX - 7);
    }
}
