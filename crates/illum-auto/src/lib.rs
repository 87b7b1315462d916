//! Choosing how to render a scene: the planner that `render --renderer auto` and the viewer's
//! Auto mode share. It is pure (no GPU, no files): the measurements come from a pilot, which
//! each front end runs its own way (the CLI blocking, the viewer across frames).

pub mod plan;
