//! The name of an animatable number: the path of its field in the preset,
//! as the preset's own error messages write it (`camera.fov_degrees`,
//! `spheres["marble"].material.diffuse.pattern.noise.fractal.frequency`,
//! `point_light.position[1]`). The panel's key buttons, the preset's
//! tracks and the command line all name a parameter so.
//!
//! A path starts at one of the scene's parts ([`Part`], the one list of
//! what can be keyed) and goes down the part's fields as serde writes
//! them, through `serde_json`'s value tree rather than a visitor written
//! per struct: every field a preset can hold is reachable without code
//! per field, and a new field is animatable the day it is added. An enum
//! variant's name is not part of a path (`pattern.noise`, not
//! `pattern.Fbm.noise`): the variant is the structure, which keys do not
//! change. A list's element is named by its `name` when it has one
//! (`spheres["marble"]`, stable when spheres are added or reordered), by
//! its index otherwise (`ramp[2]`).

use crate::scene::{Property, Scene};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;
use std::fmt;

/// One step of a path.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Step {
    Field(String),
    Index(usize),
    /// The element of a list whose `name` is this.
    Name(String),
}

/// A parsed parameter path.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ParamPath(pub Vec<Step>);

impl ParamPath {
    /// Reads `camera.target[1]`, `spheres["marble"].radius`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut steps = Vec::new();
        let mut rest = text.trim();
        if rest.is_empty() {
            return Err("the path is empty".into());
        }
        if rest.starts_with('[') {
            return Err(format!("`{text}`: a path starts with a field name"));
        }
        let mut expect_field = true;
        while !rest.is_empty() {
            if let Some(after) = rest.strip_prefix('[') {
                let close = after
                    .find(']')
                    .ok_or_else(|| format!("`{text}`: a `[` without its `]`"))?;
                let inside = &after[..close];
                steps.push(
                    if let Some(name) = inside.strip_prefix('"').and_then(|n| n.strip_suffix('"')) {
                        Step::Name(name.to_owned())
                    } else {
                        Step::Index(inside.parse().map_err(|_| {
                            format!("`{text}`: `[{inside}]` is neither an index nor a \"name\"")
                        })?)
                    },
                );
                rest = &after[close + 1..];
                expect_field = false;
                continue;
            }
            if !expect_field {
                rest = rest
                    .strip_prefix('.')
                    .ok_or_else(|| format!("`{text}`: expected `.` or `[` before `{rest}`"))?;
            }
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            if end == 0 {
                return Err(format!("`{text}`: expected a field name at `{rest}`"));
            }
            steps.push(Step::Field(rest[..end].to_owned()));
            rest = &rest[end..];
            expect_field = false;
        }
        Ok(Self(steps))
    }

    /// The path one field further down.
    pub fn field(&self, name: &str) -> Self {
        let mut steps = self.0.clone();
        steps.push(Step::Field(name.to_owned()));
        Self(steps)
    }

    /// The path one list element further down.
    pub fn index(&self, i: usize) -> Self {
        let mut steps = self.0.clone();
        steps.push(Step::Index(i));
        Self(steps)
    }

    /// The path of the element named `name` of the list here.
    pub fn named(&self, name: &str) -> Self {
        let mut steps = self.0.clone();
        steps.push(Step::Name(name.to_owned()));
        Self(steps)
    }

    /// The path of a dotted tail (`diffuse.a.factor`, a node path) below
    /// this one.
    pub fn join(&self, tail: &str) -> Result<Self, String> {
        let mut steps = self.0.clone();
        steps.extend(Self::parse(tail)?.0);
        Ok(Self(steps))
    }
}

impl fmt::Display for ParamPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, step) in self.0.iter().enumerate() {
            match step {
                Step::Field(name) if i == 0 => write!(f, "{name}")?,
                Step::Field(name) => write!(f, ".{name}")?,
                Step::Index(n) => write!(f, "[{n}]")?,
                Step::Name(n) => write!(f, "[\"{n}\"]")?,
            }
        }
        Ok(())
    }
}

/// A part of the scene that keys can reach, each read and written whole:
/// the one list of what is animatable. Names, saved views, the node
/// editor's layout and the mesh files are not parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Camera,
    Sphere(usize),
    Cylinder(usize),
    Polygon(usize),
    Ground,
    MeshPlacement(usize),
    /// Mesh `.0`'s material `.1`.
    MeshMaterial(usize, usize),
    PointLight,
    Environment,
    Render,
}

