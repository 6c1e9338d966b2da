//! Procedural tissue textures, made at start-up (no image files to ship or download): a
//! mottled parenchyma with fine vessels, tileable so that a planar projection can repeat it
//! over an organ, plus a roughness map so the wet surface glints unevenly. Each organ's tissue
//! is seeded, so the textures are the same on every run.

use bevy::asset::RenderAssetUsages;
use bevy::image::{ImageAddressMode, ImageSampler, ImageSamplerDescriptor};
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

/// Texels along a side of a tile.
pub const TILE_TEXELS: usize = 256;
/// Metres of tissue one tile covers.
pub const TILE_M: f32 = 0.06;

/// The look of one organ's tissue (linear RGB).
pub struct Tissue {
    pub base: [f32; 3],
    /// The colour the mottling darkens towards.
    pub shade: [f32; 3],
    pub vessel: [f32; 3],
    /// Lattice cells of the coarsest noise per tile: more = finer lobules.
    pub lobules: usize,
    /// 0 = no vessels, 1 = dense.
    pub vessels: f32,
    pub seed: u64,
}

/// The tissue of an organ by name; an organ it does not know (one from a mesh file) gets a
/// neutral pink.
pub fn tissue(organ: &str) -> Tissue {
    let srgb = |r, g, b| Color::srgb(r, g, b).to_linear().to_f32_array_no_alpha();
    match organ {
        // Hues kept apart (liver brown-red, gallbladder green, pancreas yellow-tan, duodenum
        // rose) so that the organs read apart under any light; vessels keep their organ's hue.
        "liver" => Tissue {
            base: srgb(0.50, 0.19, 0.12),
            shade: srgb(0.32, 0.10, 0.06),
            vessel: srgb(0.26, 0.07, 0.05),
            lobules: 12,
            vessels: 0.5,
            seed: 11,
        },
        "gallbladder" => Tissue {
            base: srgb(0.30, 0.46, 0.20),
            shade: srgb(0.16, 0.30, 0.12),
            vessel: srgb(0.20, 0.34, 0.22),
            lobules: 4,
            vessels: 0.9,
            seed: 12,
        },
        "pancreas" => Tissue {
            base: srgb(0.88, 0.74, 0.52),
            shade: srgb(0.72, 0.56, 0.36),
            vessel: srgb(0.66, 0.44, 0.30),
            lobules: 16,
            vessels: 0.3,
            seed: 13,
        },
        "duodenum" => Tissue {
            base: srgb(0.82, 0.52, 0.60),
            shade: srgb(0.66, 0.36, 0.46),
            vessel: srgb(0.55, 0.18, 0.34),
            lobules: 6,
            vessels: 0.8,
            seed: 14,
        },
        // The cornea is clear: what shows through it is the iris, here a grey-blue one, with
        // no vessels (the cornea has none).
        "cornea" => Tissue {
            base: srgb(0.46, 0.54, 0.62),
            shade: srgb(0.28, 0.34, 0.42),
            vessel: srgb(0.28, 0.34, 0.42),
            lobules: 24,
            vessels: 0.0,
            seed: 20,
        },
        // The cavity around the organs: the parietal peritoneum over the walls, the stomach's
        // paler serosa, the colon's and small bowel's pink.
        "peritoneum" => Tissue {
            base: srgb(0.72, 0.36, 0.34),
            shade: srgb(0.56, 0.24, 0.24),
            vessel: srgb(0.50, 0.10, 0.14),
            lobules: 5,
            vessels: 1.0,
            seed: 16,
        },
        "stomach" => Tissue {
            base: srgb(0.80, 0.58, 0.54),
            shade: srgb(0.64, 0.42, 0.40),
            vessel: srgb(0.52, 0.16, 0.20),
            lobules: 7,
            vessels: 0.9,
            seed: 17,
        },
        "colon" => Tissue {
            base: srgb(0.78, 0.62, 0.50),
            shade: srgb(0.62, 0.46, 0.36),
            vessel: srgb(0.50, 0.22, 0.20),
            lobules: 6,
            vessels: 0.6,
            seed: 18,
        },
        "bowel" => Tissue {
            base: srgb(0.84, 0.54, 0.54),
            shade: srgb(0.68, 0.40, 0.42),
            vessel: srgb(0.55, 0.18, 0.26),
            lobules: 6,
            vessels: 0.8,
            seed: 19,
        },
        _ => Tissue {
            base: srgb(0.78, 0.55, 0.52),
            shade: srgb(0.60, 0.40, 0.38),
            vessel: srgb(0.55, 0.20, 0.22),
            lobules: 8,
            vessels: 0.5,
            seed: 15,
        },
    }
}

