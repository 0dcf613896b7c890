//! The naive baseline: a thresholded blob centroid. Otsu's threshold on the whole frame, the class
//! holding most of the border is background, 4-connected blobs of the other class, holes (marker
//! dots) filled, and each blob's centre is the mean of its pixel centres. No subpixel edge
//! information is used: each pixel counts wholly in or out.

use restitution::frames::GrayImage;

/// Otsu's threshold over 256 bins of [0, 1]: the level maximising the between-class variance.
fn otsu(img: &GrayImage) -> f32 {
    let mut hist = [0usize; 256];
    for &x in &img.pixels {
        hist[((x.clamp(0.0, 1.0) * 255.0).round()) as usize] += 1;
    }
    let n = img.pixels.len() as f64;
    let total: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum();
    let (mut w0, mut s0, mut best, mut t_best) = (0.0, 0.0, -1.0, 0usize);
    for (t, &c) in hist.iter().enumerate() {
        w0 += c as f64;
        s0 += t as f64 * c as f64;
        let w1 = n - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let (m0, m1) = (s0 / w0, (total - s0) / w1);
        let between = w0 * w1 * (m0 - m1).powi(2);
        if between > best {
            best = between;
            t_best = t;
        }
    }
    (t_best as f32 + 0.5) / 255.0
}

/// A blob: its pixel count and centroid (col, row; pixel centres at +0.5).
#[derive(Debug, Clone, Copy)]
pub struct Blob {
    pub area: usize,
    pub col: f64,
    pub row: f64,
}

/// The blobs of a frame, largest first.
pub fn blobs(img: &GrayImage) -> Vec<Blob> {
    let (w, h) = (img.width, img.height);
    let t = otsu(img);
    let above: Vec<bool> = img.pixels.iter().map(|&x| x > t).collect();
    // Background is the class holding most of the border.
    let border: Vec<usize> = (0..w)
        .flat_map(|c| [c, (h - 1) * w + c])
        .chain((0..h).flat_map(|r| [r * w, r * w + w - 1]))
        .collect();
    let above_on_border = border.iter().filter(|&&i| above[i]).count();
    let fg_is_above = 2 * above_on_border < border.len();
    let fg: Vec<bool> = above.iter().map(|&a| a == fg_is_above).collect();
    // Flood the background from the border: what it cannot reach and is not foreground is a hole.
    let mut outside = vec![false; w * h];
    let mut stack: Vec<usize> = border.into_iter().filter(|&i| !fg[i]).collect();
    while let Some(i) = stack.pop() {
        if outside[i] || fg[i] {
            continue;
        }
        outside[i] = true;
        let (c, r) = (i % w, i / w);
        if c > 0 {
            stack.push(i - 1);
        }
        if c + 1 < w {
            stack.push(i + 1);
        }
        if r > 0 {
            stack.push(i - w);
        }
        if r + 1 < h {
            stack.push(i + w);
        }
    }
    let solid: Vec<bool> = outside.iter().map(|&o| !o).collect();
    let mut label = vec![usize::MAX; w * h];
    let mut out = Vec::new();
    for start in 0..w * h {
        if !solid[start] || label[start] != usize::MAX {
            continue;
        }
        let id = out.len();
        let (mut n, mut sc, mut sr) = (0usize, 0.0, 0.0);
        let mut stack = vec![start];
        label[start] = id;
        while let Some(i) = stack.pop() {
            let (c, r) = (i % w, i / w);
            n += 1;
            sc += c as f64 + 0.5;
            sr += r as f64 + 0.5;
            let mut push = |j: usize| {
                if solid[j] && label[j] == usize::MAX {
                    label[j] = id;
                    stack.push(j);
                }
            };
            if c > 0 {
                push(i - 1);
            }
            if c + 1 < w {
                push(i + 1);
            }
            if r > 0 {
                push(i - w);
            }
            if r + 1 < h {
                push(i + w);
            }
        }
        out.push(Blob {
            area: n,
            col: sc / n as f64,
            row: sr / n as f64,
        });
    }
    out.sort_by_key(|b| std::cmp::Reverse(b.area));
    out
}
