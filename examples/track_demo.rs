//! Renders a synthetic collision for `restitution track` (the README example): two 12.7 mm
//! spheres (25.4 px radius at 0.25 mm/pixel) meeting head-on at 1.25 m/s with e = 0.9, lit
//! from the front by two unequal lamps, marked with dots and spinning, 11 frames at 1000
//! frames/s (frame 108 skipped), 16-bit PNGs in DIR/shot_7/.
//!
//! ```sh
//! cargo run --release --example track_demo -- /tmp/frames
//! restitution track /tmp/frames/shot_7 --fps 1000 --d-mm 12.7 --out reports/track
//! ```
//! The scene is the tests' synthetic renderer (tests/common/synth.rs); the truth is printed.

#[path = "../tests/common/synth.rs"]
mod synth;

use restitution::data::images::write_png16;

fn main() -> Result<(), String> {
    let dir = std::env::args()
        .nth(1)
        .ok_or("usage: track_demo DIR (frames go to DIR/shot_7/)")?;
    let out = std::path::Path::new(&dir).join("shot_7");
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let seq = synth::collision_sequence(25.4, 5.1, 12, &[108]);
    println!("frame,x1_px,y1_px,x2_px,y2_px");
    for (n, scene, c) in &seq.frames {
        write_png16(&out.join(format!("frame{n:04}.png")), &scene.render())
            .map_err(|e| e.to_string())?;
        println!("{n},{},{},{},{}", c[0][0], c[0][1], c[1][0], c[1][1]);
    }
    for (k, s) in seq.spins.iter().enumerate() {
        println!(
            "sphere {}: w before {:?} rad/s, after {:?} rad/s",
            k + 1,
            s[0].as_slice(),
            s[1].as_slice()
        );
    }
    Ok(())
}
