//! Contrasting defaults (as Blender's nodes start): a texture switched from
//! a constant to a pattern, or a child newly nested, starts with two sides
//! that differ visibly, so the edit shows in the image at once. Without it
//! both sides took the old value and the switch looked broken (issue 21).

use super::pattern::Pattern;
use super::pattern_table::PatternKind;
use super::texture_tree::{Child, Texture};
use crate::texture::luminance;
use glam::{Vec2, Vec3};

/// The least luminance difference between a value and its
/// [`contrasting`] counterpart, for any value in [0, 1].
pub const MIN_CONTRAST: f32 = 0.4;

/// How far the counterpart goes towards black (from a light value) or
/// white (from a dark one): its luminance differs by this fraction of the
/// way, at least `0.85 · 0.5` > [`MIN_CONTRAST`].
const TOWARDS: f32 = 0.85;

/// A colour that stands out against `c`: its dark counterpart if `c` is
/// light (luminance ≥ 0.5), else its light counterpart, keeping its hue.
/// A complement would not do: mid grey is its own complement.
pub fn contrasting(c: Vec3) -> Vec3 {
    let c = c.max(Vec3::ZERO);
    if luminance(c) >= 0.5 {
        c * (1.0 - TOWARDS)
    } else {
        c + (Vec3::ONE - c).max(Vec3::ZERO) * TOWARDS
    }
}

impl Child {
    /// A plain value that stands out against this child: [`contrasting`]
    /// of its value (a nested texture's at the origin), a scalar for a
    /// scalar.
    pub fn contrasting(&self) -> Child {
        match self {
            Child::Scalar(v) => Child::Scalar(contrasting(Vec3::splat(*v)).x),
            Child::Color(c) => Child::Color(contrasting(*c)),
            Child::Texture(t) => Child::Color(contrasting(t.eval(Vec3::ZERO, Vec2::ZERO))),
        }
    }
}

impl Texture {
    /// This texture with `pattern` (from [`Pattern::with_index`]). Where
    /// both sides showed one value (a constant, or `a == b`), `b` becomes
    /// [`Child::contrasting`] of `a`, and a new mix gets a noise factor,
    /// so the new pattern shows; sides that already differ are kept.
    pub fn with_pattern_contrasting(&self, pattern: Pattern) -> Texture {
        let mut t = self.clone();
        let one_value = self.pattern == Pattern::Constant || self.a == self.b;
        t.pattern = pattern;
        if one_value && pattern != Pattern::Constant {
            t.b = self.a.contrasting();
        }
        if pattern == Pattern::Mix && t.factor.is_none() {
            t.factor = Some(Box::new(Texture::blend(
                Pattern::fresh(PatternKind::Fbm, None),
                0.0,
                1.0,
            )));
        }
        t
    }

    /// A texture nesting `child`: a checker of 4 × 4 cells per unit of
    /// (u, v) with `child` as `a`, so one side keeps the look it had, and
    /// its [`Child::contrasting`] counterpart as `b`.
    pub fn nesting(child: &Child) -> Texture {
        Texture::blend(
            Pattern::Checker2d {
                size: Vec2::splat(0.25),
                phase: 0.0,
            },
            child.clone(),
            child.contrasting(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SurfacePoint;

    fn side_luminance(child: &Child) -> f32 {
        luminance(child.eval(Vec3::ZERO, Vec2::ZERO))
    }

    /// Every value on a grid of [0, 1]³ has a counterpart at least
    /// MIN_CONTRAST away in luminance, within [0, 1].
    #[test]
    fn every_colour_has_a_counterpart_differing_by_the_stated_contrast() {
        let steps = 11;
        for i in 0..steps * steps * steps {
            let at = |k: usize| (k % steps) as f32 / (steps - 1) as f32;
            let c = Vec3::new(at(i), at(i / steps), at(i / (steps * steps)));
            let d = contrasting(c);
            let difference = (luminance(c) - luminance(d)).abs();
            assert!(difference >= MIN_CONTRAST, "{c} → {d}: {difference}");
            assert!(
                d.min_element() >= 0.0 && d.max_element() <= 1.0,
                "{c} → {d}"
            );
        }
        // Mid grey, its own complement, goes dark: 0.5 · 0.15.
        assert!((contrasting(Vec3::splat(0.5)) - Vec3::splat(0.075)).length() < 1e-6);
    }

    /// A constant switched to each pattern has sides at least MIN_CONTRAST
    /// apart, `a` the old value; a scalar stays a scalar.
    #[test]
    fn a_constant_switched_to_any_pattern_gets_contrasting_sides() {
        for old in [
            Texture::color(Vec3::new(0.8, 0.2, 0.1)),
            Texture::color(Vec3::splat(0.5)),
            Texture::scalar(0.1),
        ] {
            for kind in PatternKind::all().skip(1) {
                let t = old.with_pattern_contrasting(old.pattern.with_kind(kind));
                assert_eq!(t.pattern.kind(), kind);
                assert_eq!(t.a, old.a, "{}: a keeps the old value", kind.info().name);
                let difference = (side_luminance(&t.a) - side_luminance(&t.b)).abs();
                assert!(
                    difference >= MIN_CONTRAST,
                    "{}: {difference}",
                    kind.info().name
                );
                assert_eq!(
                    matches!(t.b, Child::Scalar(_)),
                    matches!(old.a, Child::Scalar(_))
                );
            }
        }
    }

    /// The new mix's factor varies over a unit sphere (its noise is not
    /// flat), so the mix shows both sides.
    #[test]
    fn a_new_mix_gets_a_varying_factor() {
        let t = Texture::color(Vec3::splat(0.3)).with_pattern_contrasting(Pattern::Mix);
        let factor = t.factor.expect("a factor");
        let values: Vec<f32> = (0..64)
            .map(|i| {
                let a = i as f32 * 0.1;
                let p = Vec3::new(a.cos(), a.sin() * 0.6, 0.5);
                factor.eval_at(&SurfacePoint::new(p, Vec2::ZERO)).x
            })
            .collect();
        let (lo, hi) = values
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(hi - lo > 0.2, "factor spans {lo}..{hi}");
    }

    /// Sides that already differ (a checker becoming a marble) are kept.
    #[test]
    fn differing_sides_are_kept() {
        let old = Texture::blend(Pattern::Checker { size: 1.0 }, 0.2, 0.9);
        let t = old.with_pattern_contrasting(old.pattern.with_kind(PatternKind::Marble));
        assert_eq!((t.a, t.b), (old.a, old.b));
    }

    /// Nesting keeps the parent's look on side a and contrasts side b; the
    /// checker shows both within a unit square of (u, v).
    #[test]
    fn nesting_keeps_the_old_value_on_one_side() {
        for child in [Child::Color(Vec3::new(0.1, 0.6, 0.2)), Child::Scalar(0.7)] {
            let t = Texture::nesting(&child);
            assert_eq!(t.a, child);
            assert!((side_luminance(&t.a) - side_luminance(&t.b)).abs() >= MIN_CONTRAST);
            let at = |u: f32, v: f32| t.eval(Vec3::ZERO, Vec2::new(u, v));
            assert_eq!(at(0.1, 0.1), child.eval(Vec3::ZERO, Vec2::ZERO));
            assert_eq!(at(0.35, 0.1), t.b.eval(Vec3::ZERO, Vec2::ZERO));
        }
    }
}
