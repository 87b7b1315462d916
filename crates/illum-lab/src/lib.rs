//! illum-lab: what the measuring tools (the `ladder`, `convergence` and `auto_check` examples)
//! share: the cached path-traced [`reference`](mod@reference) they compare with, the ladder's
//! [`regions`] and errors (relMSE, luminance ratio, FLIP), a setting of Auto's rendered as
//! `render` would ([`auto`]), [`plot`]s, [`report`] tables and the figures' labelled
//! [`contact_sheet`]s. Kept out of the renderer crates and the `illum` facade so that a
//! renderer's users (the wasm viewer among them) do not link plotters, csv, FLIP or a font.

pub mod auto;
pub mod contact_sheet;
pub mod plot;
pub mod reference;
pub mod regions;
pub mod report;
