//! Binary-image morphology for the coarse stage ([`super::segment`]): holes filled, connected
//! components labelled, and the exact Euclidean distance transform.

/// Sets background pixels not connected (4-neighbours) to the image border to foreground:
/// markers inside a disc become part of it.
pub(crate) fn fill_holes(mask: &mut [bool], w: usize, h: usize) {
    // Background outside the foreground's box reaches the border in a straight line, and a
    // path from inside the grown box to the border crosses the box's edge: the grown box, with
    // its edge standing for the image border, has the same holes.
    let Some((r0, r1, c0, c1)) = grown_box(mask, w, h) else {
        return;
    };
    let (bw, bh) = (c1 - c0 + 1, r1 - r0 + 1);
    let mut sub: Vec<bool> = (r0..=r1)
        .flat_map(|r| mask[r * w + c0..=r * w + c1].iter().copied())
        .collect();
    fill_holes_full(&mut sub, bw, bh);
    for r in 0..bh {
        mask[(r0 + r) * w + c0..=(r0 + r) * w + c1].copy_from_slice(&sub[r * bw..(r + 1) * bw]);
    }
}

/// The bounding box (first row, last row, first column, last column) of the true pixels of
/// `mask`, grown by one pixel and clipped to the image; `None` if there are none.
fn grown_box(mask: &[bool], w: usize, h: usize) -> Option<(usize, usize, usize, usize)> {
    let (mut r_lo, mut r_hi, mut c_lo, mut c_hi) = (usize::MAX, 0, usize::MAX, 0);
    for r in 0..h {
        let row = &mask[r * w..(r + 1) * w];
        if let Some(first) = row.iter().position(|&x| x) {
            let last = row.iter().rposition(|&x| x).unwrap_or(first);
            r_lo = r_lo.min(r);
            r_hi = r;
            c_lo = c_lo.min(first);
            c_hi = c_hi.max(last);
        }
    }
    (r_lo != usize::MAX).then(|| {
        (
            r_lo.saturating_sub(1),
            (r_hi + 1).min(h - 1),
            c_lo.saturating_sub(1),
            (c_hi + 1).min(w - 1),
        )
    })
}

/// `fill_holes` on the whole grid.
fn fill_holes_full(mask: &mut [bool], w: usize, h: usize) {
    if w == 0 || h == 0 {
        return;
    }
    // A frame of one blocked pixel around the image spares the border tests; `open` marks
    // background pixels not yet reached from the border.
    let pw = w + 2;
    let mut open = vec![false; pw * (h + 2)];
    for r in 0..h {
        for c in 0..w {
            open[(r + 1) * pw + c + 1] = !mask[r * w + c];
        }
    }
    let mut stack: Vec<usize> = Vec::new();
    let mut start = |r: usize, c: usize, open: &mut [bool]| {
        let i = (r + 1) * pw + c + 1;
        if open[i] {
            open[i] = false;
            stack.push(i);
        }
    };
    for c in 0..w {
        start(0, c, &mut open);
        start(h - 1, c, &mut open);
    }
    for r in 0..h {
        start(r, 0, &mut open);
        start(r, w - 1, &mut open);
    }
    while let Some(i) = stack.pop() {
        for j in [i - 1, i + 1, i - pw, i + pw] {
            if open[j] {
                open[j] = false;
                stack.push(j);
            }
        }
    }
    // Background pixels never reached are holes.
    for r in 0..h {
        for c in 0..w {
            if open[(r + 1) * pw + c + 1] {
                mask[r * w + c] = true;
            }
        }
    }
}

/// Connected components of `mask` (4-neighbours): labels 1..=n per pixel (0 = background) and
/// the area of each component.
pub(crate) fn label(mask: &[bool], w: usize, h: usize) -> (Vec<u32>, Vec<usize>) {
    let mut labels = vec![0u32; w * h];
    let mut areas = Vec::new();
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !mask[start] || labels[start] != 0 {
            continue;
        }
        let lab = areas.len() as u32 + 1;
        let mut area = 0;
        labels[start] = lab;
        stack.push(start);
        while let Some(i) = stack.pop() {
            area += 1;
            let (r, c) = (i / w, i % w);
            let nb = [
                (c > 0).then(|| i - 1),
                (c + 1 < w).then(|| i + 1),
                (r > 0).then(|| i - w),
                (r + 1 < h).then(|| i + w),
            ];
            for j in nb.into_iter().flatten() {
                if mask[j] && labels[j] == 0 {
                    labels[j] = lab;
                    stack.push(j);
                }
            }
        }
        areas.push(area);
    }
    (labels, areas)
}

/// Exact Euclidean distance from each pixel to the nearest pixel where `fg` is false (pixels
/// outside the image do not count; a frame with no background pixel gets a large value), by
/// Felzenszwalb & Huttenlocher's lower-envelope transform (Theory of Computing 8, 415, 2012),
/// columns then rows.
pub(crate) fn edt(fg: &[bool], w: usize, h: usize) -> Vec<f32> {
    // Only the bounding box of the foreground grown by one pixel (clipped to the image) needs
    // the transform: outside it every pixel is background (0), and a foreground pixel's nearest
    // background pixel beyond the box has a nearer one on the grown rim (clamp it to the box),
    // which is background.
    let mut out = vec![0.0f32; w * h];
    let Some((r0, r1, c0, c1)) = grown_box(fg, w, h) else {
        return out;
    };
    let (bw, bh) = (c1 - c0 + 1, r1 - r0 + 1);
    let sub: Vec<bool> = (r0..=r1)
        .flat_map(|r| fg[r * w + c0..=r * w + c1].iter().copied())
        .collect();
    let d = edt_full(&sub, bw, bh);
    for r in 0..bh {
        out[(r0 + r) * w + c0..=(r0 + r) * w + c1].copy_from_slice(&d[r * bw..(r + 1) * bw]);
    }
    out
}

