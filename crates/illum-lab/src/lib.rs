//! illum-lab: what the measuring tools (the `ladder` and `convergence` examples) share: the
//! cached path-traced [`reference`](mod@reference) they compare with, the ladder's [`regions`]
//! and errors (relMSE, luminance ratio, FLIP), [`plot`]s and [`report`] tables. Kept out of the
//! renderer crates and the `illum` facade so that a renderer's users do not link plotters, csv
//! or FLIP.

pub mod auto;
pub mod plot;
pub mod reference;
pub mod regions;
pub mod report;
