//! The pilot's cache of what it measured per setting (bias, noise curve, worst region): a CSV
//! whose first line is the key it was measured under (the scene's content, the truth and every
//! pilot setting), so that a changed scene or pilot is measured again.

use std::path::Path;

use illum_auto::measure::Measured;
use illum_auto::plan::{NoiseCurve, Setting};
use illum_lab::report::{csv_text, write_text};

/// The cached measurements, if `path` holds them for exactly `key`.
pub(super) fn read_cache(path: &Path, key: &str, expected: usize) -> Option<Vec<Measured>> {
    let text = std::fs::read_to_string(path).ok()?;
    let (first, rest) = text.split_once('\n')?;
    if first.strip_prefix("# ")? != key {
        return None;
    }
    let mut reader = csv::Reader::from_reader(rest.as_bytes());
    let mut measured = Vec::new();
    for record in reader.records() {
        let record = record.ok()?;
        let number = |i: usize| record.get(i)?.parse::<f64>().ok();
        let noise = record.get(2)?;
        let region = record.get(3)?;
        measured.push(Measured {
            bias_rel_mse: number(1)?,
            noise: if noise.is_empty() { None } else { Some(parse_curve(noise)?) },
            worst_region: if region.is_empty() { None } else { Some((region.to_owned(), number(4)?)) },
        });
    }
    (measured.len() == expected).then_some(measured)
}

/// A noise curve as the cache writes it: `spp:relMSE` points separated by `;`, then `|` and the
/// exponent beyond the last point.
fn curve_text(curve: &NoiseCurve) -> String {
    let points: Vec<String> = curve.points().iter().map(|(n, v)| format!("{n:e}:{v:e}")).collect();
    format!("{}|{:e}", points.join(";"), curve.exponent())
}

fn parse_curve(text: &str) -> Option<NoiseCurve> {
    let (points, exponent) = text.split_once('|')?;
    let points = points
        .split(';')
        .map(|p| {
            let (n, v) = p.split_once(':')?;
            Some((n.parse().ok()?, v.parse().ok()?))
        })
        .collect::<Option<Vec<(f64, f64)>>>()?;
    NoiseCurve::new(points, exponent.parse().ok()?)
}

pub(super) fn write_cache(
    path: &Path,
    key: &str,
    settings: &[Setting],
    measured: &[Measured],
) -> anyhow::Result<()> {
    let rows: Vec<Vec<String>> = settings
        .iter()
        .zip(measured)
        .map(|(s, m)| {
            vec![
                s.to_string(),
                format!("{:e}", m.bias_rel_mse),
                m.noise.as_ref().map_or(String::new(), curve_text),
                m.worst_region.as_ref().map_or(String::new(), |(r, _)| r.clone()),
                m.worst_region.as_ref().map_or(String::new(), |(_, ratio)| format!("{ratio:e}")),
            ]
        })
        .collect();
    let header = ["setting", "bias_rel_mse", "noise_curve", "worst_region", "worst_region_luminance_ratio"];
    write_text(path, &format!("# {key}\n{}", csv_text(&header, &rows)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use illum_scene::{Bounces, Sequence};

    #[test]
    fn the_cache_reads_back_what_it_wrote_and_refuses_another_key() {
        let folder = std::env::temp_dir().join(format!("illum-auto-cache-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join("pilot.csv");
        let settings = [
            Setting::Whitted { depth: 8, aa: 2 },
            Setting::PathTrace {
                bounces: Bounces::Unbounded,
                caustics: true,
                sequence: Sequence::LowDiscrepancy,
                adaptive: false,
                denoise: None,
            },
        ];
        let measured = vec![
            Measured {
                bias_rel_mse: 0.06,
                noise: None,
                worst_region: Some(("floor in the glass sphere's shadow, a \"quoted\" name".into(), 0.27)),
            },
            Measured {
                bias_rel_mse: 1.5e-6,
                noise: NoiseCurve::new(vec![(64.0, 2e-3), (256.0, 3.1e-4)], 1.34),
                worst_region: None,
            },
        ];
        write_cache(&path, "key 1", &settings, &measured).unwrap();
        assert_eq!(read_cache(&path, "key 1", 2), Some(measured));
        assert_eq!(read_cache(&path, "key 2", 2), None);
        assert_eq!(read_cache(&path, "key 1", 3), None);
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