/// The element of a list a step names, or why none.
fn element(step: Option<&Step>, names: &[&str], what: &str, list: &str) -> Result<usize, String> {
    match step {
        Some(Step::Index(i)) if *i < names.len() => Ok(*i),
        Some(Step::Index(i)) => Err(format!(
            "no {what} {i}: the scene has {} {list}",
            names.len()
        )),
        Some(Step::Name(n)) => names.iter().position(|m| m == n).ok_or_else(|| {
            format!(
                "no {what} named \"{n}\" (the scene's {list}: {})",
                if names.is_empty() {
                    "none".to_owned()
                } else {
                    names.join(", ")
                }
            )
        }),
        _ => Err(format!(
            "`{list}` needs an element: `{list}[0]` or `{list}[\"name\"]`"
        )),
    }
}

/// The part a path starts in and the steps left inside it.
fn locate<'p>(scene: &Scene, path: &'p ParamPath) -> Result<(Part, &'p [Step]), String> {
    let steps = &path.0;
    let Some(Step::Field(first)) = steps.first() else {
        return Err("a path starts with a part of the scene, such as `camera`".into());
    };
    Ok(match first.as_str() {
        "camera" => (Part::Camera, &steps[1..]),
        "ground" if scene.ground.is_some() => (Part::Ground, &steps[1..]),
        "ground" => return Err("the scene has no ground".into()),
        "point_light" if scene.point_light.is_some() => (Part::PointLight, &steps[1..]),
        "point_light" => return Err("the scene has no point light".into()),
        "environment" => (Part::Environment, &steps[1..]),
        "render" => (Part::Render, &steps[1..]),
        "spheres" => {
            let list: Vec<&str> = scene
                .spheres
                .iter()
                .map(|s| s.name.as_str())
                .collect::<Vec<&str>>();
            let i = element(steps.get(1), &list, "sphere", "spheres")?;
            (Part::Sphere(i), &steps[2..])
        }
        "cylinders" => {
            let list: Vec<&str> = scene
                .cylinders
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<&str>>();
            let i = element(steps.get(1), &list, "cylinder", "cylinders")?;
            (Part::Cylinder(i), &steps[2..])
        }
        "polygons" => {
            let list: Vec<&str> = scene
                .polygons
                .iter()
                .map(|p| p.name.as_str())
                .collect::<Vec<&str>>();
            let i = element(steps.get(1), &list, "polygon", "polygons")?;
            (Part::Polygon(i), &steps[2..])
        }
        "meshes" => {
            let list: Vec<&str> = scene
                .meshes
                .iter()
                .map(|m| m.name.as_str())
                .collect::<Vec<&str>>();
            let i = element(steps.get(1), &list, "mesh", "meshes")?;
            let mesh = &scene.meshes[i];
            match steps.get(2) {
                Some(Step::Field(f)) if f == "placement" => (Part::MeshPlacement(i), &steps[3..]),
                Some(Step::Field(f)) if f == "materials" => {
                    let list: Vec<&str> = mesh
                        .materials
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect::<Vec<&str>>();
                    let j = element(steps.get(3), &list, "material", "materials")?;
                    match steps.get(4) {
                        Some(Step::Field(f)) if f == "material" => {
                            (Part::MeshMaterial(i, j), &steps[5..])
                        }
                        _ => return Err("a mesh material's numbers are under `.material`".into()),
                    }
                }
                _ => return Err("a mesh's numbers are under `.placement` or `.materials`".into()),
            }
        }
        other => {
            return Err(format!(
                "`{other}` is not an animatable part of the scene (camera, spheres, cylinders, \
                 polygons, ground, meshes, point_light, environment, render)"
            ));
        }
    })
}

