//! The critical view of safety as surgeons document it, a doublet of pictures: the
//! hepatocystic triangle from the front, as the laparoscope saw it, and from behind, as seen
//! with the gallbladder turned over; each with the criteria it shows marked met or not. Drawn
//! from what the view was judged on ([`ViewRecord`]) when it was reached, or last when it
//! never was: the tubes as they were, the fat left, the clips, the lower third's ties to the
//! liver bed, and the organs around at rest (as the sight lines meet them).

use std::path::Path;

use nalgebra::Vector3;
use plotters::prelude::*;

use super::plot::{Area, PlotResult, draw_rgb, save_png};
use crate::biliary::view_record::{TieMark, TubeShape};
use crate::biliary::{CriticalView, Structure, ViewRecord};

/// The picture's size, each panel's, and the band of criteria under them (pixels).
pub const SIZE: (u32, u32) = (1200, 760);
pub const PANEL: (u32, u32) = (600, 560);
const TITLE_PX: u32 = 40;

const DUCT: RGBColor = RGBColor(60, 170, 90);
const COMMON_DUCT: RGBColor = RGBColor(25, 105, 60);
const ARTERY: RGBColor = RGBColor(200, 40, 40);
pub const FAT: RGBColor = RGBColor(235, 200, 90);
const CLIP: RGBColor = RGBColor(150, 150, 165);
const CLIP_OPEN: RGBColor = RGBColor(240, 130, 20);
const TIE_HOLDING: RGBColor = RGBColor(190, 30, 150);
const TIE_RELEASED: RGBColor = RGBColor(40, 160, 220);
const MET: RGBColor = RGBColor(20, 140, 50);
const NOT_MET: RGBColor = RGBColor(200, 30, 30);

/// The colour a structure is drawn in.
pub fn colour_of(structure: Structure) -> RGBColor {
    match structure {
        Structure::CysticDuct => DUCT,
        Structure::CommonDuct => COMMON_DUCT,
        Structure::CysticArtery => ARTERY,
    }
}

/// A colour's red, green and blue.
pub fn rgb(colour: RGBColor) -> [u8; 3] {
    [colour.0, colour.1, colour.2]
}

/// Which side a panel looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Side {
    /// From the laparoscope's optic.
    Front,
    /// From the optic's mirror image through the triangle's centre.
    Behind,
}

/// A perspective view of the triangle into one panel.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    eye_m: Vector3<f64>,
    forward: Vector3<f64>,
    right: Vector3<f64>,
    up: Vector3<f64>,
    /// Pixels per unit of the image plane, and the panel's top left corner in the picture.
    scale: f64,
    origin_px: (i32, i32),
}

impl Projection {
    /// The view of `record` from `side`, fitted to its panel; the head is up.
    pub fn new(record: &ViewRecord, side: Side) -> Self {
        let centre_m = record.centre_m();
        let (eye_m, towards) = match side {
            Side::Front => (record.optic_m, centre_m - record.optic_m),
            Side::Behind => (2.0 * centre_m - record.optic_m, record.optic_m - centre_m),
        };
        let forward = towards.try_normalize(1e-12).unwrap_or(-Vector3::y());
        let right = (forward.cross(&Vector3::z()))
            .try_normalize(1e-9)
            .unwrap_or(Vector3::x());
        let up = right.cross(&forward);
        let left_px = match side {
            Side::Front => 0,
            Side::Behind => PANEL.0 as i32,
        };
        let mut projection = Self {
            eye_m,
            forward,
            right,
            up,
            scale: 1.0,
            origin_px: (left_px, TITLE_PX as i32),
        };
        projection.scale = projection.fit(record);
        projection
    }

    /// The scale that fits every tube node within the panel, with a margin.
    fn fit(&self, record: &ViewRecord) -> f64 {
        let reach = (record.tubes.iter().flat_map(|t| &t.positions_m))
            .filter_map(|p| self.on_plane(p))
            .map(|(x, y)| x.abs().max(y.abs()))
            .fold(1e-6, f64::max);
        0.34 * f64::from(PANEL.0.min(PANEL.1)) / reach
    }

