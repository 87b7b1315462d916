//! The terms of the filter's edge stops that the GPU filter (`shaders/atrous.wgsl`), its f64
//! reference (`reference.rs`) and the variance spread (`spread.rs`) all compute: the normals as
//! the filter reads them, the normal stop, and the shader's constants.

/// The shader's constants (its `NORMAL_SQUARINGS` and `TINY`; tested to agree).
pub const NORMAL_POWER: i32 = 128;
pub const TINY: f64 = 1.0e-10;
/// A mean normal shorter than this is "no normal" (the pixel's rays left the scene).
pub const NO_NORMAL: f32 = 1.0e-3;

/// The normals as the filter reads them: unit vectors with w = 1, or zero with w = 0 where a
/// pixel has none (shorter than [`NO_NORMAL`]).
pub fn unit_normals(normals: &[[f32; 3]]) -> Vec<[f32; 4]> {
    normals
        .iter()
        .map(|n| {
            let length = n.iter().map(|v| v * v).sum::<f32>().sqrt();
            if length < NO_NORMAL { [0.0; 4] } else { [n[0] / length, n[1] / length, n[2] / length, 1.0] }
        })
        .collect()
}

/// The normal stop between two unit normals with w = 1 (or zero normals with w = 0).
pub(crate) fn normal_weight(p: [f64; 4], q: [f64; 4]) -> f64 {
    let cos = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    cos.max(0.0).powi(NORMAL_POWER) + (1.0 - p[3]) * (1.0 - q[3])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The WGSL constants are the ones the f64 copy (reference.rs) uses.
    #[test]
    fn the_shader_constants_match_the_f64_copy() {
        let source = include_str!("../shaders/atrous.wgsl");
        let constant = |name: &str| -> f64 {
            let rest = source.split(&format!("const {name}: ")).nth(1).unwrap_or_else(|| panic!("{name}"));
            let value = rest.split(" = ").nth(1).and_then(|r| r.split(';').next()).expect("a value");
            value.trim_end_matches('u').parse().unwrap_or_else(|e| panic!("{name} = {value}: {e}"))
        };
        assert_eq!(2f64.powf(constant("NORMAL_SQUARINGS")), f64::from(NORMAL_POWER));
        assert_eq!(constant("TINY") as f32, TINY as f32);
    }
}
