//! Undo and redo of scene edits (issue 7).
//!
//! The viewer shows the history every frame's scene after the UI ran,
//! with what changed since the frame before (worked out once, in
//! `Scene::changes_from`); a change other than the camera's is an edit,
//! recorded as the scene before it. Nothing is compared here. Edits made while one gesture goes on (a slider dragged,
//! a number typed: the pointer held or a text field focused) coalesce into
//! one step, so one Ctrl+Z undoes a whole drag, as in Blender.
//!
//! The camera is not part of a step: orbiting is looking, not editing (as
//! Blender keeps view navigation out of its undo), so undo keeps the view
//! the user has now.

use marbre_core::scene::{Change, Scene};

/// Steps kept; the oldest are forgotten first.
const MAX_STEPS: usize = 200;

pub struct History {
    /// The scenes before each step, oldest first.
    undo: Vec<Scene>,
    /// The scenes undone, most recent last.
    redo: Vec<Scene>,
    /// The scene as of the last edit seen (its camera aside): the step
    /// the next edit records.
    last: Scene,
    /// A gesture is under way and its edits join the latest step.
    step_open: bool,
}

impl History {
    pub fn new(scene: &Scene) -> Self {
        Self {
            undo: Vec::new(),
            redo: Vec::new(),
            last: scene.clone(),
            step_open: false,
        }
    }

    /// Records `scene` if `change` (from the scene seen the frame before)
    /// edits it; `gesture` says whether the user is still dragging or
    /// typing.
    ///
    /// Called every frame: the scene is cloned only when it changed.
    pub fn observe(&mut self, scene: &Scene, change: Change, gesture: bool) {
        if change.edits_document() {
            let before = std::mem::replace(&mut self.last, scene.clone());
            if !self.step_open {
                self.undo.push(before);
                if self.undo.len() > MAX_STEPS {
                    self.undo.remove(0);
                }
                self.redo.clear();
            }
            self.step_open = gesture;
        } else {
            // A gesture opens a step only by editing: a text field focused
            // (or a button held) with no edit yet must not swallow the
            // edit that ends it.
            self.step_open &= gesture;
        }
    }

    /// The scene before the latest step, seen from `current`'s camera; the
    /// current scene becomes redoable. `None` with nothing to undo.
    pub fn undo(&mut self, current: &Scene) -> Option<Scene> {
        let previous = self.undo.pop()?;
        self.redo.push(current.clone());
        Some(self.restore(previous, current))
    }

    /// The scene the latest undo left, seen from `current`'s camera.
    pub fn redo(&mut self, current: &Scene) -> Option<Scene> {
        let next = self.redo.pop()?;
        self.undo.push(current.clone());
        Some(self.restore(next, current))
    }

