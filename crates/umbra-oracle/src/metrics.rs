//! Comparison of a shadow method's per-pixel mask with the [`Reference`], and the diff image.
//!
//! The project's correctness criterion (GUIDE: "pixels outside the one-pixel shadow-boundary
//! band must match exactly") is `mismatches_outside_band == 0`. Background pixels are not
//! samples: whatever the method's mask holds there is ignored.

use crate::envelope::BandParts;
use crate::reference::{Reference, SampleClass};
use crate::OracleError;

/// Counts over the non-background samples of one image. Serialized with exactly these keys.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Metrics {
    /// Non-background pixels.
    pub samples: u64,
    /// Samples the reference puts in shadow.
    pub shadowed_reference: u64,
    /// Samples where the method's shadowed flag differs from the reference.
    pub mismatches: u64,
    /// Samples in the boundary band.
    pub band_samples: u64,
    /// Mismatching samples in the band (tolerated).
    pub band_mismatches: u64,
    /// Mismatching samples outside the band: must be 0 for an exact method.
    pub mismatches_outside_band: u64,
}

fn check(reference: &Reference, what: &'static str, actual: usize) -> Result<(), OracleError> {
    let expected = reference.width as usize * reference.height as usize;
    for (what, actual) in
        [("reference class", reference.class.len()), ("reference band", reference.band.len()), (what, actual)]
    {
        if actual != expected {
            return Err(OracleError::SizeMismatch {
                what,
                expected,
                actual,
                width: reference.width,
                height: reference.height,
            });
        }
    }
    // A reference built without parts (by hand) is judged by its band alone.
    if !reference.parts.is_empty() && reference.parts.len() != expected {
        return Err(OracleError::SizeMismatch {
            what: "reference band parts",
            expected,
            actual: reference.parts.len(),
            width: reference.width,
            height: reference.height,
        });
    }
    Ok(())
}

/// Counts mismatches of `method_shadowed` (per pixel, same layout as the reference: row-major,
/// top row first; `true` = the method put the pixel in shadow) against the reference, with
/// the band of every method ([`Reference::band`]).
pub fn compare(reference: &Reference, method_shadowed: &[bool]) -> Result<Metrics, OracleError> {
    compare_masked(reference, method_shadowed, BandParts::ALL)
}

/// Whether sample `i` is band for a method judged by the band parts in `mask`.
fn band_at(reference: &Reference, i: usize, mask: BandParts) -> bool {
    match reference.parts.get(i) {
        Some(p) => p.intersects(mask),
        // A reference built by hand without parts: its band as it is.
        None => reference.band[i],
    }
}

/// [`compare`] for a method judged by the band parts in `mask` (e.g.
/// [`BandParts::SILHOUETTE`] for a method that draws no cancelling faces).
pub fn compare_masked(
    reference: &Reference,
    method_shadowed: &[bool],
    mask: BandParts,
) -> Result<Metrics, OracleError> {
    check(reference, "method mask", method_shadowed.len())?;
    let mut m = Metrics::default();
    for (i, (&class, &shadowed)) in reference.class.iter().zip(method_shadowed).enumerate() {
        let band = band_at(reference, i, mask);
        let reference_shadowed = match class {
            SampleClass::Background => continue,
            SampleClass::Lit => false,
            SampleClass::Shadowed => true,
        };
        m.samples += 1;
        m.shadowed_reference += reference_shadowed as u64;
        m.band_samples += band as u64;
        if shadowed != reference_shadowed {
            m.mismatches += 1;
            if band {
                m.band_mismatches += 1;
            } else {
                m.mismatches_outside_band += 1;
            }
        }
    }
    Ok(m)
}

/// The pixels (indices, row-major) where `method_shadowed` differs from the reference outside
/// the band: the samples [`Metrics::mismatches_outside_band`] counts, for diagnosis.
pub fn mismatches_outside_band(reference: &Reference, method_shadowed: &[bool]) -> Result<Vec<usize>, OracleError> {
    mismatches_outside_band_masked(reference, method_shadowed, BandParts::ALL)
}

/// [`mismatches_outside_band`] for a method judged by the band parts in `mask`.
pub fn mismatches_outside_band_masked(
    reference: &Reference,
    method_shadowed: &[bool],
    mask: BandParts,
) -> Result<Vec<usize>, OracleError> {
    check(reference, "method mask", method_shadowed.len())?;
    Ok((0..method_shadowed.len())
        .filter(|&i| {
            let class = reference.class[i];
            class != SampleClass::Background
                && !band_at(reference, i, mask)
                && method_shadowed[i] != (class == SampleClass::Shadowed)
        })
        .collect())
}

/// Colour of a false shadow outside the band (method shadowed, reference lit).
pub const FALSE_SHADOW: [u8; 4] = [255, 0, 0, 255];
/// Colour of a false light outside the band (method lit, reference shadowed).
pub const FALSE_LIGHT: [u8; 4] = [0, 0, 255, 255];
/// Colour of every band sample, matching or not (band mismatches are tolerated).
pub const BAND: [u8; 4] = [170, 170, 170, 255];
/// Everything else is the base image at this fraction (in 1/256) of its brightness, so it never
/// reaches the band grey: at most 255 * 102 / 256 = 101 < 170.
pub const DIM: u16 = 102;

/// The diff image, RGBA8 in the reference's layout (row-major, top row first): false shadows
/// outside the band red, false lights outside the band blue, band samples grey, everything else
/// (matching samples and background) the `base_rgba` image dimmed, alpha opaque.
/// `base_rgba` must use the same layout (flip `glReadPixels` rows first).
pub fn diff_image(reference: &Reference, method_shadowed: &[bool], base_rgba: &[u8]) -> Result<Vec<u8>, OracleError> {
    diff_image_masked(reference, method_shadowed, base_rgba, BandParts::ALL)
}

/// [`diff_image`] for a method judged by the band parts in `mask`.
pub fn diff_image_masked(
    reference: &Reference,
    method_shadowed: &[bool],
    base_rgba: &[u8],
    mask: BandParts,
) -> Result<Vec<u8>, OracleError> {
    check(reference, "method mask", method_shadowed.len())?;
    let pixels = reference.class.len();
    if base_rgba.len() != 4 * pixels {
        return Err(OracleError::SizeMismatch {
            what: "base image bytes (RGBA8)",
            expected: 4 * pixels,
            actual: base_rgba.len(),
            width: reference.width,
            height: reference.height,
        });
    }
    let mut out = Vec::with_capacity(4 * pixels);
    for i in 0..pixels {
        let shadowed = method_shadowed[i];
        let colour = match reference.class[i] {
            _ if band_at(reference, i, mask) && reference.class[i] != SampleClass::Background => BAND,
            SampleClass::Lit if shadowed => FALSE_SHADOW,
            SampleClass::Shadowed if !shadowed => FALSE_LIGHT,
            _ => {
                let b = &base_rgba[4 * i..4 * i + 3];
                let dim = |k: usize| ((b[k] as u16 * DIM) >> 8) as u8;
                [dim(0), dim(1), dim(2), 255]
            }
        };
        out.extend_from_slice(&colour);
    }
    Ok(out)
}