/// The value `steps` lead to inside a part's tree, and the same steps
/// with each list element named as `naming` asks.
///
/// A texture written as its value (`specular: 0.04`, `diffuse: (0.8, 0.1,
/// 0.1)`: a constant's short form) holds that value in its `a` (and `b`):
/// `….specular.a` names it whichever form the preset uses, as the panel's
/// key button does, so a key on a constant stays on the same number when
/// the constant becomes a pattern and the preset writes it whole.
fn descend<'v>(
    tree: &'v mut Value,
    steps: &[Step],
    naming: Naming,
) -> Result<(&'v mut Value, Vec<Step>), String> {
    let mut at = tree;
    let mut named = Vec::with_capacity(steps.len());
    let mut holder: Option<&Step> = None;
    for step in steps {
        let short_constant = matches!(holder, Some(Step::Field(f)) if is_texture_root(f))
            && matches!(step, Step::Field(f) if f == "a" || f == "b")
            && numbers(at).is_some();
        named.push(step.clone());
        if !short_constant {
            at = through_variant(at, step);
            if let (Step::Index(_) | Step::Name(_), Value::Array(list)) = (step, &*at) {
                let names: Vec<&str> = list
                    .iter()
                    .map(|v| v.get("name").and_then(Value::as_str).unwrap_or(""))
                    .collect();
                let i = match step {
                    Step::Index(i) => Some(*i),
                    _ => names
                        .iter()
                        .position(|n| Step::Name((*n).to_owned()) == *step),
                };
                if let Some(i) = i.filter(|&i| i < names.len()) {
                    *named.last_mut().expect("pushed") = naming.element(&names, i);
                }
            }
            at = child(at, step)?;
        }
        holder = Some(step);
    }
    Ok((at, named))
}

/// How a path names the elements of lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Naming {
    /// By name where the element has one no other shares (`spheres["marble"]`),
    /// by index otherwise: the names the CLI lists and keys are saved under,
    /// which stay true when elements are added or reordered.
    Names,
    /// By index (`spheres[0]`): the names the panel builds from where a
    /// control sits.
    Indices,
}

impl Naming {
    /// The step naming element `i` of a list whose elements are named
    /// `names` ("" for none).
    fn element(self, names: &[&str], i: usize) -> Step {
        let name = names[i];
        let unique = names.iter().filter(|n| **n == name).count() == 1;
        if self == Naming::Names && !name.is_empty() && unique {
            Step::Name(name.to_owned())
        } else {
            Step::Index(i)
        }
    }
}

/// Whether a material's field of this name holds a texture tree (a
/// property, the bump, a layer's mask), which a preset may write as its
/// value.
fn is_texture_root(field: &str) -> bool {
    field == "bump" || field == "mask" || Property::ALL.iter().any(|p| p.name() == field)
}

/// What a step does to a value tree, read-only or not.
fn child<'v>(value: &'v mut Value, step: &Step) -> Result<&'v mut Value, String> {
    let value = through_variant(value, step);
    match (step, value) {
        (Step::Field(name), Value::Object(map)) => {
            if !map.contains_key(name.as_str()) {
                return Err(format!(
                    "no field `{name}` here (it has {})",
                    known_fields(map)
                ));
            }
            Ok(map.get_mut(name.as_str()).expect("checked"))
        }
        (Step::Index(i), Value::Array(list)) => {
            let len = list.len();
            list.get_mut(*i)
                .ok_or_else(|| format!("no element [{i}]: the list has {len}"))
        }
        (Step::Name(n), Value::Array(list)) => list
            .iter_mut()
            .find(|v| v.get("name").and_then(Value::as_str) == Some(n.as_str()))
            .ok_or_else(|| format!("no element named \"{n}\" here")),
        (Step::Field(name), _) => Err(format!("no field `{name}`: this is not a struct")),
        (_, _) => Err("this is not a list".into()),
    }
}

fn known_fields(map: &serde_json::Map<String, Value>) -> String {
    let names: Vec<&str> = map.keys().map(String::as_str).collect();
    names.join(", ")
}

/// An enum's value is `{"Variant": inner}` in serde's value tree; a path
/// goes through it without naming the variant (unless it does name it).
fn through_variant<'v>(value: &'v mut Value, step: &Step) -> &'v mut Value {
    let is_variant = |map: &serde_json::Map<String, Value>| {
        map.len() == 1
            && map
                .keys()
                .next()
                .is_some_and(|k| k.starts_with(|c: char| c.is_ascii_uppercase()))
            && !matches!(step, Step::Field(f) if map.contains_key(f.as_str()))
    };
    if matches!(&*value, Value::Object(map) if is_variant(map))
        && let Value::Object(map) = value
    {
        return map.values_mut().next().expect("one entry");
    }
    value
}

/// The numbers at the end of a path: one, or a vector's components.
fn numbers(value: &Value) -> Option<Vec<f32>> {
    match value {
        Value::Number(n) => Some(vec![n.as_f64()? as f32]),
        Value::Array(items) if !items.is_empty() => {
            items.iter().map(|v| v.as_f64().map(|x| x as f32)).collect()
        }
        _ => None,
    }
}

