//! Adaptive sampling (crates/illum-pathtrace/src/allocation.rs): every pixel takes exactly its
//! block's samples, whatever the passes and bands; the image stays unbiased (per-pixel Z-test
//! against the f64 oracle, with the oracle test's power checks); the pilot moves samples to
//! where the noise is; and what cannot work is refused.

use illum_pathtrace::allocation::{BLOCK, plan_adaptive};
use illum_pathtrace::{PathTraceError, PathTracer, SampleAllocation, Sequence, TracerOptions};
use illum_scene::{Bounces, Overrides, Sampling};

use crate::common;
use crate::oracle_agreement;

/// An allocation with counts that are not multiples of the chunk, on an image whose last row
/// and column of blocks are cut: after a render to its largest count, each pixel holds its
/// block's count, with passes of every size and bands of a few rows.
#[test]
fn every_pixel_takes_its_blocks_samples() {
    let (width, height) = (3 * BLOCK + 5, 2 * BLOCK + 3);
    let scene = common::scene(
        "cornell",
        Overrides { bounces: Some(Bounces::Fixed(1)), seed: Some(5), ..common::small(width, height, 1) },
    );
    let counts = [1, 7, 16, 40, 23, 3, 64, 2, 17, 33, 5, 48];
    let allocation = SampleAllocation { width, height, samples: counts.to_vec() };
    let expected_total = allocation.total();
    for (label, sequence, tiny_bands) in [
        ("independent, whole passes", Sequence::Independent, false),
        ("low-discrepancy, bands of one row", Sequence::LowDiscrepancy, true),
    ] {
        let mut tracer =
            PathTracer::with_options(common::gpu(), &scene, TracerOptions { sequence, ..Default::default() })
                .expect("tracer");
        tracer.set_chunk_aligned_passes(true);
        if tiny_bands {
            // One row of one chunk: its slot layers, one per replicate for the low-discrepancy
            // sequence (src/batch.rs, `Layers`).
            let layers = if sequence == Sequence::LowDiscrepancy {
                illum_pathtrace::replicates::REPLICATES
            } else {
                1
            };
            let row = u64::from(width) * illum_pathtrace::SLOT_BYTES * layers as u64;
            tracer.limit_batch_bytes(row).expect("one row fits");
        }
        tracer.set_sample_allocation(Some(allocation.clone())).expect("allocation fits");
        tracer.render_to_spp(allocation.max()).expect("render");
        let acc = tracer.accumulator();
        for y in 0..height {
            for x in 0..width {
                let p = (y * width + x) as usize;
                assert_eq!(
                    acc.pixel_count(p),
                    u64::from(allocation.at(x, y)),
                    "{label}: pixel ({x}, {y}) of block {}",
                    (y / BLOCK) * 4 + x / BLOCK
                );
            }
        }
        assert_eq!(acc.total_samples(), expected_total, "{label}");
        assert_eq!(tracer.spp_done(), 64, "{label}: the render ends at the largest count");
        // Turning it off gives every pixel every sample again, from a fresh start.
        tracer.set_sample_allocation(None).expect("off");
        tracer.add_samples_in_one_pass(3).expect("render");
        assert_eq!(tracer.accumulator().total_samples(), u64::from(width * height) * 3, "{label}, off");
    }
}

/// A tracer built with its allocation (`PathTracer::with_sample_allocation`, one compilation)
/// is the tracer switched to it after construction: the same pipeline, the same image bit for
/// bit; and it refuses an allocation of another size as `set_sample_allocation` does.
#[test]
fn a_tracer_built_adaptive_is_one_switched_to_adaptive() {
    let (width, height) = (2 * BLOCK, 2 * BLOCK);
    let scene = common::scene("cornell", Overrides { seed: Some(9), ..common::small(width, height, 1) });
    let allocation = SampleAllocation { width, height, samples: vec![16, 48, 32, 7] };
    let options = TracerOptions { sequence: Sequence::LowDiscrepancy, ..Default::default() };
    let mut switched = PathTracer::with_options(common::gpu(), &scene, options).expect("tracer");
    switched.set_sample_allocation(Some(allocation.clone())).expect("allocation fits");
    let mut built = PathTracer::with_sample_allocation(common::gpu(), &scene, options, allocation.clone())
        .expect("tracer");
    assert!(built.shares_pipeline_with(&switched), "one adaptive pipeline, from the context's cache");
    assert_eq!(built.sample_allocation(), Some(&allocation));
    for tracer in [&mut switched, &mut built] {
        tracer.render_to_spp(allocation.max()).expect("render");
    }
    let (a, b) = (switched.accumulator(), built.accumulator());
    assert_eq!(a.total_samples(), allocation.total());
    for p in 0..(width * height) as usize {
        assert_eq!(a.pixel_count(p), b.pixel_count(p), "pixel {p}");
        assert_eq!(a.pixel_mean(p), b.pixel_mean(p), "pixel {p}");
    }
    let wrong = SampleAllocation::uniform(width + 1, height, 16);
    let refused = PathTracer::with_sample_allocation(common::gpu(), &scene, options, wrong)
        .err()
        .expect("another size is refused")
        .to_string();
    assert!(refused.contains("17 x 16"), "{refused}");
}

