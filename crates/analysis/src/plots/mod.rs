//! Figures with plotters, written as PNG or SVG (chosen by the file extension), atomically.
//!
//! Text uses DejaVu Sans embedded in the binary (`dejavu` crate, registered with plotters'
//! `ab_glyph` backend), so PNGs render identically on machines without system fonts. SVGs
//! reference the `sans-serif` family and are rendered by the viewer.
//!
//! | module | figure |
//! |---|---|
//! | [`timeseries`] | Fig. 3: chord sketches, kinematics, measured vs predicted C_Fx/C_Fy with ±2σ |
//! | [`errors`] | Fig. 4: standardized-error histograms with intervals; half-stroke averages |
//! | [`authority`] | Fig. 5: HDR contours and modes, per-pair scatter, summary circle grid |
//! | [`hovering`] | the published hovering case: C_L and C_D histories of several sources |
//! | [`design`] | designed kinematics, their loads with the predicted band, convergence, a closed loop |
//! | [`rig`] | the rig check: a dataset's standardized loads over the reference's mean and 95 % band |
//! | [`wing3d`] | Fig. 2C: 3-D wing-motion sketches (chord lines along the path, LE dotted) |
//! | [`training`] | training curves |
//! | [`sweep`] | accuracy against a swept setting (D_x, training-set size) |
//! | [`sysid`] | system identification: test-part prediction with ±2σ band |

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use crate::error::{AnalysisError, Result};

pub mod authority;
pub mod design;
pub mod errors;
pub mod history;
pub mod hovering;
pub mod processing;
pub mod rig;
pub mod sweep;
pub mod sysid;
pub mod timeseries;
pub mod training;
pub mod wing3d;

/// Result of a drawing routine, generic over the backend's error.
pub(crate) type DrawResult = std::result::Result<(), Box<dyn std::error::Error>>;

/// The palette of the published figures (MATLAB `lines` order, `plotter.m` `map2`).
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 189),
    RGBColor(217, 83, 25),
    RGBColor(237, 177, 32),
    RGBColor(126, 47, 142),
    RGBColor(119, 172, 48),
    RGBColor(27, 158, 119),
    RGBColor(162, 20, 47),
];

/// The colour of the `i`-th model in every figure that compares models: each model its own
/// (up to the palette's 7), the measured loads black.
pub fn model_colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Font family name used by every figure.
pub const FONT: &str = "sans-serif";

static FONTS: Once = Once::new();

/// Registers the embedded DejaVu Sans faces under [`FONT`] (idempotent).
pub fn register_fonts() {
    FONTS.call_once(|| {
        // The embedded files are valid TrueType fonts; registration cannot fail on them.
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
        let _ = register_font(FONT, FontStyle::Italic, dejavu::sans::oblique());
        let _ = register_font(FONT, FontStyle::Oblique, dejavu::sans::oblique());
    });
}

/// Output format of a figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Portable Network Graphics (raster, embedded fonts).
    Png,
    /// Scalable Vector Graphics.
    Svg,
}

impl Format {
    /// Format from a path's extension (`.png` or `.svg`, case-insensitive).
    ///
    /// # Errors
    /// [`AnalysisError::Plot`] for any other extension.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(Self::Png),
            Some("svg") => Ok(Self::Svg),
            _ => Err(AnalysisError::Plot {
                path: path.to_path_buf(),
                message: "unknown figure format: use a .png or .svg file name".into(),
            }),
        }
    }
}

fn plot_err(path: &Path, e: impl std::fmt::Display) -> AnalysisError {
    AnalysisError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

fn io_err(path: &Path, source: std::io::Error) -> AnalysisError {
    AnalysisError::Io {
        path: PathBuf::from(path),
        source,
    }
}

/// Encodes an RGB8 buffer as PNG bytes.
pub(crate) fn encode_png(
    rgb: &[u8],
    width: u32,
    height: u32,
) -> std::result::Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header()?;
        w.write_image_data(rgb)?;
    }
    Ok(out)
}

