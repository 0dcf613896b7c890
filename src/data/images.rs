//! Video frames on disk: a directory of PNG (8/16-bit, grey or colour) or TIFF files, one
//! collision per directory, ordered by the integer in each file name; decoded into
//! [`GrayImage`] (intensities in [0, 1]; colour to luma with Rec. 709 weights).

use super::{DataError, DataFailure};
use crate::frames::GrayImage;
use std::path::{Path, PathBuf};

/// A frame file and the integer in its name.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameFile {
    pub path: PathBuf,
    pub number: i64,
}

fn data_err(path: &Path, kind: DataFailure, message: impl Into<String>) -> DataError {
    DataError {
        path: path.display().to_string(),
        line: None,
        column: None,
        kind,
        message: message.into(),
    }
}

/// The frame number in a frame file's name: the last run of digits in the name without its
/// extension (`shot3_frame0012.png` is frame 12). Errors: no digits in the name, or too many
/// for an i64.
pub fn frame_number(path: &Path) -> Result<i64, DataError> {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let bytes = stem.as_bytes();
    let Some(end) = bytes
        .iter()
        .rposition(|b| b.is_ascii_digit())
        .map(|i| i + 1)
    else {
        return Err(data_err(
            path,
            DataFailure::Schema,
            "no frame number in the file name (frames are ordered by the integer in their names)",
        ));
    };
    let start = bytes[..end]
        .iter()
        .rposition(|b| !b.is_ascii_digit())
        .map_or(0, |i| i + 1);
    let digits = &stem[start..end];
    digits.parse::<i64>().map_err(|_| {
        data_err(
            path,
            DataFailure::Value,
            format!("frame number {digits} is too large"),
        )
    })
}

fn is_frame_file(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .map(|e| matches!(e.to_ascii_lowercase().as_str(), "png" | "tif" | "tiff"))
        .unwrap_or(false)
}

/// The frame files of one directory, sorted by frame number. Other files (and names starting
/// with a dot) are ignored. Errors: a missing or unreadable directory, no frame files, a frame
/// file without a number in its name, two files with the same number.
pub fn list_frames(dir: &Path) -> Result<Vec<FrameFile>, DataError> {
    if !dir.is_dir() {
        return Err(data_err(
            dir,
            DataFailure::Io,
            if dir.exists() {
                "is not a directory"
            } else {
                "no such directory"
            },
        ));
    }
    let entries = std::fs::read_dir(dir)
        .map_err(|e| data_err(dir, DataFailure::Io, format!("cannot read: {e}")))?;
    let mut out: Vec<FrameFile> = Vec::new();
    for entry in entries {
        let entry =
            entry.map_err(|e| data_err(dir, DataFailure::Io, format!("cannot read: {e}")))?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().to_string();
        if name.starts_with('.') || !is_frame_file(&path) {
            continue;
        }
        let number = frame_number(&path)?;
        out.push(FrameFile { path, number });
    }
    if out.is_empty() {
        return Err(data_err(
            dir,
            DataFailure::Schema,
            "no PNG or TIFF frames in this directory",
        ));
    }
    out.sort_by(|a, b| a.number.cmp(&b.number).then(a.path.cmp(&b.path)));
    if let Some(w) = out.windows(2).find(|w| w[0].number == w[1].number) {
        return Err(data_err(
            &w[1].path,
            DataFailure::Value,
            format!(
                "frame number {} also in {}",
                w[1].number,
                w[0].path.display()
            ),
        ));
    }
    Ok(out)
}

/// Decodes a PNG or TIFF file into a grey frame.
pub fn read_gray(path: &Path) -> Result<GrayImage, DataError> {
    let img = image::ImageReader::open(path)
        .map_err(|e| data_err(path, DataFailure::Io, format!("cannot read: {e}")))?
        .with_guessed_format()
        .map_err(|e| data_err(path, DataFailure::Io, format!("cannot read: {e}")))?
        .decode()
        .map_err(|e| {
            data_err(
                path,
                DataFailure::Format,
                format!("cannot decode the image: {e}"),
            )
        })?;
    let luma = img.to_luma32f();
    let (w, h) = (luma.width() as usize, luma.height() as usize);
    if w == 0 || h == 0 {
        return Err(data_err(path, DataFailure::Format, "the image is empty"));
    }
    let pixels = luma.into_raw();
    if let Some(bad) = pixels.iter().position(|v| !v.is_finite()) {
        return Err(data_err(
            path,
            DataFailure::Value,
            format!("pixel ({}, {}) is not a finite number", bad % w, bad / w),
        ));
    }
    Ok(GrayImage {
        width: w,
        height: h,
        pixels,
    })
}

/// Encodes a grey frame as an 8-bit PNG (for figures); `path` names the frame in messages (the
/// file it was read from).
pub fn encode_png(path: &Path, img: &GrayImage) -> Result<Vec<u8>, DataError> {
    use image::ImageEncoder;
    let bytes: Vec<u8> = img
        .pixels
        .iter()
        .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &bytes,
            img.width as u32,
            img.height as u32,
            image::ExtendedColorType::L8,
        )
        .map_err(|e| data_err(path, DataFailure::Format, format!("encoding a PNG: {e}")))?;
    Ok(out)
}

/// Writes a grey frame as a 16-bit grey PNG (test fixtures, rendered frames).
pub fn write_png16(path: &Path, img: &GrayImage) -> Result<(), DataError> {
    use image::ImageEncoder;
    let mut bytes = Vec::with_capacity(img.pixels.len() * 2);
    for v in &img.pixels {
        let q = (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
        bytes.extend_from_slice(&q.to_ne_bytes());
    }
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &bytes,
            img.width as u32,
            img.height as u32,
            image::ExtendedColorType::L16,
        )
        .map_err(|e| data_err(path, DataFailure::Format, format!("encoding a PNG: {e}")))?;
    super::write_atomic(path, &out)
        .map_err(|e| data_err(path, DataFailure::Io, format!("cannot write: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_from_names() {
        let number = |name: &str| frame_number(Path::new(name));
        assert_eq!(number("dir/frame0012.png"), Ok(12));
        assert_eq!(number("shot3_frame0012.tif"), Ok(12));
        assert_eq!(number("7.png"), Ok(7));
        assert_eq!(number("cam2_x.png"), Ok(2));
        let none = number("dir/frame.png").unwrap_err();
        assert_eq!(
            (none.path.as_str(), none.kind),
            ("dir/frame.png", DataFailure::Schema)
        );
        let large = number("f99999999999999999999.png").unwrap_err();
        assert_eq!(large.kind, DataFailure::Value, "{large}");
    }
}