/// Writes `components` over the number(s) at `value`, keeping an integer
/// an integer (an octave count written as `6`, a polygon's sides).
fn write_numbers(value: &mut Value, components: &[f32]) -> Result<(), String> {
    let count = numbers(value)
        .ok_or("not a number or a vector of numbers")?
        .len();
    if count != components.len() {
        return Err(format!(
            "the parameter has {count} component(s), the key {}",
            components.len()
        ));
    }
    let write = |slot: &mut Value, x: f32| {
        *slot = if slot.is_u64() {
            Value::from(x.round().max(0.0) as u64)
        } else if slot.is_i64() {
            Value::from(x.round() as i64)
        } else {
            Value::from(f64::from(x))
        };
    };
    match value {
        Value::Array(items) => items
            .iter_mut()
            .zip(components)
            .for_each(|(slot, &x)| write(slot, x)),
        slot => write(slot, components[0]),
    }
    Ok(())
}

/// Writes `components` at `steps` inside one part, typed `T`.
fn write_through<T: Serialize + DeserializeOwned>(
    part: &mut T,
    steps: &[Step],
    components: &[f32],
) -> Result<(), String> {
    let mut tree = to_tree(&*part);
    write_numbers(descend(&mut tree, steps, Naming::Indices)?.0, components)?;
    *part = serde_json::from_value(tree).map_err(|e| format!("the new value: {e}"))?;
    Ok(())
}

/// The path of one part of the scene, its list elements named as `naming`
/// asks.
fn part_path(scene: &Scene, part: Part, naming: Naming) -> ParamPath {
    let root = |name: &str| ParamPath(vec![Step::Field(name.to_owned())]);
    let element = |list: &str, names: Vec<&str>, i: usize| {
        let mut path = root(list);
        path.0.push(naming.element(&names, i));
        path
    };
    let meshes = || scene.meshes.iter().map(|m| m.name.as_str()).collect();
    match part {
        Part::Camera => root("camera"),
        Part::Sphere(i) => element(
            "spheres",
            scene.spheres.iter().map(|s| s.name.as_str()).collect(),
            i,
        ),
        Part::Cylinder(i) => element(
            "cylinders",
            scene.cylinders.iter().map(|c| c.name.as_str()).collect(),
            i,
        ),
        Part::Polygon(i) => element(
            "polygons",
            scene.polygons.iter().map(|p| p.name.as_str()).collect(),
            i,
        ),
        Part::Ground => root("ground"),
        Part::MeshPlacement(i) => element("meshes", meshes(), i).field("placement"),
        Part::MeshMaterial(i, j) => {
            let mut path = element("meshes", meshes(), i).field("materials");
            let names = scene.meshes[i]
                .materials
                .iter()
                .map(|m| m.name.as_str())
                .collect::<Vec<_>>();
            path.0.push(naming.element(&names, j));
            path.field("material")
        }
        Part::PointLight => root("point_light"),
        Part::Environment => root("environment"),
        Part::Render => root("render"),
    }
}

/// The value tree of one part of the scene.
fn part_tree(scene: &Scene, part: Part) -> Value {
    match part {
        Part::Camera => to_tree(&scene.camera),
        Part::Sphere(i) => to_tree(&scene.spheres[i]),
        Part::Cylinder(i) => to_tree(&scene.cylinders[i]),
        Part::Polygon(i) => to_tree(&scene.polygons[i]),
        Part::Ground => to_tree(scene.ground.as_ref().expect("located")),
        Part::MeshPlacement(i) => to_tree(&scene.meshes[i].placement),
        Part::MeshMaterial(i, j) => to_tree(&scene.meshes[i].materials[j].material),
        Part::PointLight => to_tree(scene.point_light.as_ref().expect("located")),
        Part::Environment => to_tree(&scene.environment),
        Part::Render => to_tree(&scene.render),
    }
}

impl Scene {
    /// The number(s) at `path`, or why the path names none. Only the part
    /// the path starts in is read (the panel asks for each keyed number
    /// every frame).
    pub fn parameter(&self, path: &ParamPath) -> Result<Vec<f32>, String> {
        let (part, steps) = locate(self, path)?;
        let mut tree = part_tree(self, part);
        numbers(descend(&mut tree, steps, Naming::Indices)?.0)
            .ok_or_else(|| "not a number or a vector of numbers".to_owned())
    }