/// The tissue's colour tile (sRGB, RGBA8, `TILE_TEXELS` square) and its roughness tile
/// (metallic-roughness layout: roughness in green, no metal), both tileable.
pub fn texels(tissue: &Tissue) -> (Vec<u8>, Vec<u8>) {
    let mut colour = Vec::with_capacity(TILE_TEXELS * TILE_TEXELS * 4);
    let mut roughness = Vec::with_capacity(TILE_TEXELS * TILE_TEXELS * 4);
    let mottle = Noise::new(tissue.seed, tissue.lobules);
    let veins = Noise::new(tissue.seed + 100, 3);
    let wet = Noise::new(tissue.seed + 200, 5);
    for j in 0..TILE_TEXELS {
        for i in 0..TILE_TEXELS {
            let (u, v) = (i as f32 / TILE_TEXELS as f32, j as f32 / TILE_TEXELS as f32);
            let shade = mottle.fbm(u, v, 4);
            // Vessels: thin ridges where a smooth noise crosses its mid-level.
            let ridge = 1.0 - (2.0 * veins.fbm(u, v, 3) - 1.0).abs();
            let vessel = tissue.vessels * smoothstep(0.93, 0.985, ridge);
            let rgb: [f32; 3] = std::array::from_fn(|c| {
                let parenchyma = lerp(tissue.base[c], tissue.shade[c], shade);
                lerp(parenchyma, tissue.vessel[c], vessel)
            });
            let srgb = Color::linear_rgb(rgb[0], rgb[1], rgb[2]).to_srgba();
            colour.extend(srgb.to_u8_array());
            let rough = 0.22 + 0.35 * wet.fbm(u, v, 3);
            roughness.extend([0, (rough * 255.0) as u8, 0, 255]);
        }
    }
    (colour, roughness)
}

/// The tissue's textures as Bevy images that repeat across the surface.
pub fn images(tissue: &Tissue) -> (Image, Image) {
    let (colour, roughness) = texels(tissue);
    (
        image(colour, TextureFormat::Rgba8UnormSrgb),
        image(roughness, TextureFormat::Rgba8Unorm),
    )
}

/// The mean colour of the tissue's texture (sRGB, 0–255), before lighting.
pub fn mean_srgb(tissue: &Tissue) -> [u8; 3] {
    let (texels, _) = texels(tissue);
    let count = (texels.len() / 4).max(1) as u64;
    std::array::from_fn(|c| {
        let sum: u64 = texels.iter().skip(c).step_by(4).map(|&t| t as u64).sum();
        (sum / count) as u8
    })
}

fn image(texels: Vec<u8>, format: TextureFormat) -> Image {
    let side = TILE_TEXELS as u32;
    let mut image = Image::new(
        Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texels,
        format,
        RenderAssetUsages::RENDER_WORLD,
    );
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: ImageAddressMode::Repeat,
        address_mode_v: ImageAddressMode::Repeat,
        ..ImageSamplerDescriptor::linear()
    });
    image
}

/// Living tissue's surface: the tissue's colour and roughness tiles under a thin glossy film
/// of moisture (clearcoat), whose highlights move as the light and the eye do, and some light
/// let through from behind, as thin living tissue lets it (diffuse transmission, a cheap
/// stand-in for subsurface scattering). Seen from both sides: a cut or a thin wall shows its
/// inside lit.
pub fn wet(colour: Handle<Image>, roughness: Handle<Image>) -> StandardMaterial {
    StandardMaterial {
        base_color_texture: Some(colour),
        metallic_roughness_texture: Some(roughness),
        metallic: 0.0,
        perceptual_roughness: 1.0,
        reflectance: 0.5,
        clearcoat: 0.6,
        clearcoat_perceptual_roughness: 0.15,
        diffuse_transmission: 0.2,
        double_sided: true,
        cull_mode: None,
        ..default()
    }
}

