//! Every character the trainer's text can print has a glyph in its font (DejaVu Sans, shipped
//! in `assets/fonts`): a missing one shows as a box in the window and the web page.

use ab_glyph::{Font, FontRef};
use pgd_surgery::report::FONT_DATA;

/// The characters of `text` the shipped font has no glyph for (line breaks aside).
pub fn without_glyph(text: &str) -> Vec<char> {
    let font = FontRef::try_from_slice(FONT_DATA).expect("the shipped font parses");
    let mut missing: Vec<char> = text
        .chars()
        .filter(|&c| c != '\n' && font.glyph_id(c).0 == 0)
        .collect();
    missing.dedup();
    missing
}

/// The signs the debrief and the HUD print beyond ASCII have glyphs; a character no font
/// here has (a private-use one) has none, so that the check can fail.
#[test]
fn the_font_has_the_signs_the_trainer_prints() {
    let printed = without_glyph("1.00× the shortest, 23.6 m/s³ rms, 12 µs, ±0.5 N, 4 °");
    assert!(printed.is_empty(), "{printed:?}");
    assert_eq!(without_glyph("\u{e000}"), ['\u{e000}']);
}