    /// Sets the number(s) at `path`.
    pub fn set_parameter(&mut self, path: &ParamPath, components: &[f32]) -> Result<(), String> {
        let (part, steps) = locate(self, path)?;
        let c = components;
        match part {
            Part::Camera => write_through(&mut self.camera, steps, c),
            Part::Sphere(i) => write_through(&mut self.spheres[i], steps, c),
            Part::Cylinder(i) => write_through(&mut self.cylinders[i], steps, c),
            Part::Polygon(i) => write_through(&mut self.polygons[i], steps, c),
            Part::Ground => write_through(self.ground.as_mut().expect("located"), steps, c),
            Part::MeshPlacement(i) => write_through(&mut self.meshes[i].placement, steps, c),
            Part::MeshMaterial(i, j) => {
                write_through(&mut self.meshes[i].materials[j].material, steps, c)
            }
            Part::PointLight => {
                write_through(self.point_light.as_mut().expect("located"), steps, c)
            }
            Part::Environment => write_through(&mut self.environment, steps, c),
            Part::Render => write_through(&mut self.render, steps, c),
        }
    }

    /// `path` with its list elements named as `naming` asks: a parameter
    /// named by index and by name has one name of each kind, which is
    /// how the panel (by index) and the tracks (by name) find each other.
    pub fn parameter_name(&self, path: &ParamPath, naming: Naming) -> Result<ParamPath, String> {
        let (part, steps) = locate(self, path)?;
        let mut tree = part_tree(self, part);
        let (_, inside) = descend(&mut tree, steps, naming)?;
        let mut name = part_path(self, part, naming);
        name.0.extend(inside);
        Ok(name)
    }

    /// Every animatable parameter of the scene with its current value: the
    /// list the tests check round-trips, and the CLI prints.
    pub fn animatable_parameters(&self) -> Vec<(ParamPath, Vec<f32>)> {
        let mut out = Vec::new();
        for part in parts(self) {
            let path = part_path(self, part, Naming::Names);
            leaves(&part_tree(self, part), path, &mut out);
        }
        out
    }
}

/// Every part of `scene`, in the order the CLI lists them.
fn parts(scene: &Scene) -> Vec<Part> {
    let mut all = vec![Part::Camera];
    all.extend((0..scene.spheres.len()).map(Part::Sphere));
    all.extend((0..scene.cylinders.len()).map(Part::Cylinder));
    all.extend((0..scene.polygons.len()).map(Part::Polygon));
    all.extend(scene.ground.as_ref().map(|_| Part::Ground));
    for (i, mesh) in scene.meshes.iter().enumerate() {
        all.push(Part::MeshPlacement(i));
        all.extend((0..mesh.materials.len()).map(|j| Part::MeshMaterial(i, j)));
    }
    all.extend(scene.point_light.as_ref().map(|_| Part::PointLight));
    all.extend([Part::Environment, Part::Render]);
    all
}

fn to_tree<T: Serialize>(part: &T) -> Value {
    serde_json::to_value(part).expect("a scene part serialises")
}

/// The numbers and vectors of numbers under `value`, each with its path.
fn leaves(value: &Value, path: ParamPath, out: &mut Vec<(ParamPath, Vec<f32>)>) {
    if let Some(n) = numbers(value) {
        // A texture written as its value: named by its `a`, as `descend`
        // reads it and the panel's key button names it.
        let path = match path.0.last() {
            Some(Step::Field(f)) if is_texture_root(f) => path.field("a"),
            _ => path,
        };
        out.push((path, n));
        return;
    }
    match value {
        Value::Object(map)
            if map.len() == 1
                && map
                    .keys()
                    .all(|k| k.starts_with(|c: char| c.is_ascii_uppercase())) =>
        {
            leaves(map.values().next().expect("one entry"), path, out);
        }
        Value::Object(map) => {
            for (name, v) in map {
                leaves(v, path.field(name), out);
            }
        }
        Value::Array(items) => {
            let names: Vec<&str> = items
                .iter()
                .map(|v| v.get("name").and_then(Value::as_str).unwrap_or(""))
                .collect();
            for (i, v) in items.iter().enumerate() {
                let mut at = path.clone();
                at.0.push(Naming::Names.element(&names, i));
                leaves(v, at, out);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_parse_and_print_alike() {
        for text in [
            "camera.fov_degrees",
            "spheres[\"marble\"].material.diffuse.ramp[2].position",
            "point_light.position[1]",
            "meshes[0].materials[\"light\"].material.emission_strength",
        ] {
            assert_eq!(ParamPath::parse(text).unwrap().to_string(), text);
        }
        for bad in [
            "",
            "camera..fov",
            "spheres[x]",
            "spheres[0",
            "[0]",
            "camera fov",
        ] {
            assert!(ParamPath::parse(bad).is_err(), "`{bad}` parsed");
        }
    }
}
