//! The command-line tools' integration tests, one binary: the accuracy
//! bench end to end, and `marbre render` against the viewer's route to
//! the same file; `marbre render --frames`, a sequence of an animation;
//! `marbre render --sample-offset`, disjoint batches of one render.

mod accuracy_bench;
mod batches;
mod farm_scripts;
mod merge_checks;
mod render;
mod sequence;
mod tiles;
