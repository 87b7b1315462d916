//! SplitMix64 (G. Steele, D. Lea, C. Flood, "Fast splittable pseudorandom number generators",
//! OOPSLA 2014): the state walks a Weyl sequence `s += gamma` with gamma = 2^64 / golden ratio
//! (odd), and each output is the state passed through a bijective 64-bit mixing function
//! (xor-shift, multiply, xor-shift, multiply, xor-shift). Period 2^64, passes BigCrush.
//!
//! The oracle gives every (seed, pixel, sample) triple its own generator, keyed by chaining the
//! mixing function over the three numbers. A sample's random numbers therefore never depend on
//! which thread renders it or in which order.

/// The Weyl increment: round(2^64 / phi), made odd.
const GOLDEN_GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// The SplitMix64 output function (a bijection on u64, so distinct inputs never collide).
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A SplitMix64 generator.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator whose first output is `mix64(state + gamma)`, as in the reference code.
    pub fn from_state(state: u64) -> Rng {
        Rng { state }
    }

    /// The generator of sample `sample` of pixel `pixel` (row-major index y * width + x) under
    /// `seed`. Each key passes through the bijective mixer before the next one is folded in, so
    /// neighbouring pixels and samples get unrelated starting states.
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Rng {
        let k = mix64(seed ^ 0x6a09_e667_f3bc_c909);
        let k = mix64(k ^ pixel);
        let k = mix64(k.wrapping_add(GOLDEN_GAMMA) ^ sample);
        Rng::from_state(k)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GOLDEN_GAMMA);
        mix64(self.state)
    }

    /// Uniform in [0, 1): the top 53 bits as a multiple of 2^-53 (every value exactly
    /// representable, 1 never reached).
    pub fn uniform(&mut self) -> f64 {
        const SCALE: f64 = 1.0 / (1u64 << 53) as f64;
        (self.next_u64() >> 11) as f64 * SCALE
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_reference_splitmix64_sequence() {
        // Known answer of the published algorithm started from state 0.
        let mut r = Rng::from_state(0);
        assert_eq!(r.next_u64(), 0xe220_a839_7b1d_cdaf);
        let mut r = Rng::from_state(1_234_567);
        assert_eq!(r.next_u64(), 6_457_827_717_110_365_317);
        assert_eq!(r.next_u64(), 3_203_168_211_198_807_973);
    }

    #[test]
    fn uniform_stays_in_the_unit_interval_with_the_right_moments() {
        let mut r = Rng::for_sample(7, 3, 11);
        let n = 200_000;
        let (mut sum, mut sum_sq) = (0.0, 0.0);
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u;
            sum_sq += u * u;
        }
        let mean = sum / n as f64;
        let second = sum_sq / n as f64;
        // Mean 1/2 (sd of the estimate sqrt(1/12 / n) = 6.5e-4), second moment 1/3.
        assert!((mean - 0.5).abs() < 4.0 * 6.5e-4, "mean {mean}");
        assert!((second - 1.0 / 3.0).abs() < 3e-3, "second moment {second}");
    }

    #[test]
    fn sample_streams_are_keyed_by_seed_pixel_and_sample() {
        let first = |s, p, i| Rng::for_sample(s, p, i).next_u64();
        assert_eq!(first(1, 2, 3), first(1, 2, 3));
        let base = first(1, 2, 3);
        for other in [first(0, 2, 3), first(1, 3, 3), first(1, 2, 4), first(1, 3, 2), first(2, 2, 3)] {
            assert_ne!(base, other);
        }
    }
}