/// Texture coordinates of rest positions: a planar projection along the axis in which the
/// organ is thinnest (the view it shows most of), one tile per `TILE_M`. Taken at rest, so
/// the texture moves with the tissue when it deforms.
pub fn planar_uvs(positions: &[[f32; 3]]) -> Vec<[f32; 2]> {
    let mut low = [f32::INFINITY; 3];
    let mut high = [f32::NEG_INFINITY; 3];
    for p in positions {
        for a in 0..3 {
            low[a] = low[a].min(p[a]);
            high[a] = high[a].max(p[a]);
        }
    }
    let thinnest = (0..3)
        .min_by(|&a, &b| (high[a] - low[a]).total_cmp(&(high[b] - low[b])))
        .unwrap_or(1);
    let (a, b) = ((thinnest + 1) % 3, (thinnest + 2) % 3);
    positions
        .iter()
        .map(|p| [(p[a] - low[a]) / TILE_M, (p[b] - low[b]) / TILE_M])
        .collect()
}

/// Value noise on periodic lattices, one per octave: tileable over the unit square.
struct Noise {
    /// Per octave: its lattice cells per side and their values, row by row.
    octaves: Vec<(usize, Vec<f32>)>,
}

impl Noise {
    const OCTAVES: u32 = 4;

    /// `cells` lattice cells per side at the coarsest octave, doubling with each octave.
    fn new(seed: u64, cells: usize) -> Self {
        let mut rng = fastrand::Rng::with_seed(seed);
        let octaves = (0..Self::OCTAVES)
            .map(|octave| {
                let side = cells << octave;
                (side, (0..side * side).map(|_| rng.f32()).collect())
            })
            .collect();
        Self { octaves }
    }

    /// One octave's smoothly interpolated lattice values at `(u, v)` in the unit square.
    fn at(&self, u: f32, v: f32, octave: usize) -> f32 {
        let (cells, values) = &self.octaves[octave];
        let cells = *cells;
        let (x, y) = (u * cells as f32, v * cells as f32);
        let (i, j) = (x.floor() as usize, y.floor() as usize);
        let (fx, fy) = (smooth(x - x.floor()), smooth(y - y.floor()));
        let value = |i: usize, j: usize| values[(j % cells) * cells + i % cells];
        let bottom = lerp(value(i, j), value(i + 1, j), fx);
        let top = lerp(value(i, j + 1), value(i + 1, j + 1), fx);
        lerp(bottom, top, fy)
    }

    /// Fractal sum of the first `octaves`, each half the weight of the one before, in [0, 1].
    fn fbm(&self, u: f32, v: f32, octaves: u32) -> f32 {
        let (mut sum, mut weight, mut total) = (0.0, 1.0, 0.0);
        for octave in 0..octaves.min(Self::OCTAVES) as usize {
            sum += weight * self.at(u, v, octave);
            total += weight;
            weight *= 0.5;
        }
        sum / total
    }
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

fn smoothstep(low: f32, high: f32, x: f32) -> f32 {
    smooth(((x - low) / (high - low)).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tile must meet its own copy without a seam: the texels along opposite edges continue
    /// each other as smoothly as neighbouring texels inside the tile do.
    #[test]
    fn tiles_are_seamless() {
        let (colour, _) = texels(&tissue("liver"));
        let texel = |i: usize, j: usize, c: usize| colour[(j * TILE_TEXELS + i) * 4 + c] as f32;
        let n = TILE_TEXELS;
        let step = |a: (usize, usize), b: (usize, usize)| {
            (0..3)
                .map(|c| (texel(a.0, a.1, c) - texel(b.0, b.1, c)).abs())
                .sum::<f32>()
        };
        let across_seam: f32 = (0..n).map(|j| step((n - 1, j), (0, j))).sum::<f32>() / n as f32;
        let inside: f32 = (0..n)
            .map(|j| step((n / 2 - 1, j), (n / 2, j)))
            .sum::<f32>()
            / n as f32;
        assert!(
            across_seam < 3.0 * inside + 1.0,
            "{across_seam} vs {inside}"
        );
    }

    /// The organs' tissues differ in colour (the screenshot test tells them apart by it).
    #[test]
    fn organs_have_distinct_tissue() {
        let names = ["liver", "gallbladder", "pancreas", "duodenum"];
        for (k, a) in names.iter().enumerate() {
            for b in &names[k + 1..] {
                let (a, b) = (tissue(a).base, tissue(b).base);
                let distance: f32 = (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f32>().sqrt();
                assert!(distance > 0.1, "{a:?} vs {b:?}");
            }
        }
    }
}
