//! Choosing how to render a scene: what `render --renderer auto` and the viewer's Auto mode
//! share. The planner ([`plan`]) is pure; [`settings`] lists what Auto chooses among and
//! applies a choice to a scene; [`regions`] and [`measure`] turn a pilot's images into the
//! planner's measurements; the [`pilot`] measures them, polled, for the command line and the
//! viewer alike.

pub mod measure;
pub mod pilot;
pub mod plan;
pub mod regions;
pub mod settings;
