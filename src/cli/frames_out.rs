//! `restitution simulate --frames-out DIR`: renders the simulated collisions as grey frames.
//!
//! ```text
//! restitution simulate ... --frames-out DIR
//!     [--lighting bright-on-dark|dark-on-bright|uneven-lamps] [--background L]
//!     [--background-gradient GX,GY] [--sphere-albedo A] [--ambient A] [--lamps L1,L2]
//!     [--lamp-angle-deg DEG] [--markers cube|octahedron|none] [--marker-radius-deg DEG]
//!     [--marker-albedo A] [--read-noise SD] [--full-well-e N] [--bits 8|16]
//!     [--exposure-s T] [--supersample N]
//! ```
//! Writes `DIR/<collision>/frame_NNNNNN.png` (frames numbered from 0 in each collision, the
//! simulated frame times), `DIR/truth.csv` (per frame and sphere: time, phase, true centre in
//! metres and pixels, radius, spin, orientation, whether the disc is wholly in view) and
//! `DIR/render.json` (the settings), together with the tracks and truth of `--out`: all or none.
//! The camera is `simulate`'s (the paper's by default: 192 x 239 pixels, 0.25 mm each). Levels
//! are fractions of full scale. Seeded by `--seed` (a stream of its own, so the tracks do not
//! change when frames are rendered).

use rand::SeedableRng;
use rand::rngs::StdRng;
use restitution::data::png::rendered_files;
use restitution::experiment::{ExperimentSpec, Simulated};
use restitution::frames::render::{
    FilmSpec, Filmed, Lighting, Sensor, film_collision, marker_pattern,
};
use serde_json::json;
use std::path::PathBuf;

/// Mixed into `--seed` for the rendering stream ("frames" in ASCII).
const RENDER_STREAM: u64 = 0x6672_616d_6573;

#[derive(clap::Args, Debug)]
pub struct FramesArgs {
    /// Also render the collisions as PNG frames into this directory
    #[arg(long = "frames-out", value_name = "DIR")]
    frames_out: Option<PathBuf>,
    /// Lighting preset: bright-on-dark, dark-on-bright, uneven-lamps (the flags below override it)
    #[arg(long, default_value = "bright-on-dark")]
    lighting: String,
    /// Background level at the image centre, fraction of full scale
    #[arg(long)]
    background: Option<f64>,
    /// Background change left to right and bottom to top across the image
    #[arg(
        long = "background-gradient",
        value_delimiter = ',',
        value_name = "GX,GY"
    )]
    background_gradient: Option<Vec<f64>>,
    /// Sphere albedo (brightness under unit light)
    #[arg(long = "sphere-albedo")]
    sphere_albedo: Option<f64>,
    /// Ambient light on the spheres
    #[arg(long)]
    ambient: Option<f64>,
    /// Strengths of the lamp right and the lamp left of the camera
    #[arg(long, value_delimiter = ',', value_name = "L1,L2")]
    lamps: Option<Vec<f64>>,
    /// Angle of each lamp from the optical axis, degrees
    #[arg(long = "lamp-angle-deg")]
    lamp_angle_deg: Option<f64>,
    /// Marker dots on each sphere: cube (8), octahedron (6) or none
    #[arg(long, default_value = "cube")]
    markers: String,
    /// Angular radius of a marker dot, degrees
    #[arg(long = "marker-radius-deg", default_value_t = 10.0)]
    marker_radius_deg: f64,
    /// Marker albedo relative to the sphere's
    #[arg(long = "marker-albedo")]
    marker_albedo: Option<f64>,
    /// Gaussian read noise, sd as a fraction of full scale (0.01 = 2.55 levels of 8 bits)
    #[arg(long = "read-noise", default_value_t = 0.01)]
    read_noise: f64,
    /// Photo-electrons at full scale: adds shot noise (default: none)
    #[arg(long = "full-well-e")]
    full_well_e: Option<f64>,
    /// Bits per pixel of the PNG frames: 8 or 16
    #[arg(long, default_value_t = 8)]
    bits: u32,
    /// Exposure time, s (motion blur; 0 = a sharp snapshot)
    #[arg(long = "exposure-s", default_value_t = 0.0)]
    exposure_s: f64,
    /// Anti-aliasing: samples per pixel side where an edge crosses a pixel
    #[arg(long, default_value_t = 8)]
    supersample: usize,
}

impl FramesArgs {
    /// Whether frames were asked for.
    pub fn wanted(&self) -> bool {
        self.frames_out.is_some()
    }

