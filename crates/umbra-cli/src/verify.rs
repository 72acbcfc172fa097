//! `umbra verify`: every requested method against the ray-traced reference, per sample.
//! Exit status 1 when a method that must be exact has a mismatch outside the boundary band.

use std::path::{Path, PathBuf};

use serde::Serialize;
use umbra_geom::weld::WeldedMesh;
use umbra_gl::RgbaImage;
use umbra_oracle::{diff_image_masked, mismatches_outside_band_masked};
use umbra_verify::{raster_view, verify_external_mask, verify_method, view_reference_in, MethodReport, ViewReference};

use crate::backend::Backend;
use crate::config::VerifyConfig;
use crate::error::CliError;
use crate::session::Session;

/// One line of `verify --json`; the keys are a contract.
#[derive(Serialize)]
struct JsonRow<'a> {
    method: &'a str,
    /// "gl" or "wgpu" (`--backend`).
    backend: &'static str,
    /// "stencil8" or "float32" for methods that count in the stencil, "none" for the others.
    counter: &'a str,
    /// Per light: counted z-pass (`--zmode`; auto chooses it where provably exact).
    zpass: Vec<bool>,
    /// "both" or "front" (`--receivers`): which faces the samples' depth pass showed.
    receivers: &'static str,
    samples: u64,
    shadowed_reference: u64,
    mismatches: u64,
    band_samples: u64,
    band_mismatches: u64,
    mismatches_outside_band: u64,
    reference_ms: f64,
    render_ms: f64,
    /// The same counts per light, in `--light` order.
    per_light: Vec<JsonLight>,
}

/// A row of `verify --json`: a method's counts, or why it could not be verified here.
#[derive(Serialize)]
#[serde(untagged)]
enum JsonOut<'a> {
    Row(JsonRow<'a>),
    Failed { method: &'a str, backend: &'static str, error: &'a str },
}

/// One light's counts in a `verify --json` row.
#[derive(Serialize)]
struct JsonLight {
    light: [f32; 4],
    samples: u64,
    shadowed_reference: u64,
    mismatches: u64,
    band_samples: u64,
    band_mismatches: u64,
    mismatches_outside_band: u64,
}

/// A method that could not be verified: `verify` with several methods goes on with the others,
/// prints this as the method's row and exits with status 2.
struct FailedMethod {
    method: String,
    error: String,
}

/// One method's outcome. With several methods, a method that cannot be drawn here (unsupported
/// by this GL, out of memory, a shader the driver rejects) is reported on stderr at once and
/// becomes an error row, and the others are still verified; with one method, its error is the
/// command's.
fn method_result<T>(name: &str, r: Result<T, CliError>, methods: usize) -> Result<Result<T, FailedMethod>, CliError> {
    match r {
        Ok(v) => Ok(Ok(v)),
        Err(e) if methods > 1 => {
            eprintln!("umbra: {name}: {e} (verifying the other methods)");
            Ok(Err(FailedMethod { method: name.to_string(), error: e.to_string() }))
        }
        Err(e) => Err(e),
    }
}

/// `diff.png` → `diff.METHOD.png` when several images are written (and `.lightN` per light).
fn diff_path(base: &str, method: &str, light: usize, methods: usize, lights: usize) -> PathBuf {
    let p = Path::new(base);
    let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "diff".into());
    let ext = p.extension().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "png".into());
    let mut name = stem;
    if methods > 1 {
        name.push('.');
        name.push_str(&method.replace(':', "_"));
    }
    if lights > 1 {
        name.push_str(&format!(".light{light}"));
    }
    p.with_file_name(format!("{name}.{ext}"))
}

fn write_diff(
    path: &Path,
    report: &MethodReport,
    reference: &umbra_oracle::Reference,
    light: usize,
) -> Result<(), CliError> {
    let base: Vec<u8> = report.image.pixels.iter().flatten().copied().collect();
    let shadowed = &report.per_light[light].shadowed;
    let rgba =
        diff_image_masked(reference, shadowed, &base, report.band_mask).map_err(|e| CliError::Other(e.to_string()))?;
    let pixels = rgba.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
    let img = RgbaImage { width: reference.width, height: reference.height, pixels };
    img.save_png(path).map_err(|e| CliError::Gl(e.to_string()))
}

