//! Filming a simulated collision ([`crate::experiment::Simulated`]): its true flight rendered
//! frame by frame at the camera's frame times, with the truth of every frame.

use super::{GrayImage, Renderer, Sensor, SpherePose, expose};
use crate::error::{Error, Result};
use crate::experiment::{Camera, Simulated};
use crate::models::walton::{Body, Target};
use nalgebra::{UnitQuaternion, Vector2, Vector3};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// Sub-frames beyond this many per exposure are an error (a blur of hundreds of pixels).
const MAX_SUBFRAMES: usize = 4096;

/// How a collision is filmed.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmSpec {
    pub renderer: Renderer,
    pub sensor: Sensor,
    /// Shutter time, s, centred on each frame time (0: no motion blur).
    pub exposure_s: f64,
    /// Largest motion of a sphere's edge between two sub-frames of the blur, pixels: sets the
    /// number of sub-frames (0.1 pixel keeps the staircase of the sampled blur well below the
    /// accuracy the detector aims at).
    pub blur_step_px: f64,
}

/// The truth about one sphere in one frame. Pixel coordinates are continuous: `col_px` from the
/// image's left edge, `row_px` from its top edge, so pixel (col, row) spans [col, col + 1) x
/// [row, row + 1) and its centre is at (col + 0.5, row + 0.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereTruth {
    /// Centre in object-plane coordinates (x right, y up, origin at the image's bottom-left), m.
    pub centre_m: [f64; 2],
    pub col_px: f64,
    pub row_px: f64,
    pub radius_m: f64,
    pub radius_px: f64,
    /// Angular velocity at the frame time, rad/s (camera frame: x right, y up, z to the camera).
    pub spin_rad_s: [f64; 3],
    /// Orientation (body to camera frame) at the frame time: w, x, y, z.
    pub orientation: [f64; 4],
    /// The whole disc lies inside the image.
    pub in_view: bool,
}

/// The truth of one frame: its time (t = 0 at contact; mid-exposure), phase and spheres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameTruth {
    pub frame: usize,
    pub t_s: f64,
    pub post: bool,
    /// Sub-frames averaged for the motion blur.
    pub subframes: usize,
    pub spheres: [SphereTruth; 2],
}

/// A filmed collision: the recorded frames and their truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Filmed {
    pub id: String,
    pub frames: Vec<GrayImage>,
    pub truth: Vec<FrameTruth>,
    /// Where the simulation's origin (sphere 1's centre at contact) lies in the object plane, m.
    pub origin_m: [f64; 2],
}

impl FilmSpec {
    /// The grid of `camera` (pixels and field of view), with this lighting, markers and sensor.
    pub fn new(
        camera: &Camera,
        lighting: super::Lighting,
        markers: Vec<super::Marker>,
        supersample: usize,
        sensor: Sensor,
        exposure_s: f64,
    ) -> Result<FilmSpec> {
        let view = super::View {
            width: camera.pixels_x as usize,
            height: camera.pixels_y as usize,
            pixel_m: camera.pixel_m(),
            supersample,
        };
        if !(exposure_s.is_finite() && exposure_s >= 0.0 && exposure_s <= camera.dt_s()) {
            return Err(Error::InvalidParameter {
                name: "exposure time (s)",
                value: exposure_s,
                expected: "between 0 and one frame interval",
            });
        }
        Ok(FilmSpec {
            renderer: Renderer::new(view, lighting, markers)?,
            sensor,
            exposure_s,
            blur_step_px: 0.1,
        })
    }
}

/// A rotation drawn uniformly (a normalised 4-D Gaussian is uniform on the unit quaternions).
fn random_rotation(rng: &mut impl Rng) -> UnitQuaternion<f64> {
    loop {
        let q: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(rng));
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        // A norm this small has probability ~1e-24; drawing again keeps the axis well defined.
        if n > 1e-6 {
            return UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                q[0], q[1], q[2], q[3],
            ));
        }
    }
}