    /// Where `p_m` falls on the image plane at unit distance; `None` behind the eye.
    fn on_plane(&self, p_m: &Vector3<f64>) -> Option<(f64, f64)> {
        let q = p_m - self.eye_m;
        let depth = q.dot(&self.forward);
        (depth > 1e-6).then(|| (q.dot(&self.right) / depth, q.dot(&self.up) / depth))
    }

    /// How far `p_m` lies from the eye along the view (m).
    fn depth_m(&self, p_m: &Vector3<f64>) -> f64 {
        (p_m - self.eye_m).dot(&self.forward)
    }

    /// The pixel in the panel where `p_m` is drawn; `None` behind the eye.
    fn pixel(&self, p_m: &Vector3<f64>) -> Option<(i32, i32)> {
        let (x, y) = self.on_plane(p_m)?;
        Some((
            (0.5 * f64::from(PANEL.0) + x * self.scale).round() as i32,
            (0.5 * f64::from(PANEL.1) - y * self.scale).round() as i32,
        ))
    }

    /// The pixel in the whole picture where `p_m` is drawn; `None` behind the eye.
    pub fn in_picture(&self, p_m: &Vector3<f64>) -> Option<(i32, i32)> {
        let (x, y) = self.pixel(p_m)?;
        Some((self.origin_px.0 + x, self.origin_px.1 + y))
    }

    /// A length `length_m` at `p_m` in pixels, at least one.
    fn pixels(&self, length_m: f64, p_m: &Vector3<f64>) -> u32 {
        let depth = self.depth_m(p_m).max(1e-6);
        (length_m / depth * self.scale).round().max(1.0) as u32
    }
}

/// One thing to draw, at its depth from the eye.
struct Mark {
    depth_m: f64,
    shape: Shape,
}

enum Shape {
    Triangle([(i32, i32); 3], RGBAColor),
    Stroke([(i32, i32); 2], RGBAColor, u32),
    Dot((i32, i32), RGBColor, u32),
}

/// Writes the doublet of `record` into `path` (a 1200 × 760 PNG); errors name the file.
pub fn draw_critical_view(path: &Path, record: &ViewRecord) -> Result<(), String> {
    let drawn = save_png(path, SIZE, |root| draw_doublet(root, record));
    drawn.map_err(|e| format!("{}: {e}", path.display()))
}

/// The doublet of `record` as RGB rows of [`SIZE`], top first: for the window's debrief.
pub fn critical_view_rgb(record: &ViewRecord) -> Result<Vec<u8>, String> {
    draw_rgb(SIZE, |root| draw_doublet(root, record)).map_err(|e| e.to_string())
}

fn draw_doublet(root: &Area, record: &ViewRecord) -> PlotResult {
    root.draw(&Text::new(title(record), (16, 10), ("sans-serif", 24)))?;
    for side in [Side::Front, Side::Behind] {
        draw_panel(root, record, side)?;
    }
    draw_criteria(root, record)
}

fn title(record: &ViewRecord) -> String {
    let time = record.time_s.unwrap_or(0.0);
    if record.reached() {
        format!("Critical view of safety: reached at {time:.1} s")
    } else {
        format!("Critical view of safety: not reached (as judged last, at {time:.1} s)")
    }
}

/// One panel: the organs, the tubes, the fat and the clips far to near, and behind the
/// triangle the lower third's ties over them.
fn draw_panel(root: &Area, record: &ViewRecord, side: Side) -> PlotResult {
    let projection = Projection::new(record, side);
    let panel = root.clone().shrink(projection.origin_px, PANEL);
    let root = &panel;
    let mut marks = organ_marks(record, &projection, side);
    for tube in &record.tubes {
        marks.extend(tube_marks(tube, &projection));
    }
    marks.extend(fat_marks(record, &projection));
    marks.extend(clip_marks(record, &projection));
    marks.sort_by(|a, b| b.depth_m.total_cmp(&a.depth_m));
    for mark in &marks {
        draw_mark(root, &mark.shape)?;
    }
    if side == Side::Behind {
        for tie in &record.ties {
            draw_tie(root, tie, &projection)?;
        }
    }
    let caption = match side {
        Side::Front => "from the front: the laparoscope's view",
        Side::Behind => "from behind: the gallbladder turned over",
    };
    let veil = (12 + 9 * caption.len() as i32, 28);
    root.draw(&Rectangle::new([(1, 1), veil], WHITE.mix(0.8).filled()))?;
    root.draw(&Text::new(caption, (12, 6), ("sans-serif", 18)))?;
    let corner = (PANEL.0 as i32 - 1, PANEL.1 as i32 - 1);
    root.draw(&Rectangle::new([(0, 0), corner], BLACK.stroke_width(1)))?;
    Ok(())
}

