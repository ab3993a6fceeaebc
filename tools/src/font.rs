//! The font of every chart: DejaVu Sans (Debian's `fonts-dejavu-core`) read at run time and
//! registered with plotters' `ab_glyph` backend as "sans-serif", so no system library is needed
//! at build time; `AMPM_FONT=/path/to/font.ttf` overrides it.

use plotters::style::{register_font, FontStyle};
use std::path::Path;

/// Where the font is looked for, in order (after `$AMPM_FONT`).
const FONT_CANDIDATES: [&str; 3] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
];

/// The font family the charts use.
pub const FONT: &str = "sans-serif";

/// Reads and registers the charts' font; says what to install when none is found.
#[inline]
pub fn init_font() -> Result<String, String> {
    let env = std::env::var("AMPM_FONT").ok();
    let path = env
        .iter()
        .map(String::as_str)
        .chain(FONT_CANDIDATES)
        .find(|p| Path::new(p).is_file())
        .ok_or_else(|| {
            format!(
                "no TrueType font found (tried $AMPM_FONT and {}): install Debian's \
                 fonts-dejavu-core (apt-get install fonts-dejavu-core) or set AMPM_FONT",
                FONT_CANDIDATES.join(", ")
            )
        })?;
    let bytes = std::fs::read(path).map_err(|e| format!("reading {path}: {e}"))?;
    // plotters keeps the font for the whole process: leak the one buffer on purpose.
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    register_font(FONT, FontStyle::Normal, bytes)
        .map_err(|_| format!("{path} is not a usable TrueType/OpenType font"))?;
    Ok(path.to_string())
}
