//! `umbra verify --external-mask`: reads a shadow mask made outside umbra's renderer (the
//! WebGL2 viewer's `mask=1` view, read back by the browser test) so that the oracle judges it
//! with its own band, exactly as it judges a native method ([`umbra_verify::verify_external_mask`]).

use std::path::Path;

use umbra_gl::RgbaImage;

use crate::error::CliError;

/// Decodes an 8-bit RGB or RGBA PNG (top row first) into RGBA8; errors name the file.
pub fn load_mask_png(path: &Path) -> Result<RgbaImage, CliError> {
    let err = |detail: String| CliError::Other(format!("{}: {detail}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| CliError::Io { path: path.display().to_string(), source: e })?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    // Palette and sub-byte images expanded to 8 bits per channel; 16-bit ones refused below.
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| err(format!("not a readable PNG ({e})")))?;
    let size = reader.output_buffer_size().ok_or_else(|| err("too large to decode".into()))?;
    let mut bytes = vec![0; size];
    let info = reader.next_frame(&mut bytes).map_err(|e| err(format!("not a readable PNG ({e})")))?;
    if info.bit_depth != png::BitDepth::Eight {
        return Err(err(format!("{:?}-bit channels; a mask has 8", info.bit_depth)));
    }
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => return Err(err(format!("colour type {other:?}; a mask is RGB or RGBA"))),
    };
    let pixels = bytes[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|c| [c[0], c[1], c[2], if channels == 4 { c[3] } else { 255 }])
        .collect();
    Ok(RgbaImage { width: info.width, height: info.height, pixels })
}
