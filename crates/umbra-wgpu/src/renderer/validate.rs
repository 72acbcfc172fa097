//! The checks of a frame's parameters before any GPU work: what this backend cannot draw
//! ([`WgpuError::Unsupported`]), then camera, size, lights, capture indices and shading
//! ([`WgpuError::InvalidParams`]).

use umbra_geom::camera::DepthConvention;
use umbra_geom::frame::Counter;
use umbra_geom::frame_images::LightCapture;
use umbra_geom::FrameParams;

use crate::error::WgpuError;

/// Err unless `params` can be drawn by this backend as given.
pub(super) fn validate(params: &FrameParams) -> Result<(), WgpuError> {
    if params.counter != Counter::Stencil8 {
        return Err(WgpuError::Unsupported {
            what: "counter",
            value: params.counter.name().to_string(),
            supported: Counter::Stencil8.name(),
        });
    }
    if params.depth_convention != DepthConvention::ReversedZ {
        return Err(WgpuError::Unsupported {
            what: "depth convention",
            value: format!("{:?}", params.depth_convention),
            supported: "ReversedZ",
        });
    }
    params.camera.validate()?;
    if params.width == 0 || params.height == 0 {
        return Err(WgpuError::InvalidParams(format!("frame size {}x{}", params.width, params.height)));
    }
    for (i, l) in params.lights.iter().enumerate() {
        umbra_geom::check_light(i, l)?;
    }
    for (what, capture) in [("stencil", params.capture.stencil), ("lit mask", params.capture.lit_mask)] {
        if let LightCapture::Light(i) = capture {
            if i >= params.lights.len() {
                return Err(WgpuError::InvalidParams(format!(
                    "{what} capture of light {i}, but {} light(s)",
                    params.lights.len()
                )));
            }
        }
    }
    let scalars = [params.ambient, params.specular, params.shininess];
    if scalars.iter().chain(&params.albedo).chain(&params.light_color).chain(&params.background).any(|v| !v.is_finite())
    {
        return Err(WgpuError::InvalidParams("non-finite colour or shading parameter".into()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_wgpu_cannot_draw() {
        assert!(validate(&FrameParams::default()).is_ok());
        let e = validate(&FrameParams { counter: Counter::Float32, ..FrameParams::default() }).unwrap_err();
        assert!(matches!(e, WgpuError::Unsupported { what: "counter", .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            "the wgpu backend does not support counter float32 (it supports stencil8 only); use umbra-gl for it"
        );
        let standard = FrameParams { depth_convention: DepthConvention::Standard, ..FrameParams::default() };
        let e = validate(&standard).unwrap_err();
        assert!(matches!(e, WgpuError::Unsupported { what: "depth convention", .. }), "{e:?}");
        let e = validate(&FrameParams { width: 0, ..FrameParams::default() }).unwrap_err();
        assert!(matches!(e, WgpuError::InvalidParams(_)), "{e:?}");
    }
}
