//! The device and the host API's checks: a missing adapter is a typed error naming what to
//! install (never a panic), bad formats and names are errors that say what is wrong.

mod common;

use umbra_wgpu::{HeadlessGpu, PassFormats, ShadowVolumes, WgpuError};

#[test]
fn no_adapter_is_an_error_that_says_what_to_install() {
    // No backend at all: wgpu finds no adapter, whatever the machine has.
    match HeadlessGpu::with_backends(umbra_wgpu::wgpu::Backends::empty()) {
        Err(e @ WgpuError::NoAdapter { .. }) => {
            let text = e.to_string();
            assert!(text.starts_with("no no adapter found"), "{text}");
            if cfg!(target_os = "linux") {
                assert!(text.contains("mesa-vulkan-drivers libvulkan1"), "{text}");
            }
        }
        Err(e) => panic!("expected NoAdapter, got {e}"),
        Ok(_) => panic!("an adapter without backends"),
    }
}

#[test]
fn adapter_has_the_features_umbra_needs() {
    let Some(gpu) = common::gpu() else { return };
    let features = gpu.device.features();
    assert!(features.contains(umbra_wgpu::device::frame_features()), "{features:?}");
    let line = gpu.adapter_line();
    assert!(!line.is_empty());
    println!("adapter: {line}");
}

#[test]
fn host_api_refuses_bad_formats_and_names() {
    let Some(gpu) = common::gpu() else { return };
    let depth = umbra_wgpu::wgpu::TextureFormat::Depth24PlusStencil8;
    let formats = |depth_stencil| PassFormats { color: vec![Some(umbra_wgpu::COLOR_FORMAT)], depth_stencil };
    let err = |r: Result<ShadowVolumes, WgpuError>| r.err().expect("an error").to_string();
    // No stencil, or no depth: the volumes need both.
    let e = err(ShadowVolumes::new(
        &gpu.device,
        &formats(umbra_wgpu::wgpu::TextureFormat::Depth32Float),
        1,
        "cs-silhouette",
    ));
    assert!(e.contains("depth and a stencil aspect"), "{e}");
    let e =
        err(ShadowVolumes::new(&gpu.device, &formats(umbra_wgpu::wgpu::TextureFormat::Stencil8), 1, "cs-silhouette"));
    assert!(e.contains("depth and a stencil aspect"), "{e}");
    let e = err(ShadowVolumes::new(&gpu.device, &formats(depth), 3, "cs-silhouette"));
    assert!(e.contains("sample count 3"), "{e}");
    // A GL-only method: the error lists what the wgpu backend has.
    let e = err(ShadowVolumes::new(&gpu.device, &formats(depth), 1, "gs-silhouette"));
    assert!(e.contains("\"gs-silhouette\"") && e.contains("cs-silhouette"), "{e}");
    // Every registered name builds, with and without colour attachments, multisampled too.
    for &name in umbra_wgpu::method_names() {
        ShadowVolumes::new(&gpu.device, &formats(depth), 4, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let depth_only = PassFormats { color: Vec::new(), depth_stencil: depth };
        ShadowVolumes::new(&gpu.device, &depth_only, 1, name).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}
