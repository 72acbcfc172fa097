//! The checks of a frame's parameters before any GPU work: what this backend cannot draw
//! ([`WgpuError::Unsupported`]), then the checks every backend makes
//! ([`FrameParams::check`], [`WgpuError::InvalidParams`]).

use umbra_geom::camera::DepthConvention;
use umbra_geom::frame::{Counter, Receivers};
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
    if params.receivers != Receivers::Both {
        return Err(WgpuError::Unsupported {
            what: "receivers",
            value: params.receivers.name().to_string(),
            supported: Receivers::Both.name(),
        });
    }
    Ok(params.check()?)
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
        let front = FrameParams { receivers: Receivers::Front, ..FrameParams::default() };
        let e = validate(&front).unwrap_err();
        assert!(matches!(e, WgpuError::Unsupported { what: "receivers", .. }), "{e:?}");
        let e = validate(&FrameParams { width: 0, ..FrameParams::default() }).unwrap_err();
        assert!(matches!(e, WgpuError::InvalidParams(_)), "{e:?}");
    }
}
