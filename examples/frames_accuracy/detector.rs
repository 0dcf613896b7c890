//! The project's detector (src/frames/), as a method of the study.

use super::Method;

pub fn methods() -> Vec<(&'static str, Method)> {
    Vec::new()
}
