//! The camera and depth conventions, shared with every backend: [`Camera`],
//! [`DepthConvention`], [`to_f32_cols`] live in [`umbra_geom::camera`] (the infinite far plane
//! of Everitt & Kilgard 2002, standard or reversed-Z; see there for the numbers) and are
//! re-exported here. This module adds what a convention means in OpenGL terms
//! ([`DepthConventionGl`]: depth function, glClipControl depth mode, depth format).

pub use umbra_geom::camera::{to_f32_cols, Camera, CameraError, DepthConvention, Projection};

/// The OpenGL enums of a [`DepthConvention`].
pub trait DepthConventionGl {
    /// The depth function under which a fragment passes when it is strictly NEARER than the
    /// stored depth: LESS for Standard, GREATER for ReversedZ.
    fn nearer(self) -> u32;

    /// glClipControl depth mode: NEGATIVE_ONE_TO_ONE (GL's default) or ZERO_TO_ONE. The origin
    /// is always LOWER_LEFT (GL's default).
    fn clip_depth_mode(self) -> u32;

    /// Depth-stencil format of the renderer's own target: DEPTH24_STENCIL8 for Standard (the
    /// quantum of 1 - n / d near 1 is 2^-24 in fixed point and in float alike, so float would
    /// buy nothing), DEPTH32F_STENCIL8 for ReversedZ (float keeps ~24 significant bits of n / d
    /// down to tiny depths, where fixed point would keep only the leading bits).
    fn depth_format(self) -> u32;
}

impl DepthConventionGl for DepthConvention {
    fn nearer(self) -> u32 {
        match self {
            DepthConvention::Standard => glow::LESS,
            DepthConvention::ReversedZ => glow::GREATER,
        }
    }

    fn clip_depth_mode(self) -> u32 {
        match self {
            DepthConvention::Standard => glow::NEGATIVE_ONE_TO_ONE,
            DepthConvention::ReversedZ => glow::ZERO_TO_ONE,
        }
    }

    fn depth_format(self) -> u32 {
        match self {
            DepthConvention::Standard => glow::DEPTH24_STENCIL8,
            DepthConvention::ReversedZ => glow::DEPTH32F_STENCIL8,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gl_enums_follow_the_convention() {
        assert_eq!(DepthConvention::Standard.nearer(), glow::LESS);
        assert_eq!(DepthConvention::ReversedZ.nearer(), glow::GREATER);
        assert_eq!(DepthConvention::ReversedZ.clip_depth_mode(), glow::ZERO_TO_ONE);
        assert_eq!(DepthConvention::Standard.depth_format(), glow::DEPTH24_STENCIL8);
        assert_eq!(DepthConvention::ReversedZ.depth_format(), glow::DEPTH32F_STENCIL8);
    }
}
