//! Pictures for people: PNG files drawn with plotters and an embedded font, so they
//! need no system fonts.
//!
//! - [`top_view_png`]: points seen from above, coloured by height, with the reference lines,
//!   the extracted edges and the trajectory on top; either the whole scene or a square window
//!   (a curb cut, an intersection, a parked car, the bus bay). Axes in metres from a round
//!   local origin, equal scale on both axes.
//! - [`cross_section_png`]: one scanline in the x′–z′ plane and its bend angles ρ before and
//!   after Taubin smoothing, with the seed candidates marked (like Honma et al.'s Fig. 4
//!   and 6).
//!
//! The inputs are plain slices so callers need nothing but their own columns.
//!
//! | module | what |
//! |---|---|
//! | [`top_view`] | the top view and its colour scales |
//! | [`windows`] | where to zoom: curb cuts, corners, bus bays, occlusions |
//! | [`cross_section`] | one scanline's profile and bend angles |
//! | `style` | colours, axis ticks, clipping and dashing of lines |

pub mod cross_section;
mod style;
pub mod top_view;
pub mod windows;

pub use cross_section::{cross_section_png, CrossSection};
pub use style::viridis;
pub use top_view::{top_view_png, Cloud, Colouring, TopView, TopViewStats, Window, AUTO_Z_SPAN_M};
pub use windows::windows_of_interest;

use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans, embedded (licence in `host-sim/assets/`).
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
pub(crate) const FONT_NAME: &str = "sans-serif";

static REGISTER: Once = Once::new();

/// Registers the embedded font once per process under the name plotters uses by default.
pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        // The bytes are a valid TTF (checked by a unit test); plotters falls back from other
        // styles to Normal, so one registration serves all text.
        let _ = plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT);
    });
}

/// Why a picture could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The input is unusable (empty, mismatched lengths, non-finite).
    #[error("{path}: {what}")]
    Input {
        /// The picture's file.
        path: String,
        /// What was wrong.
        what: String,
    },
    /// Drawing or writing the PNG failed.
    #[error("{path}: drawing failed: {what}")]
    Draw {
        /// The picture's file.
        path: String,
        /// The plotters error.
        what: String,
    },
}

pub(crate) fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw {
        path: path.display().to_string(),
        what: e.to_string(),
    }
}

/// The legend box every chart here uses: white, half-transparent, thin black border.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    ch: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    font_px: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    ch.configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .label_font((FONT_NAME, font_px))
        .draw()
}

pub(crate) fn input_err(path: &Path, what: impl Into<String>) -> PlotError {
    PlotError::Input {
        path: path.display().to_string(),
        what: what.into(),
    }
}

#[cfg(test)]
mod tests;