/// The organs around the triangle, shaded by the light from the eye; from behind a veil of
/// them, so that the structures show through as they do with the gallbladder turned over.
fn organ_marks(record: &ViewRecord, projection: &Projection, side: Side) -> Vec<Mark> {
    let alpha = match side {
        Side::Front => 1.0,
        Side::Behind => 0.25,
    };
    let mut marks = Vec::new();
    for organ in &record.organs {
        let base = match organ.name.as_str() {
            "gallbladder" => (95.0, 125.0, 55.0),
            _ => (150.0, 75.0, 60.0),
        };
        for rest in &organ.triangles_m {
            let corners = rest.map(|c| c + organ.shift_m);
            let Some(pixels) = corners
                .iter()
                .map(|c| projection.pixel(c))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let normal = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
            let lit = normal
                .try_normalize(1e-18)
                .map_or(0.0, |n| n.dot(&projection.forward).abs());
            let shade = 0.45 + 0.55 * lit;
            let colour = RGBColor(
                (base.0 * shade) as u8,
                (base.1 * shade) as u8,
                (base.2 * shade) as u8,
            );
            let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
            marks.push(Mark {
                depth_m: projection.depth_m(&centre),
                shape: Shape::Triangle([pixels[0], pixels[1], pixels[2]], colour.mix(alpha)),
            });
        }
    }
    marks
}

/// A tube's undivided segments, as wide as the tube.
fn tube_marks<'a>(
    tube: &'a TubeShape,
    projection: &'a Projection,
) -> impl Iterator<Item = Mark> + 'a {
    let colour = colour_of(tube.structure);
    (tube.positions_m.windows(2).zip(&tube.divided))
        .filter(|(_, divided)| !**divided)
        .filter_map(move |(ends, _)| {
            let middle = (ends[0] + ends[1]) * 0.5;
            let width = projection.pixels(2.0 * tube.outer_radius_m, &middle);
            Some(Mark {
                depth_m: projection.depth_m(&middle),
                shape: Shape::Stroke(
                    [projection.pixel(&ends[0])?, projection.pixel(&ends[1])?],
                    colour.to_rgba(),
                    width,
                ),
            })
        })
}

/// The strands of fat left.
fn fat_marks<'a>(
    record: &'a ViewRecord,
    projection: &'a Projection,
) -> impl Iterator<Item = Mark> + 'a {
    (record.fat.iter().filter(|s| !s.cleared)).filter_map(|strand| {
        let (from, to) = (strand.axis.from_m, strand.axis.to_m);
        let middle = (from + to) * 0.5;
        Some(Mark {
            depth_m: projection.depth_m(&middle),
            shape: Shape::Stroke(
                [projection.pixel(&from)?, projection.pixel(&to)?],
                FAT.mix(0.9),
                projection.pixels(2.0 * strand.radius_m, &middle),
            ),
        })
    })
}

/// The clips: grey where they close their tube, orange where they do not.
fn clip_marks<'a>(
    record: &'a ViewRecord,
    projection: &'a Projection,
) -> impl Iterator<Item = Mark> + 'a {
    record.clips.iter().filter_map(|clip| {
        let radius_m = (record.tubes.iter())
            .find(|t| t.structure == clip.structure)
            .map_or(1e-3, |t| t.outer_radius_m);
        let colour = if clip.closes_lumen { CLIP } else { CLIP_OPEN };
        Some(Mark {
            // Just in front of its tube.
            depth_m: projection.depth_m(&clip.at_m) - 2.0 * radius_m,
            shape: Shape::Dot(
                projection.pixel(&clip.at_m)?,
                colour,
                projection.pixels(1.5 * radius_m, &clip.at_m),
            ),
        })
    })
}

