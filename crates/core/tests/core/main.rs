//! The CPU reference tests of `marbre-core` that read data files: Perlin's
//! own reference points, and the fuzzers' minimised corpora.

mod fuzz_regressions;
mod perlin_reference;
mod tx_report;
