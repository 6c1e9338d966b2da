//! PNG plots drawn by plotters into a pixel buffer (no image crate, no system fonts: the font
//! is embedded) and encoded by png, which Bevy already builds.

use std::path::Path;

use plotters::prelude::*;

/// The plots' font, shipped with the crate so that plots need nothing from the system.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// A whole plot's drawing area.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

pub type PlotResult = Result<(), Box<dyn std::error::Error>>;

/// Draws a `size` plot on white with `draw` (fonts: "sans-serif") and saves it as a PNG.
pub fn save_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> PlotResult,
) -> PlotResult {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font could not be read")?;
    let (width, height) = size;
    let mut pixels = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&pixels)?;
    Ok(())
}
