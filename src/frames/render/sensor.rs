//! The sensor: what turns a noiseless rendered image into recorded pixel values.

use super::GrayImage;
use crate::error::{Error, Result};
use rand::Rng;
use rand_distr::{Distribution, Normal, Poisson};

/// Sensor noise and digitisation, in the image's [0, 1] units (1 = full scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensor {
    /// Standard deviation of the Gaussian read noise (e.g. 0.01 = 2.55 grey levels of 8 bits).
    pub read_noise: f64,
    /// Photo-electrons at full scale; `Some(N)` adds shot noise (a level I collects Poisson(I N)
    /// electrons, so its variance is I/N), `None` none.
    pub full_well_e: Option<f64>,
    /// Bits per pixel of the recorded value (`Some(8)`: 256 grey levels), `None` to keep floats.
    pub bits: Option<u32>,
}

impl Sensor {
    /// No noise and no quantisation: the rendered radiance as recorded.
    pub const IDEAL: Sensor = Sensor {
        read_noise: 0.0,
        full_well_e: None,
        bits: None,
    };

    fn validate(&self) -> Result<()> {
        if !(self.read_noise.is_finite() && (0.0..=1.0).contains(&self.read_noise)) {
            return Err(Error::InvalidParameter {
                name: "read noise (full-scale units)",
                value: self.read_noise,
                expected: "in [0, 1]",
            });
        }
        if let Some(n) = self.full_well_e
            && !(n.is_finite() && (1.0..=1e12).contains(&n))
        {
            return Err(Error::InvalidParameter {
                name: "full-well capacity (electrons)",
                value: n,
                expected: "in [1, 1e12]",
            });
        }
        if let Some(b) = self.bits
            && !(1..=16).contains(&b)
        {
            return Err(Error::InvalidParameter {
                name: "bits per pixel",
                value: b as f64,
                expected: "1 to 16",
            });
        }
        Ok(())
    }
}

/// Records a noiseless image: shot noise (Poisson electron counts), then Gaussian read noise, then
/// the sensor's clipping to its range [0, 1] (a real sensor saturates at full scale and reads no
/// less than its black level), then rounding to `bits`. A non-finite input pixel is an error.
pub fn expose(image: &GrayImage, sensor: &Sensor, rng: &mut impl Rng) -> Result<GrayImage> {
    sensor.validate()?;
    let read = Normal::new(0.0, sensor.read_noise).map_err(|_| Error::InvalidParameter {
        name: "read noise (full-scale units)",
        value: sensor.read_noise,
        expected: "in [0, 1]",
    })?;
    let levels = sensor.bits.map(|b| ((1u32 << b) - 1) as f64);
    let mut out = image.clone();
    for px in out.pixels.iter_mut() {
        let signal = *px as f64;
        if !(signal.is_finite() && signal >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "rendered pixel value",
                value: signal,
                expected: "a finite level >= 0",
            });
        }
        let mut x = match sensor.full_well_e {
            Some(n) if signal > 0.0 => {
                let electrons: f64 = Poisson::new(signal * n)
                    .map_err(|_| Error::InvalidParameter {
                        name: "expected photo-electrons",
                        value: signal * n,
                        expected: "a finite count > 0",
                    })?
                    .sample(rng);
                electrons / n
            }
            _ => signal,
        };
        if sensor.read_noise > 0.0 {
            x += read.sample(rng);
        }
        x = x.clamp(0.0, 1.0);
        if let Some(l) = levels {
            x = (x * l).round() / l;
        }
        *px = x as f32;
    }
    Ok(out)
}
