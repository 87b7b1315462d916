//! How errors spell values: numbers, vectors and keys as the TOML file would write them, so
//! that an error quotes the value the way the user typed it.

use glam::Vec3;

/// A number as TOML would spell it: `nan`, `inf`, exponent form for very large or small
/// magnitudes, else Rust's shortest round-trip decimal.
pub(crate) fn fmt_num(x: f64) -> String {
    if x.is_nan() {
        "nan".to_owned()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_owned()
    } else if x != 0.0 && !(1e-5..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

pub(crate) fn fmt_vec(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]))
}

/// An f32 in its own shortest form (0.5608, not 0.5608000159263611), by the same rules as
/// `fmt_num`: how errors show a number that validation has already converted.
pub fn fmt_f32(x: f32) -> String {
    if x.is_finite() && (x == 0.0 || (1e-5..1e16).contains(&x.abs())) {
        x.to_string()
    } else if x.is_finite() {
        format!("{x:e}")
    } else {
        fmt_num(f64::from(x))
    }
}

/// A vector of f32s, each as [`fmt_f32`] shows it.
pub(crate) fn fmt_vec32(v: Vec3) -> String {
    format!("[{}, {}, {}]", fmt_f32(v.x), fmt_f32(v.y), fmt_f32(v.z))
}

/// A TOML key as it would be written in a dotted path: bare if it can be, quoted otherwise.
pub fn toml_key(name: &str) -> String {
    let bare = !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare { name.to_owned() } else { format!("{name:?}") }
}

/// How errors name object `i`: `objects[3] ("tall block")`, or `objects[3]` without a name.
pub(crate) fn object_label(i: usize, name: Option<&str>) -> String {
    match name {
        Some(name) => format!("objects[{i}] ({name:?})"),
        None => format!("objects[{i}]"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_formatting_uses_toml_spellings() {
        assert_eq!(fmt_num(f64::NAN), "nan");
        assert_eq!(fmt_num(f64::INFINITY), "inf");
        assert_eq!(fmt_num(f64::NEG_INFINITY), "-inf");
        assert_eq!(fmt_num(278.0), "278");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(1e39), "1e39");
        assert_eq!(fmt_num(-2.5e-7), "-2.5e-7");
        assert_eq!(fmt_vec([1.0, -724.26, 0.5]), "[1, -724.26, 0.5]");
        assert_eq!(fmt_vec32(Vec3::new(0.5608, 1.0, f32::NAN)), "[0.5608, 1, nan]");
    }

    #[test]
    fn keys_are_quoted_only_when_needed() {
        assert_eq!(toml_key("red"), "red");
        assert_eq!(toml_key("light-2_b"), "light-2_b");
        assert_eq!(toml_key("my red"), "\"my red\"");
        assert_eq!(toml_key("a.b"), "\"a.b\"");
        assert_eq!(toml_key(""), "\"\"");
    }
}
