//! PNG output of grey frames ([`crate::frames::GrayImage`]), and the files of rendered virtual
//! frames (`simulate --frames-out`): one directory per collision, `frame_NNNNNN.png` per frame,
//! `truth.csv` with every frame's true centres, radii and spins, and `render.json` with the
//! settings.

use crate::data::fmt_num;
use crate::frames::GrayImage;
use crate::frames::render::Filmed;
use image::ImageEncoder;
use image::codecs::png::PngEncoder;
use std::path::{Path, PathBuf};

/// Why a frame could not be encoded as a grey PNG.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PngFailure {
    /// The frame's pixel count is not its width times its height, or it has no pixels.
    #[error("frame of {width} x {height} pixels holds {values} values")]
    Size {
        width: usize,
        height: usize,
        values: usize,
    },
    /// The frame is wider (`"wide"`) or taller (`"tall"`) than PNG's 2^32 - 1 pixels.
    #[error("frame too {0} for PNG")]
    TooLarge(&'static str),
    /// A bit depth other than 8 or 16.
    #[error("PNG grey frames have 8 or 16 bits, not {0}")]
    Bits(u32),
    /// A pixel's level is outside [0, 1] or not finite.
    #[error("pixel (col {col}, row {row}) = {value}: expected a level in [0, 1]")]
    Level { col: usize, row: usize, value: f32 },
    /// The PNG encoder refused the frame (its message).
    #[error("encoding PNG: {0}")]
    Encoder(String),
}

/// Why the files of rendered collisions could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderedFilesError {
    /// A collision id that cannot name a directory (empty, `.`, `..`, or with a path separator).
    #[error("collision id '{0}' cannot name a directory")]
    CollisionId(String),
    /// A frame that cannot be encoded: the collision, the frame's index and why.
    #[error("collision {collision} frame {frame}: {kind}")]
    Frame {
        collision: String,
        frame: usize,
        kind: PngFailure,
    },
}

/// Encodes a frame as a grey PNG of 8 or 16 bits: each value in [0, 1] is scaled to the full
/// range and rounded. A value outside [0, 1] or not finite is an error naming the pixel.
pub fn encode_gray_png(img: &GrayImage, bits: u32) -> Result<Vec<u8>, PngFailure> {
    if img.pixels.len() != img.width * img.height || img.width == 0 || img.height == 0 {
        return Err(PngFailure::Size {
            width: img.width,
            height: img.height,
            values: img.pixels.len(),
        });
    }
    let (w, h) = (
        u32::try_from(img.width).map_err(|_| PngFailure::TooLarge("wide"))?,
        u32::try_from(img.height).map_err(|_| PngFailure::TooLarge("tall"))?,
    );
    let full = match bits {
        8 => 255.0,
        16 => 65535.0,
        _ => return Err(PngFailure::Bits(bits)),
    };
    let mut levels = Vec::with_capacity(img.pixels.len());
    for (i, &x) in img.pixels.iter().enumerate() {
        if !(x.is_finite() && (0.0..=1.0).contains(&x)) {
            return Err(PngFailure::Level {
                col: i % img.width,
                row: i / img.width,
                value: x,
            });
        }
        levels.push((x as f64 * full).round() as u16);
    }
    let mut out = Vec::new();
    let enc = PngEncoder::new(&mut out);
    let result = if bits == 8 {
        let bytes: Vec<u8> = levels.iter().map(|&l| l as u8).collect();
        enc.write_image(&bytes, w, h, image::ExtendedColorType::L8)
    } else {
        // image's encoders take 16-bit samples in native byte order (PNG's big-endian is theirs
        // to write).
        let bytes: Vec<u8> = levels.iter().flat_map(|l| l.to_ne_bytes()).collect();
        enc.write_image(&bytes, w, h, image::ExtendedColorType::L16)
    };
    result.map_err(|e| PngFailure::Encoder(e.to_string()))?;
    Ok(out)
}

/// The name of frame `k` of a collision.
pub fn frame_file_name(k: usize) -> String {
    format!("frame_{k:06}.png")
}

