//! `marbre parameters`: every number of a preset a track can key, named
//! by the path the preset's tracks, the panel's key buttons and this list
//! share (`marbre_core::animation::ParamPath`), with its value; with
//! `--at T`, the values the scene's animation traces at T seconds.

use anyhow::{Result, bail};
use clap::Args;
use marbre_core::scene::Scene;
use marbre_render::session::load_scene;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ParametersArgs {
    /// The preset whose numbers are listed (its OBJ files' materials
    /// included).
    #[arg(long)]
    pub preset: PathBuf,
    /// The values at this time, in seconds, as the animation traces them.
    #[arg(long, allow_negative_numbers = true)]
    pub at: Option<f32>,
    /// Only the paths containing this text (such as `noise` or `camera`).
    #[arg(long)]
    pub filter: Option<String>,
}

pub fn run(args: &ParametersArgs) -> Result<()> {
    let loaded = load_scene(&args.preset, None)?;
    let scene = match args.at {
        Some(t) if !t.is_finite() => bail!("--at must be a number of seconds (got {t})"),
        Some(t) => loaded.scene.at_time(t),
        None => loaded.scene,
    };
    for line in lines(&scene, args.filter.as_deref()) {
        println!("{line}");
    }
    Ok(())
}

/// `path = value` for each animatable number of `scene` whose path
/// contains `filter`; a vector's value as `[x, y, z]`, as a key writes it.
fn lines(scene: &Scene, filter: Option<&str>) -> Vec<String> {
    scene
        .animatable_parameters()
        .into_iter()
        .map(|(path, value)| (path.to_string(), value))
        .filter(|(path, _)| filter.is_none_or(|f| path.contains(f)))
        .map(|(path, value)| match value.as_slice() {
            [x] => format!("{path} = {x}"),
            v => {
                let parts: Vec<String> = v.iter().map(f32::to_string).collect();
                format!("{path} = [{}]", parts.join(", "))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use marbre_core::animation::ParamPath;

    /// Each line's path reads back its value from the scene: the list is
    /// what a track may name.
    #[test]
    fn every_line_names_a_number_of_the_scene() {
        let file =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../presets/default.ron");
        let scene = marbre_core::preset::load(&file).unwrap().preset.scene;
        let all = lines(&scene, None);
        assert!(
            all.contains(&"camera.fov_degrees = 40".to_owned()),
            "{all:#?}"
        );
        assert!(
            all.contains(&"camera.target = [0, 0.8, 0]".to_owned()),
            "{all:#?}"
        );
        for line in &all {
            let (path, _) = line.split_once(" = ").unwrap();
            let path = ParamPath::parse(path).unwrap();
            assert!(scene.parameter(&path).is_ok(), "{line}");
        }
        let noise = lines(&scene, Some("noise.fractal.frequency"));
        assert_eq!(
            noise.len(),
            5,
            "the spheres' five noise patterns: {noise:?}"
        );
    }
}