/// Renders a figure of `size` pixels into `path` (format by extension) with `draw`, which is
/// called with a white root area. Written atomically.
macro_rules! render {
    ($path:expr, $size:expr, |$root:ident| $body:expr) => {{
        let path: &std::path::Path = $path;
        let size: (u32, u32) = $size;
        $crate::plots::register_fonts();
        match $crate::plots::Format::from_path(path)? {
            $crate::plots::Format::Png => {
                let mut buf = vec![255u8; size.0 as usize * size.1 as usize * 3];
                {
                    let $root = plotters::prelude::BitMapBackend::with_buffer(&mut buf, size)
                        .into_drawing_area();
                    let r: $crate::plots::DrawResult = (|| {
                        $root.fill(&plotters::prelude::WHITE)?;
                        $body?;
                        $root.present()?;
                        Ok(())
                    })();
                    r.map_err(|e| $crate::plots::plot_err_pub(path, e))?;
                }
                let bytes = $crate::plots::encode_png(&buf, size.0, size.1)
                    .map_err(|e| $crate::plots::plot_err_pub(path, e))?;
                $crate::plots::write_file(path, &bytes)
            }
            $crate::plots::Format::Svg => {
                let mut s = String::new();
                {
                    let $root = plotters::prelude::SVGBackend::with_string(&mut s, size)
                        .into_drawing_area();
                    let r: $crate::plots::DrawResult = (|| {
                        $root.fill(&plotters::prelude::WHITE)?;
                        $body?;
                        $root.present()?;
                        Ok(())
                    })();
                    r.map_err(|e| $crate::plots::plot_err_pub(path, e))?;
                }
                $crate::plots::write_file(path, s.as_bytes())
            }
        }
    }};
}
pub(crate) use render;

pub(crate) fn plot_err_pub(path: &Path, e: impl std::fmt::Display) -> AnalysisError {
    plot_err(path, e)
}

/// Writes bytes atomically, mapping I/O errors to [`AnalysisError::Io`].
pub(crate) fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    flapssm_data::atomic::write_bytes_atomic(path, bytes).map_err(|e| io_err(path, e))
}

/// `(min, max)` of finite values with a relative margin; `(-1, 1)` if there are none.
pub(crate) fn padded_range<'a>(
    values: impl IntoIterator<Item = &'a f64>,
    margin: f64,
) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let span = if hi > lo { hi - lo } else { 1.0 };
    (lo - margin * span, hi + margin * span)
}

/// A text style of the embedded font.
pub(crate) fn font(size: f64) -> TextStyle<'static> {
    (FONT, size).into_font().into()
}

/// Draws the legend of `ch`'s labelled series at `position` in the plots' one style: the
/// embedded font at `size`, a white box at 85 % and a light grey border.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    ch: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
    size: f64,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    ch.configure_series_labels()
        .position(position)
        .label_font(font(size))
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(200, 200, 200))
        .draw()
}

/// A bold text style of the embedded font.
pub(crate) fn bold(size: f64) -> TextStyle<'static> {
    (FONT, size, FontStyle::Bold).into_font().into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_by_extension() {
        assert_eq!(
            Format::from_path(Path::new("a/b.PNG")).unwrap(),
            Format::Png
        );
        assert_eq!(Format::from_path(Path::new("b.svg")).unwrap(), Format::Svg);
        assert!(Format::from_path(Path::new("b.pdf")).is_err());
    }

    #[test]
    fn each_model_has_its_own_colour() {
        let colours: Vec<_> = (0..PALETTE.len()).map(model_colour).collect();
        for (i, a) in colours.iter().enumerate() {
            assert_ne!((a.0, a.1, a.2), (0, 0, 0), "black is the measured loads'");
            for b in &colours[i + 1..] {
                assert_ne!((a.0, a.1, a.2), (b.0, b.1, b.2));
            }
        }
    }
}