/// All files of rendered collisions under `dir`: `dir/<id>/frame_NNNNNN.png`, `dir/truth.csv`
/// (one row per sphere and frame) and `dir/render.json` (`settings`). Nothing is written here;
/// the caller writes them all or none.
pub fn rendered_files(
    dir: &Path,
    filmed: &[Filmed],
    bits: u32,
    settings: &serde_json::Value,
) -> Result<Vec<(PathBuf, Vec<u8>)>, RenderedFilesError> {
    let mut files = Vec::new();
    let mut w = csv::Writer::from_writer(Vec::new());
    let header = [
        "collision",
        "frame",
        "file",
        "t_s",
        "phase",
        "subframes",
        "sphere",
        "x_m",
        "y_m",
        "col_px",
        "row_px",
        "radius_m",
        "radius_px",
        "wx_rad_s",
        "wy_rad_s",
        "wz_rad_s",
        "qw",
        "qx",
        "qy",
        "qz",
        "in_view",
    ];
    // Writing CSV into memory cannot fail: the writer's only errors are I/O (none into a `Vec`)
    // and records of unequal length (each has the header's by construction).
    const IN_MEMORY: &str = "writing CSV into memory cannot fail";
    w.write_record(header).expect(IN_MEMORY);
    for f in filmed {
        if f.id.is_empty() || f.id.contains(['/', '\\']) || f.id == "." || f.id == ".." {
            return Err(RenderedFilesError::CollisionId(f.id.clone()));
        }
        for (k, (img, t)) in f.frames.iter().zip(&f.truth).enumerate() {
            let name = frame_file_name(k);
            let png = encode_gray_png(img, bits).map_err(|kind| RenderedFilesError::Frame {
                collision: f.id.clone(),
                frame: k,
                kind,
            })?;
            files.push((dir.join(&f.id).join(&name), png));
            for (i, s) in t.spheres.iter().enumerate() {
                let mut rec = vec![
                    f.id.clone(),
                    t.frame.to_string(),
                    format!("{}/{name}", f.id),
                    fmt_num(t.t_s),
                    if t.post { "post" } else { "pre" }.to_string(),
                    t.subframes.to_string(),
                    (i + 1).to_string(),
                ];
                rec.extend(
                    [
                        s.centre_m[0],
                        s.centre_m[1],
                        s.col_px,
                        s.row_px,
                        s.radius_m,
                        s.radius_px,
                    ]
                    .iter()
                    .chain(&s.spin_rad_s)
                    .chain(&s.orientation)
                    .map(|&x| fmt_num(x)),
                );
                rec.push(s.in_view.to_string());
                w.write_record(&rec).expect(IN_MEMORY);
            }
        }
    }
    let truth = w.into_inner().expect(IN_MEMORY);
    files.push((dir.join("truth.csv"), truth));
    // A JSON value (string keys only) always serialises.
    let json = serde_json::to_string_pretty(settings).expect("a JSON value serialises") + "\n";
    files.push((dir.join("render.json"), json.into_bytes()));
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trips_levels_and_orientation() {
        let mut img = GrayImage::filled(5, 3, 0.0);
        img.set(4, 0, 1.0); // top-right
        img.set(0, 2, 0.3); // bottom-left
        for bits in [8, 16] {
            let bytes = encode_gray_png(&img, bits).unwrap();
            let back = image::load_from_memory(&bytes).unwrap().into_luma16();
            assert_eq!(back.dimensions(), (5, 3));
            // image's PNG decoder puts row 0 at the top, like GrayImage.
            assert_eq!(back.get_pixel(4, 0).0[0], 65535);
            // 0.3 is 76.5 of 255 (rounds to 77, read back as 77 * 257) and 19660.5 of 65535.
            let expected = if bits == 8 { 77 * 257 } else { 19661 };
            assert_eq!(back.get_pixel(0, 2).0[0], expected);
            assert_eq!(back.get_pixel(2, 1).0[0], 0);
        }
    }

    #[test]
    fn bad_frames_are_errors() {
        let mut img = GrayImage::filled(2, 2, 0.5);
        img.set(1, 1, f32::NAN);
        let e = encode_gray_png(&img, 8).unwrap_err();
        assert!(
            matches!(e, PngFailure::Level { col: 1, row: 1, value } if value.is_nan()),
            "{e}"
        );
        img.set(1, 1, 1.5);
        assert_eq!(
            encode_gray_png(&img, 8),
            Err(PngFailure::Level {
                col: 1,
                row: 1,
                value: 1.5
            })
        );
        assert_eq!(
            encode_gray_png(&GrayImage::filled(2, 2, 0.5), 12),
            Err(PngFailure::Bits(12))
        );
    }
}
