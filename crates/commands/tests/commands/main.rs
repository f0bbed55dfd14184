//! The command-line tools' integration tests, one binary: the accuracy
//! bench end to end, and `marbre render` against the viewer's route to
//! the same file; `marbre render --frames`, a sequence of an animation.

mod accuracy_bench;
mod render;
mod sequence;
