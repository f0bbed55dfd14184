//! A small seeded generator (PCG32, O'Neill 2014): the soak's edits must be
//! the same for the same seed on every machine, so that a failing run can
//! be replayed; a crate dependency for that would be out of proportion.

pub struct Pcg32 {
    state: u64,
    increment: u64,
}

impl Pcg32 {
    const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

    pub fn new(seed: u64) -> Self {
        let mut rng = Self {
            state: 0,
            increment: (seed << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(seed);
        rng.next_u32();
        rng
    }

    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old
            .wrapping_mul(Self::MULTIPLIER)
            .wrapping_add(self.increment);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        xorshifted.rotate_right((old >> 59) as u32)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }

    /// Uniform in `[lo, hi]` (within rounding).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        (lo + (hi - lo) * self.unit()).clamp(lo, hi)
    }

    /// Log-uniform in `[lo, hi]`, both positive: what a logarithmic slider
    /// gives when dragged anywhere along it.
    pub fn log_range(&mut self, lo: f32, hi: f32) -> f32 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit())
            .exp()
            .clamp(lo, hi)
    }

    /// Uniform in `0..n`; 0 when `n` is 0.
    pub fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            return 0;
        }
        ((u64::from(self.next_u32()) * n as u64) >> 32) as usize
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.unit() < p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference outputs of the PCG paper's `pcg32-demo` (seed 42,
    /// sequence 54): the generator is PCG32 and not something close to it.
    #[test]
    fn matches_the_reference_sequence() {
        let mut rng = Pcg32 {
            state: 0,
            increment: (54 << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(42);
        rng.next_u32();
        let first: Vec<u32> = (0..3).map(|_| rng.next_u32()).collect();
        assert_eq!(first, [0xa15c02b7, 0x7b47f409, 0xba1d3330]);
    }

    #[test]
    fn draws_stay_in_their_ranges() {
        let mut rng = Pcg32::new(7);
        for _ in 0..10_000 {
            assert!((2.0..=3.0).contains(&rng.range(2.0, 3.0)));
            assert!((0.01..=100.0).contains(&rng.log_range(0.01, 100.0)));
            assert!(rng.below(5) < 5);
        }
        assert_eq!(rng.below(0), 0);
    }
}