/// Renders `sim` as the camera of `spec` records it: one frame at each of the simulated frame
/// times (`sim.frames[k].t_s`), the true centres (not the noisy tracked ones), spheres in their
/// pre- or post-collision spin (a torque-free sphere spins at a constant rate), starting from
/// orientations drawn from `rng`, then the sensor's noise from `rng`. The contact point is placed
/// at the centre of the image.
pub fn film_collision(sim: &Simulated, spec: &FilmSpec, rng: &mut impl Rng) -> Result<Filmed> {
    let Target::Sphere(b2_pre) = &sim.pre.target else {
        return Err(Error::InvalidParameter {
            name: "collision target",
            value: f64::NAN,
            expected: "a second sphere (walls are not rendered)",
        });
    };
    let Target::Sphere(b2_post) = &sim.post.target else {
        unreachable!("a pair stays a pair");
    };
    let bodies: [[&Body; 2]; 2] = [[&sim.pre.sphere, &sim.post.sphere], [b2_pre, b2_post]];
    let view = &spec.renderer.view;
    let p = view.pixel_m;
    let (w_m, h_m) = (view.width as f64 * p, view.height as f64 * p);
    let (d1, d2) = (bodies[0][0].d_m, bodies[1][0].d_m);
    let r1 = sim.scene.position(0, 0.0);
    let r2 = sim.scene.position(1, 0.0);
    let contact = r1 + (r2 - r1) * (d1 / (d1 + d2));
    let origin = Vector2::new(0.5 * w_m, 0.5 * h_m) - contact;
    let q0 = [random_rotation(rng), random_rotation(rng)];

    let spin = |i: usize, t: f64| bodies[i][usize::from(t >= 0.0)].spin_rad_s;
    let pose = |i: usize, t: f64| {
        let r = sim.scene.position(i, t) + origin;
        SpherePose {
            centre_m: Vector3::new(r.x, r.y, 0.0),
            radius_m: 0.5 * bodies[i][0].d_m,
            orientation: UnitQuaternion::from_scaled_axis(spin(i, t) * t) * q0[i],
        }
    };
    let poses_at = |t: f64| Ok(vec![pose(0, t), pose(1, t)]);
    // The fastest edge point: centre speed plus rim speed, over both phases and spheres.
    let edge_speed = (0..2)
        .flat_map(|i| {
            (0..2).map(move |ph| {
                let b = bodies[i][ph];
                b.velocity_m_s.norm() + 0.5 * b.d_m * b.spin_rad_s.norm()
            })
        })
        .fold(0.0f64, f64::max);
    let blur_px = edge_speed * spec.exposure_s / p;
    let subframes = (blur_px / spec.blur_step_px).ceil().max(1.0);
    if !(subframes.is_finite() && subframes <= MAX_SUBFRAMES as f64) {
        return Err(Error::InvalidParameter {
            name: "motion blur (pixels)",
            value: blur_px,
            expected: "a blur the renderer can sample (at most 409.6 pixels at 0.1-pixel steps)",
        });
    }
    let subframes = subframes as usize;

    let mut frames = Vec::with_capacity(sim.frames.len());
    let mut truth = Vec::with_capacity(sim.frames.len());
    for (k, f) in sim.frames.iter().enumerate() {
        let clean = spec
            .renderer
            .render_exposure(&poses_at, f.t_s, spec.exposure_s, subframes)?;
        frames.push(expose(&clean, &spec.sensor, rng)?);
        let sphere = |i: usize| {
            let ps = pose(i, f.t_s);
            let c = ps.centre_m;
            let r = ps.radius_m;
            let q = ps.orientation;
            let w = spin(i, f.t_s);
            SphereTruth {
                centre_m: [c.x, c.y],
                col_px: c.x / p,
                row_px: (h_m - c.y) / p,
                radius_m: r,
                radius_px: r / p,
                spin_rad_s: [w.x, w.y, w.z],
                orientation: [q.w, q.i, q.j, q.k],
                in_view: c.x - r >= 0.0 && c.x + r <= w_m && c.y - r >= 0.0 && c.y + r <= h_m,
            }
        };
        truth.push(FrameTruth {
            frame: k,
            t_s: f.t_s,
            post: k >= sim.split,
            subframes: if spec.exposure_s > 0.0 { subframes } else { 1 },
            spheres: [sphere(0), sphere(1)],
        });
    }
    Ok(Filmed {
        id: sim.id.clone(),
        frames,
        truth,
        origin_m: [origin.x, origin.y],
    })
}
