//! WGSL literals for generated code: numbers that read back as exactly the same f32.

use glam::Vec3;

/// WGSL for an f32 literal that reads back as exactly the same f32 (Rust's `{:?}` prints the
/// shortest string that round-trips, always with a `.` or an exponent).
pub fn lit(x: f32) -> String {
    format!("{x:?}")
}

pub fn vec3(v: Vec3) -> String {
    format!("vec3<f32>({}, {}, {})", lit(v.x), lit(v.y), lit(v.z))
}

pub fn vec4(v: [f32; 4]) -> String {
    format!("vec4<f32>({}, {}, {}, {})", lit(v[0]), lit(v[1]), lit(v[2]), lit(v[3]))
}

/// The cases of `switch index` returning the k-th value for index `first + k` (the last as the
/// default, which WGSL requires; callers pass only valid indices).
///
/// A switch over literals rather than a storage-buffer read: on a CPU Vulkan driver a read at a
/// per-lane index is one scalar load per lane and component, while each case costs a few vector
/// selects (docs/performance-levers.md).
pub fn switch_cases(first: usize, values: impl ExactSizeIterator<Item = String>) -> String {
    let count = values.len();
    let mut cases = String::new();
    for (i, value) in values.enumerate() {
        if i + 1 == count {
            cases.push_str(&format!("        default: {{ return {value}; }}\n"));
        } else {
            cases.push_str(&format!("        case {}u: {{ return {value}; }}\n", first + i));
        }
    }
    cases
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn literals_read_back_as_the_same_float() {
        for x in [0.1f32, 1.0 / 3.0, 555.0, 1.0e-30, 3.0e38, -2.5e-7, f32::MIN_POSITIVE] {
            assert_eq!(lit(x).parse::<f32>().unwrap().to_bits(), x.to_bits(), "{x}");
        }
    }
}
