//! A track's keys and its value at any time: the interpolation between
//! two keys and the extrapolation outside them.
//!
//! Evaluated in f64 and returned as f32, the scene's precision, so that
//! a value at a key's time is the key's value exactly.

use serde::{Deserialize, Serialize};

/// How a track goes from a key to the next (the key's own setting, as in
/// Blender: it governs the segment after the key).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Interpolation {
    /// The key's value until the next key.
    Constant,
    /// A straight line to the next key.
    Linear,
    /// Ease in and out: `a + (b − a)·(3s² − 2s³)` with `s` the fraction of
    /// the segment, the cubic Bézier whose handles are flat and a third of
    /// the segment long. That is the curve Blender's default key (Bézier,
    /// auto-clamped handles) draws between two keys that are each an
    /// extreme of their neighbours, as the first and last keys and every
    /// turning point are; a key inside a monotone run keeps a flat tangent
    /// here where Blender's slopes.
    #[default]
    Smooth,
}

impl Interpolation {
    pub const ALL: [Interpolation; 3] = [
        Interpolation::Constant,
        Interpolation::Linear,
        Interpolation::Smooth,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Interpolation::Constant => "constant",
            Interpolation::Linear => "linear",
            Interpolation::Smooth => "smooth",
        }
    }

    /// The fraction of the way from one key to the next at `s` ∈ [0, 1) of
    /// the segment.
    fn weight(self, s: f64) -> f64 {
        match self {
            Interpolation::Constant => 0.0,
            Interpolation::Linear => s,
            Interpolation::Smooth => s * s * (3.0 - 2.0 * s),
        }
    }
}

/// What a track is before its first key and after its last.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Extrapolation {
    /// The first key's value before it, the last key's after it.
    #[default]
    Hold,
    /// The keys repeat: the value at `t` is the value at `t` brought into
    /// [first key, last key) by whole spans.
    Cycle,
}

impl Extrapolation {
    pub const ALL: [Extrapolation; 2] = [Extrapolation::Hold, Extrapolation::Cycle];

    pub fn label(self) -> &'static str {
        match self {
            Extrapolation::Hold => "hold",
            Extrapolation::Cycle => "cycle",
        }
    }
}

/// A key's value: one number, or a vector or colour (its components).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum KeyValue {
    Number(f32),
    Vector(Vec<f32>),
}

impl KeyValue {
    /// The value of a parameter with these components.
    pub fn from_components(components: &[f32]) -> Self {
        match components {
            [x] => KeyValue::Number(*x),
            _ => KeyValue::Vector(components.to_vec()),
        }
    }

    pub fn components(&self) -> &[f32] {
        match self {
            KeyValue::Number(x) => std::slice::from_ref(x),
            KeyValue::Vector(v) => v,
        }
    }
}

/// A track's value at a moment: `time` in seconds from the animation's
/// start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Key {
    pub time: f32,
    pub value: KeyValue,
    #[serde(default, skip_serializing_if = "is_smooth")]
    pub interpolation: Interpolation,
}

fn is_smooth(i: &Interpolation) -> bool {
    *i == Interpolation::Smooth
}