    /// The scene as of the last edit seen: what a frame's edits are
    /// measured from when the traced scene moves on its own (time).
    pub fn last(&self) -> &Scene {
        &self.last
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// A kept scene, seen from `current`'s camera.
    fn restore(&mut self, mut scene: Scene, current: &Scene) -> Scene {
        scene.camera = current.camera;
        self.last = scene.clone();
        self.step_open = false;
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The history as the viewer drives it: each frame's scene with its
    /// change from the frame before; an undone or redone scene becomes the
    /// next frame's baseline (the viewer hands it to the renderer at once).
    struct Frames {
        history: History,
        frame: Scene,
    }

    impl Frames {
        fn new(scene: &Scene) -> Self {
            Self {
                history: History::new(scene),
                frame: scene.clone(),
            }
        }

        fn observe(&mut self, scene: &Scene, gesture: bool) {
            let change = scene.changes_from(&self.frame);
            self.history.observe(scene, change, gesture);
            self.frame = scene.clone();
        }

        fn undo(&mut self, current: &Scene) -> Option<Scene> {
            let scene = self.history.undo(current)?;
            self.frame = scene.clone();
            Some(scene)
        }

        fn redo(&mut self, current: &Scene) -> Option<Scene> {
            let scene = self.history.redo(current)?;
            self.frame = scene.clone();
            Some(scene)
        }

        fn can_undo(&self) -> bool {
            self.history.can_undo()
        }

        fn can_redo(&self) -> bool {
            self.history.can_redo()
        }
    }

    fn with_exposure(exposure: f32) -> Scene {
        let mut scene = Scene::default();
        scene.render.display.exposure = exposure;
        scene
    }

    #[test]
    fn each_edit_is_a_step_undone_and_redone_in_order() {
        let mut h = Frames::new(&with_exposure(0.0));
        h.observe(&with_exposure(1.0), false);
        h.observe(&with_exposure(2.0), false);
        let one = h.undo(&with_exposure(2.0)).unwrap();
        assert_eq!(one.render.display.exposure, 1.0);
        h.observe(&one, false);
        let zero = h.undo(&one).unwrap();
        assert_eq!(zero.render.display.exposure, 0.0);
        assert!(h.undo(&zero).is_none(), "nothing before the first scene");
        assert_eq!(h.redo(&zero).unwrap().render.display.exposure, 1.0);
        assert_eq!(h.redo(&one).unwrap().render.display.exposure, 2.0);
        assert!(!h.can_redo());
    }

    /// A slider dragged through many values is one step.
    #[test]
    fn a_drag_coalesces_into_one_step() {
        let mut h = Frames::new(&with_exposure(0.0));
        for k in 1..=30 {
            h.observe(&with_exposure(k as f32 * 0.1), true);
        }
        // The pointer is released: the gesture ends without a change.
        h.observe(&with_exposure(3.0), false);
        let before = h.undo(&with_exposure(3.0)).unwrap();
        assert_eq!(before.render.display.exposure, 0.0);
        assert!(!h.can_undo());
    }

    /// A new edit after an undo forgets what could be redone.
    /// A text field focused without an edit, then a click elsewhere that
    /// both ends the focus and edits (one frame): that edit is a step.
    #[test]
    fn a_gesture_without_an_edit_does_not_swallow_the_next_edit() {
        let mut history = Frames::new(&with_exposure(0.0));
        history.observe(&with_exposure(0.0), true);
        history.observe(&with_exposure(0.0), true);
        history.observe(&with_exposure(1.0), false);
        assert!(history.can_undo());
        assert_eq!(history.undo(&with_exposure(1.0)), Some(with_exposure(0.0)));
    }

    #[test]
    fn an_edit_after_undo_clears_redo() {
        let mut h = Frames::new(&with_exposure(0.0));
        h.observe(&with_exposure(1.0), false);
        let zero = h.undo(&with_exposure(1.0)).unwrap();
        h.observe(&zero, false);
        assert!(h.can_redo());
        h.observe(&with_exposure(5.0), false);
        assert!(!h.can_redo());
    }

    /// Orbiting is not a step, and undo keeps the current view.
    #[test]
    fn camera_moves_are_not_steps_and_undo_keeps_the_view() {
        let mut h = Frames::new(&with_exposure(0.0));
        let mut moved = with_exposure(0.0);
        moved.camera.yaw_degrees = 40.0;
        h.observe(&moved, true);
        h.observe(&moved, false);
        assert!(!h.can_undo());
        let mut edited = moved.clone();
        edited.render.display.exposure = 1.0;
        h.observe(&edited, false);
        let undone = h.undo(&edited).unwrap();
        assert_eq!(undone.render.display.exposure, 0.0);
        assert_eq!(undone.camera.yaw_degrees, 40.0);
    }

    #[test]
    fn the_oldest_steps_are_forgotten_past_the_limit() {
        let mut h = Frames::new(&with_exposure(0.0));
        for k in 1..=(MAX_STEPS + 10) {
            h.observe(&with_exposure(k as f32), false);
        }
        let mut current = with_exposure((MAX_STEPS + 10) as f32);
        let mut undone = 0;
        while let Some(previous) = h.undo(&current) {
            current = previous;
            undone += 1;
        }
        assert_eq!(undone, MAX_STEPS);
        assert_eq!(current.render.display.exposure, 10.0);
    }

    /// A node-graph edit (a parameter dragged in a node, then a link
    /// dropped on another socket with the node's place) is what the graph
    /// window does to the scene: each gesture is one step, and undo brings
    /// back the tree the tree panel shows.
    #[test]
    fn node_graph_edits_are_steps() {
        use glam::{Vec2, Vec3};
        use marbre_core::scene::texture_graph::{NodePath, Socket, move_subtree, texture_at_mut};
        use marbre_core::scene::{Child, MaterialKey, Pattern, Sphere, Texture};
        let checker = |phase, a: Child, b: Child| {
            Texture::blend(
                Pattern::Checker2d {
                    size: Vec2::splat(0.25),
                    phase,
                },
                a,
                b,
            )
        };
        let mut sphere = Sphere::default();
        sphere.material.diffuse = checker(
            0.0,
            checker(0.0, Vec3::X.into(), Vec3::Y.into()).into(),
            Vec3::Z.into(),
        );
        let mut scene = Scene {
            spheres: vec![sphere],
            ..Scene::default()
        };
        let original = scene.clone();
        let mut history = Frames::new(&scene);
        let key = MaterialKey::Sphere(0);
        let path: NodePath = "diffuse.a".parse().unwrap();

        for k in 1..=5 {
            let (m, _) = scene.material_and_layout_mut(key).unwrap();
            texture_at_mut(m, &path).unwrap().pattern = Pattern::Checker2d {
                size: Vec2::splat(0.25),
                phase: 0.1 * k as f32,
            };
            history.observe(&scene, true);
        }
        history.observe(&scene, false);
        let after_drag = scene.clone();

        let (m, layout) = scene.material_and_layout_mut(key).unwrap();
        let to = NodePath::root(path.root).child(Socket::B);
        layout
            .edit(key, |l| {
                l.set(&path, Vec2::new(-600.0, 0.0));
                move_subtree(m, l, &path, &to)
            })
            .unwrap();
        history.observe(&scene, false);
        let diffuse = &scene.spheres[0].material.diffuse;
        assert_eq!(diffuse.a, Child::Color(Vec3::Z), "the tree shows the link");
        assert!(
            matches!(&diffuse.b, Child::Texture(t) if t.pattern == Pattern::Checker2d {
                size: Vec2::splat(0.25),
                phase: 0.5,
            })
        );
        assert!(scene.graph_layout.get(key).is_some());

        let undone = history.undo(&scene).unwrap();
        assert_eq!(undone, after_drag);
        let undone = history.undo(&undone).unwrap();
        assert_eq!(undone, original);
        assert!(!history.can_undo());
    }
}
