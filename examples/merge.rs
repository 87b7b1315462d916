//! Merges partial path-traced renders into one image.
//!
//! ```text
//! cargo run --release --example merge -- IN.exr... -o OUT.exr
//! ```
//! Each input is an EXR written by `render --sample-range A..B` (or a merge of such files): the
//! same scene and settings, sample ranges that together cover one range with no overlap and no
//! gap, each starting on a multiple of 16. The output holds the union, as one render of it would
//! (within 1e-12 relative per pixel: see `illum_pathtrace::checkpoint`), and can itself be resumed
//! (`render --resume`) or merged again. A mismatch is refused, naming the files and what differs.

use std::path::PathBuf;

use clap::Parser;
use illum::pathtrace::checkpoint::{merge_checkpoint_files, save_loaded};

/// Parts listed by name in the summary; more are counted, with the first and the last named.
const LISTED: usize = 8;

#[derive(Parser, Debug)]
#[command(about = "Merge partial path-traced renders (render --sample-range A..B) into one EXR")]
struct Args {
    /// Partial renders (EXR files written by the render example).
    #[arg(required = true, value_name = "IN.exr")]
    inputs: Vec<PathBuf>,
    /// The merged EXR (also a checkpoint: it can be resumed or merged again).
    #[arg(short = 'o', long = "output", value_name = "OUT.exr")]
    output: PathBuf,
}

fn main() {
    illum_cli::main_with(run);
}

fn run(args: Args) -> anyhow::Result<()> {
    if illum_cli::output_format(&args.output)? != illum_cli::OutputFormat::Exr {
        anyhow::bail!("output {}: the merge writes an EXR (.exr)", args.output.display());
    }
    illum::image::check_output(&args.output)?;
    // The parts are read one at a time (all headers first, to refuse a bad set before any is
    // read whole), so the merge holds one part and the running total, whatever their number.
    let mut ranges = Vec::new();
    let merged = merge_checkpoint_files(&args.inputs, |path, part| {
        let range = part.sample_range();
        ranges.push(format!("{} ({}..{})", path.display(), range.start, range.end));
    })
    .map_err(anyhow::Error::msg)?;
    save_loaded(&args.output, &merged).map_err(anyhow::Error::msg)?;
    let parts = if ranges.len() <= LISTED {
        ranges.join(", ")
    } else {
        format!("{} parts: {}, ..., {}", ranges.len(), ranges[0], ranges[ranges.len() - 1])
    };
    println!(
        "merged {parts}: samples {}..{} ({} spp), estimated relative error {:.4}, dropped samples {}",
        merged.sample_range().start,
        merged.sample_range().end,
        merged.spp_done,
        merged.accumulator.estimated_relative_error(),
        merged.accumulator.dropped_samples()
    );
    println!("wrote {}", args.output.display());
    Ok(())
}
