//! The `render` example's `--renderer` value: one of the renderers, or `auto` (the planner of
//! `illum_lab::auto` chooses the renderer and its settings), and what `auto` refuses.

use std::fmt;
use std::str::FromStr;

use illum_scene::RendererKind;

/// `--renderer pathtrace|raster|whitted|auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RendererChoice {
    Kind(RendererKind),
    Auto,
}

impl FromStr for RendererChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(RendererChoice::Auto);
        }
        s.parse::<RendererKind>().map(RendererChoice::Kind).map_err(|_| {
            format!("{s:?} is not a renderer: must be \"pathtrace\", \"raster\", \"whitted\" or \"auto\"")
        })
    }
}

impl fmt::Display for RendererChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RendererChoice::Kind(kind) => kind.fmt(f),
            RendererChoice::Auto => f.write_str("auto"),
        }
    }
}

/// What `--renderer auto` is asked for: one of `--target-error` and `--time-budget`, and none
/// of the flags that choose what it chooses (`chosen`: the names of those given).
pub fn check_auto_flags(
    target_error: Option<f64>,
    time_budget: Option<std::time::Duration>,
    chosen: &[&str],
) -> Result<(), String> {
    if !chosen.is_empty() {
        return Err(format!(
            "--renderer auto chooses the renderer and its settings itself, so {} cannot be given with it \
             (name a renderer with --renderer to set {})",
            chosen.join(", "),
            if chosen.len() == 1 { "it" } else { "them" }
        ));
    }
    match (target_error, time_budget) {
        (Some(_), None) | (None, Some(_)) => Ok(()),
        (None, None) => Err("--renderer auto needs a goal: --target-error E (the fastest render predicted to \
                             reach a relative error of E) or --time-budget S (the most accurate predicted \
                             to finish within S seconds)"
            .to_owned()),
        (Some(_), Some(_)) => Err("--renderer auto takes one goal: --target-error or --time-budget, not both \
                                   (it picks the fastest render for an error, or the most accurate for a time)"
            .to_owned()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_and_every_renderer_parse_and_anything_else_is_refused_by_name() {
        assert_eq!("auto".parse(), Ok(RendererChoice::Auto));
        for kind in RendererKind::ALL {
            assert_eq!(kind.to_string().parse(), Ok(RendererChoice::Kind(kind)));
            assert_eq!(RendererChoice::Kind(kind).to_string(), kind.to_string());
        }
        let error = "opengl".parse::<RendererChoice>().unwrap_err();
        assert!(error.contains("\"opengl\"") && error.contains("\"auto\""), "{error}");
    }

    #[test]
    fn auto_needs_exactly_one_goal_and_none_of_the_settings_it_chooses() {
        let second = Some(std::time::Duration::from_secs(1));
        assert!(check_auto_flags(Some(0.1), None, &[]).is_ok());
        assert!(check_auto_flags(None, second, &[]).is_ok());
        assert!(check_auto_flags(None, None, &[]).unwrap_err().contains("needs a goal"));
        assert!(check_auto_flags(Some(0.1), second, &[]).unwrap_err().contains("not both"));
        let error = check_auto_flags(Some(0.1), None, &["--spp", "--depth"]).unwrap_err();
        assert!(error.contains("--spp, --depth cannot be given"), "{error}");
    }
}
