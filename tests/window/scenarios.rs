//! Every shipped scenario opens on its organs: its start, drawn offscreen, shows each of its
//! organs somewhere in the image (through a laparoscope, at least the one it is aimed at), and
//! the image is not one colour.

use std::path::Path;

use nalgebra::Vector3;
use pgd_surgery::app::attempt::scenario_scene;
use pgd_surgery::app::scene::Detail;
use pgd_surgery::scenario::load;
use pgd_surgery::store::OnStale;

use super::{Surface, distance, held_at, shot_of, vademecums};

#[test]
fn every_shipped_scenario_opens_on_its_organs() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<_> = std::fs::read_dir(&shipped)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.to_string_lossy().ends_with(".scenario.ron"))
        .collect();
    files.sort();
    assert!(files.len() >= 11, "{} scenarios", files.len());
    for file in files {
        let scenario = load(&file).unwrap();
        scenario_scene(&scenario, vademecums(), Detail::Coarse, OnStale::Rebuild).unwrap();
        let name = file
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .replace(".scenario", "");
        let history = dir.join(format!("{name}-history.sqlite"));
        let args = [
            "run",
            file.to_str().unwrap(),
            "--frames",
            "2",
            "--history",
            history.to_str().unwrap(),
        ];
        // The device's handle half a metre up, scaled as the scenario scales it.
        let shot = shot_of(
            &format!("start-{name}"),
            held_at(Vector3::new(0.0, 0.5, 0.0)),
            &args,
            Surface::Offscreen,
        );
        // Through a laparoscope, what the optic is aimed at; otherwise every organ.
        let in_sight = |organ: &str| {
            let drawn = shot.legend.organs.iter().find(|o| o.name == organ);
            drawn.is_some_and(|o| !o.visible_px.is_empty())
        };
        let seen = scenario.organs.iter().filter(|o| in_sight(&o.name)).count();
        let needed = match scenario.laparoscope {
            Some(_) => 1,
            None => scenario.organs.len(),
        };
        assert!(
            seen >= needed,
            "{name}: {seen} organs in sight, {needed} needed"
        );
        let first = [0, 1, 2].map(|c| f32::from(shot.rgb[c]));
        let differ = shot
            .rgb
            .chunks(3)
            .filter(|p| distance([p[0], p[1], p[2]].map(f32::from), first) > 30.0)
            .count();
        assert!(
            differ * 20 > shot.rgb.len() / 3,
            "{name}: the image is nearly one colour"
        );
    }
}
