//! The laparoscopic view, as the shipped laparoscopic scenario opens it: through the optic,
//! the organ it is aimed at is in the middle of the round image, in its tissue's colour, and
//! lit by the light at the optic's tip (without it only the faint ambient light reaches it).

use std::path::Path;

use nalgebra::Vector3;
use pgd_surgery::app::window::tissue::{mean_srgb, tissue};
use pgd_surgery::scenario::{load, metres};

use super::{Shot, held_at, hue_distance, hue_saturation, scenario_shot};

/// The shipped scenario with a time limit long enough that no debrief covers the view while
/// software rendering draws its first frames.
fn long_scenario(dir: &Path) -> std::path::PathBuf {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/liver-laparoscopic-press.scenario.ron");
    let text = std::fs::read_to_string(&shipped).unwrap();
    assert!(text.contains("time_limit_s: 20.0"));
    let file = dir.join("laparoscopic.scenario.ron");
    std::fs::write(
        &file,
        text.replace("time_limit_s: 20.0", "time_limit_s: 600.0"),
    )
    .unwrap();
    file
}

fn laparoscopic_shot() -> (Shot, [f32; 2]) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("window");
    std::fs::create_dir_all(&dir).unwrap();
    let file = long_scenario(&dir);
    let scenario = load(&file).unwrap();
    let focus = metres(scenario.laparoscope.as_ref().unwrap().look_at_mm);
    // The probe held 30 mm above the point looked at: its handle where the shaft puts it.
    let fulcrum = scenario.port.as_ref().unwrap().fulcrum();
    let handle = fulcrum
        .handle_for(&(focus + Vector3::new(0.0, 0.03, 0.0)))
        .unwrap();
    let shot = scenario_shot("laparoscopic", &file, 6, held_at(handle));
    let height = shot.rgb.len() / 3 / shot.width;
    let centre = [shot.width as f32 / 2.0, height as f32 / 2.0];
    (shot, centre)
}

#[test]
fn the_laparoscopic_view_shows_the_focus_organ_lit() {
    let (shot, centre) = laparoscopic_shot();
    let radius = centre[1];
    let liver = shot
        .legend
        .organs
        .iter()
        .find(|o| o.name == "liver")
        .expect("the liver is in the legend");
    // In the middle of the round image: within half its radius of the centre.
    let middle: Vec<[f32; 2]> = liver
        .visible_px
        .iter()
        .copied()
        .filter(|px| (px[0] - centre[0]).hypot(px[1] - centre[1]) < 0.5 * radius)
        .collect();
    assert!(
        middle.len() >= 3,
        "the liver is not in the middle of the view: {:?}",
        liver.visible_px
    );
    let reference = hue_saturation(mean_srgb(&tissue("liver")).map(f32::from)).0;
    let colours: Vec<[f32; 3]> = liver
        .visible_px
        .iter()
        .map(|&px| shot.colour_at(px))
        .collect();
    let own = colours
        .iter()
        .filter(|c| hue_distance(hue_saturation(**c).0, reference) < 25.0)
        .count();
    assert!(
        own * 4 >= colours.len() * 3,
        "{own} of {} pixels show liver tissue: {colours:?}",
        colours.len()
    );
    // Lit: the ambient light alone leaves the liver below 60 in every channel (its mean red
    // about 45), the tip's light well above 100.
    let red = colours.iter().map(|c| c[0]).sum::<f32>() / colours.len() as f32;
    assert!(red > 100.0, "the liver is dark: red {red:.0}");
}
