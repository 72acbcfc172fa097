//! [`Driver`]: one backend's frames as the interleaved schedule drives them; the GL driver is
//! `gl_driver.rs`, the wgpu driver `wgpu_driver.rs`.

use super::flythrough::Keyframe;

/// One backend's frames, as the interleaved schedule drives them (`measure.rs`).
pub trait Driver {
    /// "gl" or "wgpu".
    fn backend(&self) -> &'static str;
    /// The device, for the report.
    fn device_name(&self) -> String;
    /// Triangles drawn.
    fn triangles(&self) -> usize;
    /// Lights per frame.
    fn lights(&self) -> usize;
    /// Method `method`'s counter label ("stencil8", "float32", "none").
    fn counter(&self, method: usize) -> String;
    /// Draws method `method`'s frame at `cam` (no readback) and returns its time: the GPU
    /// idle before, CPU clock from the first command to the frame's completion (ms).
    fn frame(&mut self, method: usize, cam: Keyframe) -> Result<f64, String>;
    /// The same frame once more with per-stage timing: (stage, GPU ms) summed over lights;
    /// empty when the backend has no stage timing.
    fn stages(&mut self, method: usize, cam: Keyframe) -> Result<Vec<(String, f64)>, String>;
    /// The same frame once more with work counting ([`umbra_gl::ShadowMethod::set_count_work`]):
    /// its counts summed over lights, or `None` when the method (or backend) counts no work
    /// (then nothing is drawn).
    fn work(&mut self, _method: usize, _cam: Keyframe) -> Result<Option<umbra_gl::WorkCounts>, String> {
        Ok(None)
    }
    /// The same frame once more with the volume passes' fragments counted: what they drew,
    /// summed over lights, or `None` when the method reports nothing (then nothing is drawn).
    fn volume_counts(&mut self, _method: usize, _cam: Keyframe) -> Result<Option<super::stats::VolumeCounts>, String> {
        Ok(None)
    }
    /// Whether method `method` culls its volumes against the receivers in these frames.
    fn volume_cull(&self, _method: usize) -> bool {
        false
    }
    /// Lights of the last frame counted z-pass.
    fn zpass_lights(&self, method: usize) -> usize;
    /// Bytes of GPU memory method `method` holds.
    fn gpu_bytes(&self, method: usize) -> usize;
    /// Method `method`'s figures of its per-scene preprocessing (ray-bvh's `bvh_build_ms`,
    /// `bvh_bytes`, ...), keys of its `--json` rows; none by default.
    fn scene_figures(&self, _method: usize) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
}