    fn lighting(&self) -> Result<Lighting, String> {
        let mut l = Lighting::preset(&self.lighting).ok_or_else(|| {
            format!(
                "--lighting '{}': expected bright-on-dark, dark-on-bright or uneven-lamps",
                self.lighting
            )
        })?;
        let pair = |flag: &str, v: &Option<Vec<f64>>| -> Result<Option<[f64; 2]>, String> {
            match v.as_deref() {
                None => Ok(None),
                Some([a, b]) => Ok(Some([*a, *b])),
                Some(v) => Err(format!("{flag}: expected two values, got {}", v.len())),
            }
        };
        l.background = self.background.unwrap_or(l.background);
        if let Some(g) = pair("--background-gradient", &self.background_gradient)? {
            l.background_gradient = g;
        }
        l.albedo = self.sphere_albedo.unwrap_or(l.albedo);
        l.ambient = self.ambient.unwrap_or(l.ambient);
        if let Some(g) = pair("--lamps", &self.lamps)? {
            l.lamps = g;
        }
        l.lamp_angle_deg = self.lamp_angle_deg.unwrap_or(l.lamp_angle_deg);
        l.marker_albedo = self.marker_albedo.unwrap_or(l.marker_albedo);
        Ok(l)
    }

    /// Renders every collision and returns the files to write (PNG frames, truth.csv,
    /// render.json), having created the collision directories; nothing when no `--frames-out`.
    pub fn render(
        &self,
        sims: &[Simulated],
        spec: &ExperimentSpec,
        seed: u64,
    ) -> Result<Vec<(PathBuf, Vec<u8>)>, String> {
        let Some(dir) = &self.frames_out else {
            return Ok(Vec::new());
        };
        let lighting = self.lighting()?;
        if !(self.marker_radius_deg.is_finite()
            && self.marker_radius_deg > 0.0
            && self.marker_radius_deg < 90.0)
        {
            return Err(format!(
                "--marker-radius-deg {}: expected an angle in (0, 90)",
                self.marker_radius_deg
            ));
        }
        let markers = marker_pattern(&self.markers, self.marker_radius_deg.to_radians())
            .ok_or_else(|| {
                format!(
                    "--markers '{}': expected cube, octahedron or none",
                    self.markers
                )
            })?;
        if self.bits != 8 && self.bits != 16 {
            return Err(format!("--bits {}: expected 8 or 16", self.bits));
        }
        let sensor = Sensor {
            read_noise: self.read_noise,
            full_well_e: self.full_well_e,
            bits: Some(self.bits),
        };
        let film = FilmSpec::new(
            &spec.camera,
            lighting,
            markers,
            self.supersample,
            sensor,
            self.exposure_s,
        )
        .map_err(|e| e.to_string())?;
        let mut rng = StdRng::seed_from_u64(seed ^ RENDER_STREAM);
        let filmed: Vec<Filmed> = sims
            .iter()
            .map(|s| film_collision(s, &film, &mut rng).map_err(|e| format!("{}: {e}", s.id)))
            .collect::<Result<_, _>>()?;
        let origins: serde_json::Map<String, serde_json::Value> = filmed
            .iter()
            .map(|f| (f.id.clone(), json!(f.origin_m)))
            .collect();
        let settings = json!({
            "seed": seed,
            "camera": {"pixels_x": spec.camera.pixels_x, "pixels_y": spec.camera.pixels_y,
                       "pixel_m": spec.camera.pixel_m(), "frames_per_s": spec.camera.frames_per_s},
            "lighting": {"preset": self.lighting, "background": lighting.background,
                         "background_gradient": lighting.background_gradient,
                         "sphere_albedo": lighting.albedo, "ambient": lighting.ambient,
                         "lamps": lighting.lamps, "lamp_angle_deg": lighting.lamp_angle_deg,
                         "marker_albedo": lighting.marker_albedo},
            "markers": {"pattern": self.markers, "radius_deg": self.marker_radius_deg},
            "sensor": {"read_noise": self.read_noise, "full_well_e": self.full_well_e,
                       "bits": self.bits},
            "exposure_s": self.exposure_s,
            "supersample": self.supersample,
            "coordinates": "x_m, y_m: object plane, x right, y up, origin at the image's bottom-left corner; col_px, row_px from the left and top edges, pixel (c, r) spans [c, c+1) x [r, r+1)",
            "origin_m": origins,
        });
        let files =
            rendered_files(dir, &filmed, self.bits, &settings).map_err(|e| e.to_string())?;
        for f in &filmed {
            let sub = dir.join(&f.id);
            std::fs::create_dir_all(&sub)
                .map_err(|e| format!("{}: cannot create: {e}", sub.display()))?;
        }
        Ok(files)
    }

    /// One line for the summary.
    pub fn summary(&self, files: usize) -> Option<String> {
        self.frames_out.as_ref().map(|d| {
            format!(
                "rendered {} frames -> {}/<collision>/frame_NNNNNN.png, truth.csv, render.json",
                files.saturating_sub(2),
                d.display()
            )
        })
    }
}
