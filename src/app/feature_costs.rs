//! What each shader feature of the scene costs per frame: the user compiles
//! one out in the Quality panel and sees the trace pass's time without it
//! next to the time with everything in. The image is then wrong (a texture
//! gone, a light unlit): the point is the difference in time.

use marbre_render::gpu::{Feature, FeatureSet};
use std::collections::{BTreeMap, BTreeSet};

/// Frames measured for each set of features, after the first few (which
/// include compiling at the first draw on some drivers).
const FRAMES: usize = 8;
const SKIPPED_FRAMES: usize = 3;

#[derive(Debug, Clone, Default)]
pub struct FeatureCosts {
    /// The scene's own features: the measurements belong to them, and a
    /// structural edit that changes them starts over.
    scene_features: FeatureSet,
    /// Features compiled out on request.
    disabled: BTreeSet<Feature>,
    /// Trace-pass times of the frames drawn with the current set.
    frames: Vec<f32>,
    /// Median trace-pass ms by set of compiled-out features (the empty set:
    /// everything the scene uses).
    measured: BTreeMap<Vec<Feature>, f32>,
}

impl FeatureCosts {
    /// Follows the scene's features; returns true if they changed, and
    /// with them everything measured is forgotten and nothing is disabled.
    pub fn follow_scene(&mut self, scene_features: &FeatureSet) -> bool {
        if *scene_features == self.scene_features {
            return false;
        }
        *self = Self {
            scene_features: scene_features.clone(),
            ..Self::default()
        };
        true
    }

    pub fn disabled(&self) -> &BTreeSet<Feature> {
        &self.disabled
    }

    /// The features the shader should be built with: the scene's minus
    /// those compiled out; `None` when nothing is (the renderer then
    /// specialises per scene as usual).
    pub fn override_set(&self) -> Option<FeatureSet> {
        if self.disabled.is_empty() {
            return None;
        }
        Some(FeatureSet(
            self.scene_features
                .0
                .difference(&self.disabled)
                .copied()
                .collect(),
        ))
    }

    /// Compiles `feature` in or out; the measurement of the new set starts.
    pub fn toggle(&mut self, feature: Feature) {
        if !self.disabled.remove(&feature) {
            self.disabled.insert(feature);
        }
        self.frames.clear();
    }

    /// Takes in a frame's trace-pass time, drawn with `built` (the features
    /// of the pipeline that drew it).
    pub fn record(&mut self, built: &FeatureSet, trace_ms: f32) {
        let expected = self
            .override_set()
            .unwrap_or_else(|| self.scene_features.clone());
        if *built != expected || !trace_ms.is_finite() {
            return;
        }
        self.frames.push(trace_ms);
        if self.frames.len() >= SKIPPED_FRAMES + FRAMES {
            let mut kept = self.frames[SKIPPED_FRAMES..].to_vec();
            kept.sort_by(f32::total_cmp);
            let key = self.disabled.iter().copied().collect();
            self.measured.insert(key, kept[kept.len() / 2]);
            self.frames.drain(..FRAMES);
        }
    }

    /// Median ms per frame with every feature compiled in.
    pub fn with_all(&self) -> Option<f32> {
        self.measured.get(&Vec::new()).copied()
    }

    /// Median ms per frame with `feature` alone compiled out.
    pub fn without(&self, feature: Feature) -> Option<f32> {
        self.measured.get(&vec![feature]).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_set_is_measured_by_its_median_after_the_first_frames() {
        let set = |features: &[Feature]| FeatureSet(features.iter().copied().collect());
        let scene = set(&[Feature::Ground, Feature::Bump]);
        let mut costs = FeatureCosts::default();
        assert!(costs.follow_scene(&scene));
        assert!(!costs.follow_scene(&scene));
        // Compile-at-first-draw frames are skipped: 500 ms never counts.
        for ms in [
            500.0, 400.0, 300.0, 10.0, 11.0, 12.0, 10.5, 11.5, 10.0, 12.0, 11.0,
        ] {
            costs.record(&scene, ms);
        }
        assert_eq!(costs.with_all(), Some(11.0));
        costs.toggle(Feature::Bump);
        assert_eq!(costs.override_set(), Some(set(&[Feature::Ground])));
        // Frames still drawn by the old pipeline do not count.
        costs.record(&scene, 99.0);
        for _ in 0..SKIPPED_FRAMES + FRAMES {
            costs.record(&set(&[Feature::Ground]), 7.0);
        }
        assert_eq!(costs.without(Feature::Bump), Some(7.0));
        costs.toggle(Feature::Bump);
        assert_eq!(costs.override_set(), None);
        // A structural edit forgets it all.
        assert!(costs.follow_scene(&set(&[Feature::Ground])));
        assert_eq!(costs.with_all(), None);
        assert!(costs.disabled().is_empty());
    }
}
