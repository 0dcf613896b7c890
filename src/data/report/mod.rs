//! Report documents: what a command writes about its results (Markdown, CSV, JSON), built here
//! once so that the command line and the Python package hand users the same document.

pub mod camera_study;
pub mod fit;
pub mod fit_text;
pub mod kinematics;
pub mod track;
pub mod walton;
