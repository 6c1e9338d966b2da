//! The keratotomy's window: the camera looks down on the cornea, which fills the middle of
//! the image (the abdomen's camera would show it as a speck), with its optical zone inked in
//! green on it.

use std::path::Path;

use nalgebra::Vector3;

use super::{held_at, hue_saturation, scenario_shot};

#[test]
fn the_keratotomy_looks_down_on_the_cornea() {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios/cornea-radial-keratotomy.scenario.ron");
    // The knife held 3 mm above the apex, off to the side (the hand moves ten times as far).
    let held = held_at(Vector3::new(0.004, 0.0, 0.003) / 0.1);
    let shot = scenario_shot("cornea", &shipped, 4, held);
    let height = (shot.rgb.len() / 3 / shot.width) as f32;
    let width = shot.width as f32;
    let cornea = shot
        .legend
        .organs
        .iter()
        .find(|o| o.name == "cornea")
        .expect("the cornea is in the legend");
    let xs = cornea.visible_px.iter().map(|p| p[0]);
    let (left, right) = xs.fold((f32::MAX, f32::MIN), |(l, r), x| (l.min(x), r.max(x)));
    assert!(
        right - left > 0.25 * width,
        "the cornea spans {:.0} of {width} pixels",
        right - left
    );
    let middle = (left + right) / 2.0;
    assert!(
        (middle - width / 2.0).abs() < 0.1 * width,
        "off centre at {middle}"
    );
    // The optical zone's ring: green pixels (hue near 120°, saturated) in the middle third.
    let green = shot
        .rgb
        .chunks(3)
        .enumerate()
        .filter(|(k, _)| {
            let (x, y) = ((k % shot.width) as f32, (k / shot.width) as f32);
            (x - width / 2.0).abs() < width / 6.0 && (y - height / 2.0).abs() < height / 3.0
        })
        .filter(|(_, p)| {
            let (hue, saturation) = hue_saturation([p[0], p[1], p[2]].map(f32::from));
            (hue - 120.0).abs() < 30.0 && saturation > 0.5
        })
        .count();
    assert!(green > 50, "{green} green pixels: no optical zone inked");
}
