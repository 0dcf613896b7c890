//! All figures, as SVG through plotters' SVG backend (no system fonts: text stays SVG `<text>`).
//! One submodule per figure family; they take plain numbers, never read files.
//!
//! plotters' SVG font sizes come out smaller than asked, so sizes here are chosen by looking at
//! the rendered figures, not by the nominal point size.
use plotters::chart::{ChartContext, SeriesLabelPosition};
use plotters::coord::CoordTranslate;
use plotters::prelude::DrawingBackend;
use plotters::style::{BLACK, Color, RGBColor, WHITE};

/// Okabe & Ito's colour-blind-safe palette (without black and yellow, which carry the models and
/// vanish on white), shared by every figure so that series look alike across them.
pub const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
];

/// The palette's colour for series number `i` (cycling).
pub fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// `x` to four significant digits, printed shortest: ticks read 0.92 and 1e-5, not
/// 0.9200000000000002 or 1.000e-5, and a legend's eta 2236, not 2236.423.
pub fn short(x: f64) -> String {
    let rounded: f64 = format!("{x:.3e}").parse().unwrap_or(x);
    if rounded == 0.0 || (1e-3..1e6).contains(&rounded.abs()) {
        format!("{rounded}")
    } else {
        format!("{rounded:e}")
    }
}

/// The extent of a log axis over data from `lo` to `hi` with a margin of the factor `pad` on
/// each side, in finite positive numbers: where the margin would overflow (data near f64::MAX)
/// or underflow to 0 (subnormal data) that end stays at the data, and a range that is still one
/// number (a lone subnormal) is widened by 2 each side where it can be. Axes built from user
/// data go through it: an infinite end made the tick loops run forever. None unless
/// 0 < lo <= hi < inf.
pub fn log_axis(lo: f64, hi: f64, pad: f64) -> Option<(f64, f64)> {
    if !(lo > 0.0 && lo <= hi && hi.is_finite() && pad >= 1.0) {
        return None;
    }
    let kept = |x: f64, data: f64| if x > 0.0 && x.is_finite() { x } else { data };
    let (mut a, mut b) = (kept(lo / pad, lo), kept(hi * pad, hi));
    if !(a < b) {
        (a, b) = (kept(a / 2.0, a), kept(b * 2.0, b));
    }
    (a < b).then_some((a, b))
}

/// Why a figure could not be drawn: which figure, and the kind of failure as a field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("drawing {figure}: {kind}")]
pub struct PlotError {
    /// The figure, as its file is named (`fig7.svg`) or described (`the overlay of frame 12`).
    pub figure: String,
    pub kind: PlotFailure,
}

/// The kinds of [`PlotError`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotFailure {
    /// plotters' SVG backend refused an element (its message).
    #[error("{0}")]
    Backend(String),
    /// No point of the data can be placed on the figure's axes (what is empty).
    #[error("nothing to draw: {0}")]
    NothingToDraw(String),
    /// The figure needs an input it was not given (which).
    #[error("it needs {0}")]
    Missing(&'static str),
    /// A model curve could not be evaluated.
    #[error("{0}")]
    Model(#[from] crate::error::Error),
}

impl PlotFailure {
    /// The backend's error as a failure (for `map_err`).
    pub fn backend(e: impl std::fmt::Display) -> Self {
        PlotFailure::Backend(e.to_string())
    }
}

impl PlotError {
    /// Names the figure a failure happened in (for `map_err`).
    pub fn of(figure: impl Into<String>) -> impl FnOnce(PlotFailure) -> PlotError {
        let figure = figure.into();
        move |kind| PlotError { figure, kind }
    }
}

/// The command line reports every error as one line of text.
impl From<PlotError> for String {
    fn from(e: PlotError) -> String {
        e.to_string()
    }
}

#[cfg(feature = "io")]
pub mod bench;
/// Draws a chart's legend in the house style: a nearly opaque white box with a grey border, at
/// `position`, labels at `font_px` (nominal; see the module note on SVG font sizes).
pub fn legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_px: u32,
) -> Result<(), PlotFailure> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(("sans-serif", font_px))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(|e| PlotFailure::Backend(format!("a legend: {e}")))
}

pub mod export;
pub mod fit;
pub mod frames;
pub mod frames_accuracy;
pub mod kinematics;
pub mod walton;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axes_are_finite_positive_and_hold_the_data() {
        // Ordinary data: the margin each side, exactly as the figures always had it.
        assert_eq!(log_axis(0.5, 40.0, 1.25), Some((0.5 / 1.25, 40.0 * 1.25)));
        let max = f64::MAX;
        let tiny = 5e-324;
        for (lo, hi) in [
            (1.0, max),
            (max, max),
            (tiny, tiny),
            (tiny, 1.0),
            (1e-310, 1e-309),
        ] {
            let (a, b) = log_axis(lo, hi, 1.25).unwrap();
            assert!(a > 0.0 && b.is_finite() && a < b, "{lo} {hi}: {a} {b}");
            assert!(a <= lo && hi <= b, "{lo} {hi}: {a} {b}");
        }
        for (lo, hi) in [
            (0.0, 1.0),
            (2.0, 1.0),
            (1.0, f64::INFINITY),
            (f64::NAN, 1.0),
        ] {
            assert_eq!(log_axis(lo, hi, 1.25), None, "{lo} {hi}");
        }
    }

    #[test]
    fn failures_name_the_figure_and_their_kind() {
        let e = kinematics::camera_study_svg(&[], "no points").unwrap_err();
        assert_eq!(e.figure, "camera_study.svg");
        assert!(matches!(e.kind, PlotFailure::NothingToDraw(_)), "{e:?}");
        assert_eq!(
            e.to_string(),
            "drawing camera_study.svg: nothing to draw: no measurable point in the camera study"
        );
        let nan_only = frames_accuracy::Panel {
            title: "centre error".into(),
            x_desc: "x".into(),
            y_desc: "y".into(),
            log_x: false,
            lines: vec![frames_accuracy::Line {
                label: "fit".into(),
                points: vec![(1.0, f64::NAN)],
            }],
            references: vec![],
        };
        let e = frames_accuracy::accuracy_svg(&[nan_only], 1, "t").unwrap_err();
        assert_eq!(
            e.kind,
            PlotFailure::NothingToDraw("panel 'centre error' has no finite point".into())
        );
        let text: String = e.into();
        assert!(text.starts_with("drawing the accuracy figure: "), "{text}");
    }
}
