//! Every shipped scenario opens on its organs: its start, drawn offscreen, shows each of its
//! organs somewhere in the image (through a laparoscope, at least the one it is aimed at), and
//! the image is not one colour. A screenshot of each, on software Vulkan, is the slow tier's
//! (docs/development.md): the fast tier draws four shipped scenarios' windows (free play on the
//! default organs, the laparoscope, the keratotomy, an incision) and runs every scenario's
//! scene through its scripted attempts, so what only this test sees is one scenario whose
//! start frames none of its organs.

use std::path::Path;

use nalgebra::Vector3;
use pgd_surgery::scenario::load;

use super::{distance, held_at, scenario_shot};

#[test]
#[ignore = "slow tier: a screenshot of every shipped scenario (docs/development.md)"]
fn every_shipped_scenario_opens_on_its_organs() {
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
        let name = file
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .replace(".scenario", "");
        // The device's handle half a metre up, scaled as the scenario scales it.
        let held = held_at(Vector3::new(0.0, 0.5, 0.0));
        let shot = scenario_shot(&format!("start-{name}"), &file, 2, held);
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
