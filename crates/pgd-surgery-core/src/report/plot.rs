//! PNG plots drawn by plotters into a pixel buffer (no image crate, no system fonts: the font
//! is embedded) and encoded by png, which Bevy already builds.

use std::path::Path;

use plotters::prelude::*;

/// DejaVu Sans, shipped with the product so that its text needs nothing from the system: the
/// plots' font, and the trainer window's.
pub const FONT_DATA: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");

/// The characters of `text` the shipped font has no glyph for (each once, in order; line
/// breaks aside): the window and the web page would draw them as boxes.
pub fn without_glyph(text: &str) -> Vec<char> {
    use ab_glyph::Font;
    let Ok(font) = ab_glyph::FontRef::try_from_slice(FONT_DATA) else {
        return Vec::new();
    };
    let mut missing: Vec<char> = Vec::new();
    for c in text.chars() {
        if c != '\n' && font.glyph_id(c).0 == 0 && !missing.contains(&c) {
            missing.push(c);
        }
    }
    missing
}

/// A whole plot's drawing area.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

pub type PlotResult = Result<(), Box<dyn std::error::Error>>;

/// Draws the chart's legend at `position`, framed on a veil of white over the plot.
pub fn draw_legend<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> PlotResult {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// A line series' mark in the legend: a 20-pixel stroke in the series' style.
pub fn legend_stroke(
    style: impl Into<ShapeStyle>,
) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    let style = style.into();
    move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style)
}

/// Draws a `size` plot on white with `draw` (fonts: "sans-serif") and saves it as a PNG.
pub fn save_png(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> PlotResult,
) -> PlotResult {
    let pixels = draw_rgb(size, draw)?;
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, size.0, size.1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&pixels)?;
    Ok(())
}

/// Draws a `size` plot on white with `draw` into RGB rows, top first.
pub fn draw_rgb(
    size: (u32, u32),
    draw: impl FnOnce(&Area) -> PlotResult,
) -> Result<Vec<u8>, Box<dyn std::error::Error>> {
    // Plotters draws text with a registered font only off the web; the page draws no plots.
    #[cfg(not(target_arch = "wasm32"))]
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_DATA)
        .map_err(|_| "the embedded font could not be read")?;
    let (width, height) = size;
    let mut pixels = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(pixels)
}

/// One named line of a [`LineChart`].
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Lines against a common x axis, each in its own colour with a legend; the axes span the
/// data.
pub struct LineChart<'a> {
    pub title: String,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: Vec<Series>,
}

/// Draws `chart` into a 900 × 600 PNG at `path`; errors name the file.
pub fn line_chart(path: &Path, chart: &LineChart) -> Result<(), String> {
    let points = || chart.series.iter().flat_map(|s| s.points.iter().copied());
    let span = |values: Vec<f64>| {
        let low = values.iter().copied().fold(f64::INFINITY, f64::min);
        let high = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let pad = 0.05 * (high - low).max(1e-9 * high.abs().max(1e-12));
        (low - pad)..(high + pad)
    };
    let (xs, ys) = (
        span(points().map(|p| p.0).collect()),
        span(points().map(|p| p.1).collect()),
    );
    let colours = [BLUE, RED, GREEN, MAGENTA, CYAN];
    save_png(path, (900, 600), |root| {
        let mut drawing = ChartBuilder::on(root)
            .caption(&chart.title, ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d(xs, ys)?;
        drawing
            .configure_mesh()
            .x_desc(chart.x_label)
            .y_desc(chart.y_label)
            .draw()?;
        for (series, colour) in chart.series.iter().zip(colours.iter().cycle()) {
            let colour = *colour;
            drawing
                .draw_series(LineSeries::new(
                    series.points.iter().copied(),
                    colour.stroke_width(2),
                ))?
                .label(series.name.as_str())
                .legend(legend_stroke(colour.stroke_width(2)));
        }
        draw_legend(&mut drawing, SeriesLabelPosition::LowerLeft)?;
        Ok(())
    })
    .map_err(|e| format!("{}: {e}", path.display()))
}
