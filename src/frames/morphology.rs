//! Binary-image morphology for the coarse stage ([`super::segment`]): holes filled, connected
//! components labelled, and the exact Euclidean distance transform.

/// Sets background pixels not connected (4-neighbours) to the image border to foreground:
/// markers inside a disc become part of it.
pub(crate) fn fill_holes(mask: &mut [bool], w: usize, h: usize) {
    let mut outside = vec![false; w * h];
    let mut stack: Vec<usize> = (0..w * h)
        .filter(|&i| {
            let (r, c) = (i / w, i % w);
            (r == 0 || c == 0 || r + 1 == h || c + 1 == w) && !mask[i]
        })
        .collect();
    for &i in &stack {
        outside[i] = true;
    }
    while let Some(i) = stack.pop() {
        let (r, c) = (i / w, i % w);
        let mut push = |j: usize| {
            if !mask[j] && !outside[j] {
                outside[j] = true;
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
    for i in 0..w * h {
        if !mask[i] && !outside[i] {
            mask[i] = true;
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
    const BIG: f64 = 1e12;
    let mut g = vec![0.0f64; w * h];
    for i in 0..w * h {
        g[i] = if fg[i] { BIG } else { 0.0 };
    }
    let mut f = vec![0.0f64; w.max(h)];
    let mut d = vec![0.0f64; w.max(h)];
    let mut v = vec![0usize; w.max(h)];
    let mut z = vec![0.0f64; w.max(h) + 1];
    for c in 0..w {
        for r in 0..h {
            f[r] = g[r * w + c];
        }
        dt1(&f[..h], &mut d[..h], &mut v, &mut z);
        for r in 0..h {
            g[r * w + c] = d[r];
        }
    }
    for r in 0..h {
        f[..w].copy_from_slice(&g[r * w..(r + 1) * w]);
        dt1(&f[..w], &mut d[..w], &mut v, &mut z);
        g[r * w..(r + 1) * w].copy_from_slice(&d[..w]);
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
