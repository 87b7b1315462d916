//! Choosing how to render a scene: what `render --renderer auto` and the viewer's Auto mode
//! share. The planner ([`plan`]) is pure; [`settings`] lists what Auto chooses among and
//! applies a choice to a scene; [`regions`] and [`measure`] turn a pilot's images into the
//! planner's measurements. Running the pilot is each front end's own: the CLI's blocks
//! (`illum_lab::auto::pilot`), the viewer's runs across frames.

pub mod measure;
pub mod plan;
pub mod regions;
pub mod settings;