/// `edt` on the whole grid.
fn edt_full(fg: &[bool], w: usize, h: usize) -> Vec<f32> {
    const BIG: f64 = 1e12;
    let mut g = vec![0.0f64; w * h];
    let mut f = vec![0.0f64; w.max(h)];
    let mut d = vec![0.0f64; w.max(h)];
    let mut v = vec![0usize; w.max(h)];
    let mut z = vec![0.0f64; w.max(h) + 1];
    // Columns: on a binary image the 1-D transform is the squared distance to the nearest
    // background pixel of the column (BIG if it has none), found by two scans; the lower
    // envelope gives the same values (integers and BIG are exact in f64).
    let mut near = vec![usize::MAX; h];
    for c in 0..w {
        let mut last = usize::MAX;
        for (r, nr) in near.iter_mut().enumerate() {
            if !fg[r * w + c] {
                last = r;
            }
            *nr = if last == usize::MAX {
                usize::MAX
            } else {
                r - last
            };
        }
        let mut last = usize::MAX;
        for r in (0..h).rev() {
            if !fg[r * w + c] {
                last = r;
            }
            let below = if last == usize::MAX {
                usize::MAX
            } else {
                last - r
            };
            let k = near[r].min(below);
            g[r * w + c] = if k == usize::MAX { BIG } else { (k * k) as f64 };
        }
    }
    for r in 0..h {
        let row = &mut g[r * w..(r + 1) * w];
        // A row of background pixels stays 0.
        if row.iter().all(|&x| x == 0.0) {
            continue;
        }
        f[..w].copy_from_slice(row);
        dt1(&f[..w], &mut d[..w], &mut v, &mut z);
        row.copy_from_slice(&d[..w]);
    }
    g.iter().map(|&v| v.sqrt() as f32).collect()
}

/// One-dimensional squared distance transform d[q] = min_p (f[p] + (q - p)^2): the lower
/// envelope of parabolas rooted at each p (Felzenszwalb & Huttenlocher, Algorithm 1).
fn dt1(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    let mut k = 0usize;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    let cross = |q: usize, p: usize| {
        ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64)) / (2.0 * (q - p) as f64)
    };
    for q in 1..n {
        // The intersections are finite (f is finite), so s > z[0] = -inf ends the loop at k = 0.
        let mut s = cross(q, v[k]);
        while s <= z[k] {
            k -= 1;
            s = cross(q, v[k]);
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        *dq = (q as f64 - p as f64).powi(2) + f[p];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edt_matches_brute_force() {
        let (w, h) = (23, 17);
        let fg: Vec<bool> = (0..w * h)
            .map(|i| {
                let (r, c) = ((i / w) as f64, (i % w) as f64);
                (r - 8.0).hypot(c - 11.0) < 7.3 || (c > 18.0 && r < 5.0)
            })
            .collect();
        let d = edt(&fg, w, h);
        for (i, &di) in d.iter().enumerate() {
            let (r, c) = ((i / w) as f64, (i % w) as f64);
            let brute = (0..w * h)
                .filter(|&j| !fg[j])
                .map(|j| (r - (j / w) as f64).hypot(c - (j % w) as f64))
                .fold(f64::INFINITY, f64::min);
            assert!(
                (di as f64 - brute).abs() < 1e-5,
                "pixel {i}: {di} vs {brute}"
            );
        }
    }

    // The boxed fill against the whole-grid flood fill on shapes whose holes and openings sit
    // at the box's edge: a ring with a one-pixel hole, a C open towards the border, a ring cut
    // by the image edge (its inside is then outside), and a blob in a corner.
    #[test]
    fn boxed_fill_matches_whole_grid() {
        let (w, h) = (20, 14);
        let shapes: [&dyn Fn(usize, usize) -> bool; 4] = [
            &|r, c| (3..=5).contains(&r) && (4..=6).contains(&c) && !(r == 4 && c == 5),
            &|r, c| (2..=9).contains(&r) && (8..=15).contains(&c) && !(r > 3 && r < 8 && c > 9),
            &|r, c| {
                let d = (r as f64 - 1.0).hypot(c as f64 - 10.0);
                (2.5..4.0).contains(&d)
            },
            &|r, c| r + c < 4 || (r > 10 && c > 16 && !(r == 12 && c == 18)),
        ];
        for (k, f) in shapes.iter().enumerate() {
            let m: Vec<bool> = (0..w * h).map(|i| f(i / w, i % w)).collect();
            let (mut a, mut b) = (m.clone(), m.clone());
            fill_holes(&mut a, w, h);
            fill_holes_full(&mut b, w, h);
            assert_eq!(a, b, "shape {k}");
        }
        let mut ring: Vec<bool> = (0..w * h).map(|i| shapes[0](i / w, i % w)).collect();
        fill_holes(&mut ring, w, h);
        assert!(ring[4 * w + 5], "the ring's hole is filled");
    }

    #[test]
    fn holes_filled_and_components_counted() {
        let (w, h) = (12, 8);
        let mut m = vec![false; w * h];
        for r in 1..6 {
            for c in 1..6 {
                m[r * w + c] = !(r == 3 && c == 3);
            }
        }
        m[2 * w + 9] = true;
        fill_holes(&mut m, w, h);
        assert!(m[3 * w + 3]);
        let (_, areas) = label(&m, w, h);
        assert_eq!(areas, vec![25, 1]);
    }
}