/// The value at `time` of keys in strictly increasing time order (a track
/// checks them so, [`super::Track::check`]), all with as many
/// components; `None` without keys.
pub fn value_at(keys: &[Key], extrapolation: Extrapolation, time: f32) -> Option<Vec<f32>> {
    let first = keys.first()?;
    let last = keys.last()?;
    let (start, end) = (f64::from(first.time), f64::from(last.time));
    let mut t = f64::from(time);
    if extrapolation == Extrapolation::Cycle && end > start {
        t = start + (t - start).rem_euclid(end - start);
    }
    if t <= start {
        return Some(first.value.components().to_vec());
    }
    if t >= end {
        return Some(last.value.components().to_vec());
    }
    // The segment [keys[i], keys[i + 1]) holding t.
    let i = keys.partition_point(|k| f64::from(k.time) <= t) - 1;
    let (a, b) = (&keys[i], &keys[i + 1]);
    let s = (t - f64::from(a.time)) / (f64::from(b.time) - f64::from(a.time));
    let w = a.interpolation.weight(s);
    Some(
        a.value
            .components()
            .iter()
            .zip(b.value.components())
            .map(|(&x, &y)| (f64::from(x) + (f64::from(y) - f64::from(x)) * w) as f32)
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f32, value: f32, interpolation: Interpolation) -> Key {
        Key {
            time,
            value: KeyValue::Number(value),
            interpolation,
        }
    }

    fn at(keys: &[Key], e: Extrapolation, t: f32) -> f32 {
        value_at(keys, e, t).unwrap()[0]
    }

    /// Constant holds the left key; linear is the line; smooth is the
    /// cubic 3s² − 2s³ (half way at the middle, 0.156 25 at a quarter).
    #[test]
    fn interpolations_follow_their_closed_forms() {
        for (interp, quarter, half) in [
            (Interpolation::Constant, 2.0, 2.0),
            (Interpolation::Linear, 3.0, 4.0),
            (Interpolation::Smooth, 2.0 + 4.0 * 0.156_25, 4.0),
        ] {
            let keys = [key(1.0, 2.0, interp), key(3.0, 6.0, interp)];
            let e = Extrapolation::Hold;
            assert_eq!(at(&keys, e, 1.5), quarter, "{interp:?} at a quarter");
            assert_eq!(at(&keys, e, 2.0), half, "{interp:?} at the middle");
            assert_eq!(at(&keys, e, 1.0), 2.0, "{interp:?} at the first key");
            assert_eq!(at(&keys, e, 3.0), 6.0, "{interp:?} at the last key");
        }
        // Smooth everywhere: a + (b − a)(3s² − 2s³), its slope 0 at both keys.
        let keys = [
            key(0.0, -1.0, Interpolation::Smooth),
            key(2.0, 3.0, Interpolation::Smooth),
        ];
        for i in 0..=20 {
            let t = i as f32 * 0.1;
            let s = f64::from(t) / 2.0;
            let expected = (-1.0 + 4.0 * s * s * (3.0 - 2.0 * s)) as f32;
            assert_eq!(at(&keys, Extrapolation::Hold, t), expected, "t = {t}");
        }
    }

    /// Each segment takes its left key's interpolation.
    #[test]
    fn a_key_governs_the_segment_after_it() {
        let keys = [
            key(0.0, 0.0, Interpolation::Linear),
            key(1.0, 1.0, Interpolation::Constant),
            key(2.0, 5.0, Interpolation::Linear),
        ];
        assert_eq!(at(&keys, Extrapolation::Hold, 0.5), 0.5);
        assert_eq!(at(&keys, Extrapolation::Hold, 1.9), 1.0);
        assert_eq!(at(&keys, Extrapolation::Hold, 2.0), 5.0);
    }

    /// Hold keeps the end keys' values; cycle repeats the span [0.5, 2.5)
    /// every 2 s, before and after.
    #[test]
    fn extrapolation_holds_or_cycles() {
        let keys = [
            key(0.5, 10.0, Interpolation::Linear),
            key(2.5, 30.0, Interpolation::Linear),
        ];
        assert_eq!(at(&keys, Extrapolation::Hold, -4.0), 10.0);
        assert_eq!(at(&keys, Extrapolation::Hold, 9.0), 30.0);
        for (t, expected) in [
            (1.5, 20.0),
            (3.5, 20.0),
            (5.5, 20.0),
            (-0.5, 20.0),
            (4.5, 10.0),
        ] {
            assert_eq!(at(&keys, Extrapolation::Cycle, t), expected, "cycle at {t}");
        }
        // One key: its value everywhere, cycle or not.
        let one = [key(1.0, 7.0, Interpolation::Smooth)];
        assert_eq!(at(&one, Extrapolation::Cycle, 12.0), 7.0);
        assert_eq!(value_at(&[], Extrapolation::Hold, 0.0), None);
    }

    /// Vectors interpolate per component.
    #[test]
    fn vectors_interpolate_per_component() {
        let keys = [
            Key {
                time: 0.0,
                value: KeyValue::Vector(vec![0.0, 1.0, 2.0]),
                interpolation: Interpolation::Linear,
            },
            Key {
                time: 1.0,
                value: KeyValue::Vector(vec![1.0, 1.0, 0.0]),
                interpolation: Interpolation::Linear,
            },
        ];
        assert_eq!(
            value_at(&keys, Extrapolation::Hold, 0.25).unwrap(),
            vec![0.25, 1.0, 1.5]
        );
    }
}
