//! Frames: from high-speed video frames to sphere centres, radii and spins (the paper's Sec. III
//! front end; docs/physics.md §8). Pure numerics on in-memory pixel arrays: decoding image files
//! lives in the I/O layer (`crate::data`), figures in `crate::plot`.

/// A grey-level frame in memory: row-major, row 0 is the top row of the image, intensities
/// scaled to [0, 1] (an 8-bit 255 or a 16-bit 65535 is 1.0).
///
/// Object-plane coordinates (docs/physics.md §8): with pixel size P, pixel (col, row) covers
/// x in [col, col + 1) P and y in [H - 1 - row, H - row) P, so x is to the right, y is up and
/// the origin is the bottom-left corner of the image.
#[derive(Debug, Clone, PartialEq)]
pub struct GrayImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<f32>,
}

impl GrayImage {
    /// A frame of one uniform intensity.
    pub fn filled(width: usize, height: usize, value: f32) -> Self {
        GrayImage {
            width,
            height,
            pixels: vec![value; width * height],
        }
    }

    /// Intensity at (col, row); row 0 is the top row.
    #[inline]
    pub fn get(&self, col: usize, row: usize) -> f32 {
        self.pixels[row * self.width + col]
    }

    #[inline]
    pub fn set(&mut self, col: usize, row: usize, value: f32) {
        self.pixels[row * self.width + col] = value;
    }
}

pub mod circle;
pub mod detect;
pub mod edges;
pub mod levels;
pub mod markers;
pub mod morphology;
pub mod render;
pub mod segment;
pub mod spin;
pub mod track;