fn draw_mark(root: &Area, shape: &Shape) -> PlotResult {
    match *shape {
        Shape::Triangle(corners, colour) => {
            root.draw(&Polygon::new(corners.to_vec(), colour.filled()))?
        }
        Shape::Stroke(ends, colour, width) => {
            root.draw(&PathElement::new(ends.to_vec(), colour.stroke_width(width)))?;
            // Round the joints between a tube's segments.
            for end in ends {
                root.draw(&Circle::new(end, width / 2, colour.filled()))?;
            }
        }
        Shape::Dot(centre, colour, radius) => {
            root.draw(&Circle::new(centre, radius, colour.filled()))?;
            root.draw(&Circle::new(centre, radius, BLACK.stroke_width(1)))?;
        }
    }
    Ok(())
}

fn draw_tie(root: &Area, tie: &TieMark, projection: &Projection) -> PlotResult {
    let Some(at) = projection.pixel(&tie.at_m) else {
        return Ok(());
    };
    let colour = if tie.released {
        TIE_RELEASED
    } else {
        TIE_HOLDING
    };
    root.draw(&Circle::new(at, 4, colour.filled()))?;
    Ok(())
}

/// The criteria under the panels, each met or not, and the legend.
fn draw_criteria(root: &Area, record: &ViewRecord) -> PlotResult {
    let top = (TITLE_PX + PANEL.1) as i32 + 12;
    let lines = record.view.as_ref().map(criteria).unwrap_or_default();
    for (k, (met, line)) in lines.iter().enumerate() {
        let (word, colour) = if *met {
            ("MET", MET)
        } else {
            ("NOT MET", NOT_MET)
        };
        let y = top + 26 * k as i32;
        root.draw(&Text::new(
            word,
            (16, y),
            ("sans-serif", 18).into_font().color(&colour),
        ))?;
        root.draw(&Text::new(line.as_str(), (110, y), ("sans-serif", 18)))?;
    }
    draw_legend(root, top + 26 * 3 + 4)
}

/// Each criterion: whether it is met, and what was measured against what was asked.
fn criteria(view: &CriticalView) -> Vec<(bool, String)> {
    let rule = &view.rule;
    let seen: Vec<String> = view
        .entering()
        .map(|e| format!("{} {:.0} %", e.structure.name(), 100.0 * e.seen_share))
        .collect();
    vec![
        (
            view.triangle_met(),
            format!(
                "1. the hepatocystic triangle cleared of fat: {:.0} % (asked {:.0} %)",
                100.0 * view.triangle_cleared,
                100.0 * rule.triangle_cleared
            ),
        ),
        (
            view.lower_third_met(),
            format!(
                "2. the gallbladder's lower third off the liver bed: {:.0} % (asked {:.0} %)",
                100.0 * view.lower_third_released,
                100.0 * rule.lower_third_released
            ),
        ),
        (
            view.two_structures_met(),
            format!(
                "3. two structures, and only two, seen entering the gallbladder: {} (asked {:.0} %)",
                seen.join(", "),
                100.0 * rule.seen_share
            ),
        ),
    ]
}

fn draw_legend(root: &Area, y: i32) -> PlotResult {
    let items = [
        ("cystic duct", DUCT),
        ("common duct", COMMON_DUCT),
        ("cystic artery", ARTERY),
        ("fat", FAT),
        ("clip", CLIP),
        ("clip not closing", CLIP_OPEN),
        ("tie holding", TIE_HOLDING),
        ("tie released", TIE_RELEASED),
    ];
    let mut x = 16;
    for (name, colour) in items {
        root.draw(&Rectangle::new(
            [(x, y + 2), (x + 14, y + 16)],
            colour.filled(),
        ))?;
        root.draw(&Text::new(name, (x + 20, y), ("sans-serif", 16)))?;
        x += 36 + 9 * name.len() as i32;
    }
    Ok(())
}
