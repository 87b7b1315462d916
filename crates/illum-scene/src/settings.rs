//! Text forms of the renderer settings, shared by the scene file and the command line, so that
//! `--bounces unbounded` and `bounces = "unbounded"` mean the same and `Display` round-trips.

use std::fmt;
use std::str::FromStr;

use crate::error::ParseValueError;
use crate::renderers::{Bounces, CausticMethod, Look, MAX_BOUNCES, RendererKind, Sampling, Sequence};

/// The spelling of "no fixed depth" in files and on the command line.
pub(crate) const UNBOUNDED: &str = "unbounded";

/// What `bounces` accepts, for error messages.
pub(crate) fn bounces_allowed() -> String {
    format!("must be an integer in 0..={MAX_BOUNCES} or \"{UNBOUNDED}\"")
}

/// For each enum of fixed words: `as_str` (the name used in files and on the command line),
/// `FromStr` and `Display`, and the constant `$allowed` (its text given) that error messages
/// show.
macro_rules! named_words {
    ($($ty:ident, $allowed:ident = $allowed_text:expr, { $($variant:ident => $word:literal),+ $(,)? };)+) => {$(
        #[doc = concat!("What a `", stringify!($ty), "` accepts, for error messages.")]
        pub(crate) const $allowed: &str = $allowed_text;

        impl $ty {
            /// The name used in files and on the command line.
            pub fn as_str(self) -> &'static str {
                match self {
                    $($ty::$variant => $word,)+
                }
            }
        }

        impl FromStr for $ty {
            type Err = ParseValueError;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                match s {
                    $($word => Ok($ty::$variant),)+
                    _ => Err(ParseValueError { value: s.to_owned(), allowed: $allowed.to_owned() }),
                }
            }
        }

        impl fmt::Display for $ty {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.as_str())
            }
        }
    )+};
}

named_words! {
    Sampling, SAMPLING_ALLOWED = "must be \"cosine\" or \"uniform\"",
        { Cosine => "cosine", Uniform => "uniform" };
    Sequence, SEQUENCE_ALLOWED = "must be \"independent\" or \"low-discrepancy\"",
        { Independent => "independent", LowDiscrepancy => "low-discrepancy" };
    CausticMethod, CAUSTIC_METHOD_ALLOWED = "must be \"light-tracer\" or \"manifold\"",
        { LightTracer => "light-tracer", Manifold => "manifold" };
    Look, LOOK_ALLOWED = "must be \"figure\" or \"enhanced\"",
        { Figure => "figure", Enhanced => "enhanced" };
    RendererKind, RENDERER_ALLOWED = "must be \"raster\", \"pathtrace\" or \"whitted\"",
        { Raster => "raster", PathTrace => "pathtrace", Whitted => "whitted" };
}

impl Look {
    pub const ALL: [Look; 2] = [Look::Figure, Look::Enhanced];
}

impl FromStr for Bounces {
    type Err = ParseValueError;

    /// `"unbounded"` or a decimal integer in `0..=MAX_BOUNCES`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == UNBOUNDED {
            return Ok(Bounces::Unbounded);
        }
        match s.parse::<u32>() {
            Ok(n) if n <= MAX_BOUNCES => Ok(Bounces::Fixed(n)),
            _ => Err(ParseValueError { value: s.to_owned(), allowed: bounces_allowed() }),
        }
    }
}

impl fmt::Display for Bounces {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Bounces::Fixed(n) => write!(f, "{n}"),
            Bounces::Unbounded => f.write_str(UNBOUNDED),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounces_parse_and_round_trip() {
        assert_eq!("0".parse::<Bounces>(), Ok(Bounces::Fixed(0)));
        assert_eq!("2".parse::<Bounces>(), Ok(Bounces::Fixed(2)));
        assert_eq!("256".parse::<Bounces>(), Ok(Bounces::Fixed(256)));
        assert_eq!("unbounded".parse::<Bounces>(), Ok(Bounces::Unbounded));
        for b in [Bounces::Fixed(0), Bounces::Fixed(17), Bounces::Unbounded] {
            assert_eq!(b.to_string().parse::<Bounces>(), Ok(b));
        }
        assert_eq!(Bounces::Fixed(3).to_string(), "3");
        assert_eq!(Bounces::Unbounded.to_string(), "unbounded");
    }

    #[test]
    fn bounces_rejects_with_the_allowed_forms() {
        for bad in ["257", "-1", "2.5", "", "Unbounded", "infinite", "99999999999"] {
            let err = bad.parse::<Bounces>().unwrap_err();
            assert_eq!(err.value, bad);
            let text = err.to_string();
            assert!(text.contains(&format!("{bad:?}")), "{text}");
            assert!(text.contains("0..=256"), "{text}");
            assert!(text.contains("\"unbounded\""), "{text}");
        }
    }

    #[test]
    fn sampling_parse_and_round_trip() {
        assert_eq!("cosine".parse::<Sampling>(), Ok(Sampling::Cosine));
        assert_eq!("uniform".parse::<Sampling>(), Ok(Sampling::Uniform));
        for s in [Sampling::Cosine, Sampling::Uniform] {
            assert_eq!(s.to_string().parse::<Sampling>(), Ok(s));
        }
        let err = "importance".parse::<Sampling>().unwrap_err();
        let text = err.to_string();
        assert!(text.contains("\"importance\""), "{text}");
        assert!(text.contains("\"cosine\"") && text.contains("\"uniform\""), "{text}");
    }

    #[test]
    fn look_sequence_and_renderer_round_trip_and_reject_other_words() {
        for look in Look::ALL {
            assert_eq!(look.to_string().parse::<Look>(), Ok(look));
        }
        for seq in [Sequence::Independent, Sequence::LowDiscrepancy] {
            assert_eq!(seq.to_string().parse::<Sequence>(), Ok(seq));
        }
        for kind in RendererKind::ALL {
            assert_eq!(kind.to_string().parse::<RendererKind>(), Ok(kind));
        }
        // "whitted" names the Whitted ray tracer only, never a raster look; the refusal names
        // the look a file meant by it ("enhanced").
        let err = "whitted".parse::<Look>().unwrap_err();
        assert!(err.to_string().contains("\"enhanced\""), "{err}");
        assert!("sobol".parse::<Sequence>().unwrap_err().to_string().contains("low-discrepancy"));
        assert!("opengl".parse::<RendererKind>().unwrap_err().to_string().contains("\"pathtrace\""));
    }
}