/// Prints on stderr what is known about up to `n` of `report`'s mismatches outside the band, per
/// light (`--explain`).
fn explain(
    name: &str,
    report: &MethodReport,
    reference: &ViewReference,
    welded: &WeldedMesh,
    n: usize,
) -> Result<(), CliError> {
    for (lr, res) in reference.lights.iter().zip(&report.per_light) {
        let outside = mismatches_outside_band_masked(&lr.reference, &res.shadowed, report.band_mask)
            .map_err(|e| CliError::Other(e.to_string()))?;
        for &k in outside.iter().take(n) {
            let (x, y) = ((k % reference.width as usize) as u32, (k / reference.width as usize) as u32);
            let what = if res.shadowed[k] { "false shadow" } else { "false light" };
            eprintln!("{name} light {} {what} {}", lr.light, umbra_verify::explain(welded, reference, lr.light, x, y));
        }
    }
    Ok(())
}

/// Returns whether every method that must be exact passed.
pub fn run(a: &VerifyConfig) -> Result<bool, CliError> {
    let (backend, methods, sm, view, choice) = (a.backend, &a.methods, &a.sm, &a.view, a.counter);
    // Per method: (report, counter label, per-light z-pass); then the reference, the mesh and
    // the device that drew them.
    let (results, reference, welded, device_name) = match backend {
        Backend::Gl => {
            let mut s = Session::new(view)?;
            let mut params = s.frame_params(view);
            let decision =
                crate::methods::choose_counter(choice, &s.welded.positions, &s.welded.triangles, &params.lights)?;
            crate::methods::report_counter(&decision);
            params.counter = decision.counter;
            let gl = s.context.gl();
            let mut raster = raster_view(gl, &params);
            if let Some(bits) = a.subpixel_bits {
                raster.subpixel_bits = bits;
            }
            // An external mask was decided on its renderer's own depth pass, not on these
            // samples: the band adds the surfaces that pass may have seen instead.
            raster.other_depth_pass = a.external_mask.is_some();
            let reference = view_reference_in(gl, &mut s.renderer, &s.scene, &params, raster)
                .map_err(|e| CliError::Other(e.to_string()))?;
            let mut results = Vec::new();
            for name in methods {
                let verified = (|| {
                    let mut method = crate::methods::make_method(name, sm, "--method")?;
                    let report = verify_method(gl, &mut s.renderer, &s.scene, method.as_mut(), &params, &reference);
                    let counter = crate::methods::counter_label(method.as_ref(), params.counter);
                    let zpass = s.renderer.last_zpass().to_vec();
                    method.destroy(gl);
                    let report = report.map_err(|e| CliError::Other(e.to_string()))?;
                    Ok::<_, CliError>((report, counter, zpass))
                })();
                results.push(method_result(name, verified, methods.len())?);
            }
            (results, reference, s.welded.clone(), s.context.renderer_string())
        }
        Backend::Wgpu => {
            let (s, reference, verified) = crate::wgpu_backend::verify(view, methods, sm, choice)?;
            let mut results = Vec::new();
            for (name, v) in methods.iter().zip(verified) {
                results.push(method_result(name, v.map(|v| (v.report, v.counter, v.zpass)), methods.len())?);
            }
            (results, reference, s.welded.clone(), format!("wgpu on {}", s.gpu.adapter_line()))
        }
    };
    let mut rows = Vec::new();
    let rows_expected = methods.len() + usize::from(a.external_mask.is_some());
    let mut all_passed = true;
    let mut failed = Vec::new();
    for result in results {
        let (report, counter, zpass) = match result {
            Ok(r) => r,
            Err(f) => {
                failed.push(f);
                continue;
            }
        };
        let name = &report.method;
        if let Some(base) = &a.diff {
            for (i, lr) in reference.lights.iter().enumerate() {
                let path = diff_path(base, name, i, rows_expected, reference.lights.len());
                write_diff(&path, &report, &lr.reference, i)?;
            }
        }
        explain(name, &report, &reference, &welded, a.explain)?;
        all_passed &= report.passed();
        rows.push((report, reference.total_ms(), counter, zpass));
    }
    if let Some(path) = &a.external_mask {
        // One more row: a mask drawn elsewhere (the WebGL2 viewer), judged by the same oracle.
        let mask = crate::external_mask::load_mask_png(Path::new(path))?;
        let report = verify_external_mask(path, &mask, &reference).map_err(|e| CliError::Other(e.to_string()))?;
        if let Some(base) = &a.diff {
            write_diff(&diff_path(base, "external", 0, rows_expected, 1), &report, &reference.lights[0].reference, 0)?;
        }
        explain(path, &report, &reference, &welded, a.explain)?;
        all_passed &= report.passed();
        rows.push((report, reference.total_ms(), "none", Vec::new()));
    }
    if a.json {
        let mut json: Vec<JsonOut> = rows
            .iter()
            .map(|(r, reference_ms, counter, zpass)| JsonRow {
                method: &r.method,
                backend: backend.name(),
                counter,
                zpass: zpass.clone(),
                receivers: view.receivers.name(),
                samples: r.metrics.samples,
                shadowed_reference: r.metrics.shadowed_reference,
                mismatches: r.metrics.mismatches,
                band_samples: r.metrics.band_samples,
                band_mismatches: r.metrics.band_mismatches,
                mismatches_outside_band: r.metrics.mismatches_outside_band,
                reference_ms: *reference_ms,
                render_ms: r.render_ms,
                per_light: r
                    .per_light
                    .iter()
                    .map(|l| JsonLight {
                        light: view.lights[l.light],
                        samples: l.metrics.samples,
                        shadowed_reference: l.metrics.shadowed_reference,
                        mismatches: l.metrics.mismatches,
                        band_samples: l.metrics.band_samples,
                        band_mismatches: l.metrics.band_mismatches,
                        mismatches_outside_band: l.metrics.mismatches_outside_band,
                    })
                    .collect(),
            })
            .map(JsonOut::Row)
            .collect();
        json.extend(failed.iter().map(|f| JsonOut::Failed {
            method: &f.method,
            backend: backend.name(),
            error: &f.error,
        }));
        println!("{}", serde_json::to_string_pretty(&json).map_err(|e| CliError::Other(e.to_string()))?);
    } else {
        println!(
            "{} at {}x{}, {} light(s), receivers {}, {}; reference {:.0} ms",
            view.scene_spec,
            view.width,
            view.height,
            view.lights.len(),
            view.receivers.name(),
            device_name,
            reference.total_ms()
        );
        println!(
            "{:<24} {:>9} {:>9} {:>10} {:>9} {:>9} {:>13} {:>10}  verdict",
            "method", "samples", "shadowed", "mismatch", "band", "band mis", "outside band", "render ms"
        );
        for (r, _, _, _) in &rows {
            let m = &r.metrics;
            let verdict = match (r.must_be_exact, r.passed()) {
                (false, _) => "measured",
                (true, true) => "EXACT",
                (true, false) => "FAIL",
            };
            println!(
                "{:<24} {:>9} {:>9} {:>10} {:>9} {:>9} {:>13} {:>10.1}  {}",
                r.method,
                m.samples,
                m.shadowed_reference,
                m.mismatches,
                m.band_samples,
                m.band_mismatches,
                m.mismatches_outside_band,
                r.render_ms,
                verdict
            );
        }
        for f in &failed {
            println!("{:<24} ERROR: {}", f.method, f.error);
        }
    }
    if !failed.is_empty() {
        let names: Vec<&str> = failed.iter().map(|f| f.method.as_str()).collect();
        return Err(CliError::Other(format!(
            "{} of {} methods could not be verified here: {} (their errors above)",
            failed.len(),
            methods.len(),
            names.join(", ")
        )));
    }
    Ok(all_passed)
}