/// The pilot's allocation on the Cornell box: within the budget, every block at least one chunk,
/// the noisy ceiling (top rows, lit only by interreflection) given more samples than the
/// directly lit floor and walls below.
#[test]
fn the_pilot_spends_the_budget_where_the_noise_is() {
    let scene = common::cornell(64, 256, Bounces::Fixed(2), Sampling::Cosine, 3);
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("tracer");
    let allocation = plan_adaptive(&mut tracer, 256).expect("pilot");
    assert_eq!(tracer.accumulator().total_samples(), 0, "the pilot's samples are discarded");
    assert!(allocation.total() <= 64 * 64 * 256, "{}", allocation.describe());
    assert!(allocation.total() >= 64 * 64 * 240, "nearly all the budget: {}", allocation.describe());
    assert!(allocation.min() >= illum_pathtrace::CHUNK_SAMPLES);
    // Rows of blocks: 0 to 2 hold the ceiling (and the light), 5 to 7 the floor and the blocks.
    let (bx, _) = SampleAllocation::blocks(64, 64);
    let row_mean = |j: u32| {
        let row = &allocation.samples[(j * bx) as usize..((j + 1) * bx) as usize];
        row.iter().map(|&n| f64::from(n)).sum::<f64>() / row.len() as f64
    };
    println!(
        "allocation {}; block rows: {:?}",
        allocation.describe(),
        (0..8).map(row_mean).collect::<Vec<_>>()
    );
    assert!(row_mean(1) > 1.3 * row_mean(5), "ceiling {} against floor {}", row_mean(1), row_mean(5));
    assert!(allocation.min() < 256 && allocation.max() > 2 * 256, "{}", allocation.describe());
}

/// The adaptive image agrees with the oracle pixel by pixel (a pixel's count is independent of
/// the samples it averages, so no bias), with the same test and power checks as a uniform render.
#[test]
fn an_adaptive_render_agrees_with_the_oracle() {
    for sequence in [Sequence::Independent, Sequence::LowDiscrepancy] {
        let scene = oracle_agreement::scene("cornell", 2);
        let mut tracer =
            PathTracer::with_options(common::gpu(), &scene, TracerOptions { sequence, ..Default::default() })
                .expect("tracer");
        let allocation = plan_adaptive(&mut tracer, scene.pathtrace.spp).expect("pilot");
        assert!(
            allocation.min() < allocation.max(),
            "the test needs uneven counts: {}",
            allocation.describe()
        );
        tracer.render_to_spp(allocation.max()).expect("render");
        oracle_agreement::compare_render(&format!("adaptive, {sequence}"), &tracer, 4096);
    }
}

/// Refusals: another resolution, a block with no samples, the caustic's light tracer.
#[test]
fn what_adaptive_sampling_cannot_do_is_refused() {
    let scene = common::cornell(16, 4, Bounces::Fixed(1), Sampling::Cosine, 1);
    let mut tracer = PathTracer::new(common::gpu(), &scene).expect("tracer");
    let message = |r: Result<(), PathTraceError>| r.expect_err("refused").to_string();
    let other = message(tracer.set_sample_allocation(Some(SampleAllocation::uniform(24, 16, 4))));
    assert!(other.contains("24 x 16") && other.contains("16 x 16"), "{other}");
    let mut empty = SampleAllocation::uniform(16, 16, 4);
    empty.samples[3] = 0;
    let none = message(tracer.set_sample_allocation(Some(empty)));
    assert!(none.contains("block 3") && none.contains("at least one"), "{none}");
    let mut whitted = common::scene("whitted", common::small(16, 16, 4));
    whitted.pathtrace.caustics = true;
    let mut caustic = PathTracer::new(common::gpu(), &whitted).expect("tracer");
    assert!(caustic.caustics(), "the test needs the caustic's light tracer");
    let refused = message(caustic.set_sample_allocation(Some(SampleAllocation::uniform(16, 16, 4))));
    assert!(refused.contains("caustic"), "{refused}");
}
