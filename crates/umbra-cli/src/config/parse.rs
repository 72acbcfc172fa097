//! Flag values to typed values: the parsers the per-command configurations call. Each
//! error names its flag (`--size: expected WxH ...`).

use umbra_geom::{Light, Receivers};
use umbra_gl::counter::Counter;
use umbra_gl::methods::shadow_map::FacePasses;
use umbra_gl::{create_method, method_names};
use umbra_wgpu::methods::shadow_map::ShadowMapConfig as WgpuShadowMapConfig;

use crate::args::SmArgs;
use crate::backend::Backend;
use crate::error::{bad, CliError};
use crate::methods::{CounterChoice, SmOptions};

/// Parses `N` comma-separated finite numbers.
fn parse_numbers(flag: &'static str, text: &str, counts: &[usize]) -> Result<Vec<f64>, CliError> {
    let values: Vec<f64> = text
        .split(',')
        .map(|s| {
            let v: f64 = s.trim().parse().map_err(|_| bad(flag, format!("{s:?} in {text:?} is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(bad(flag, format!("{s:?} in {text:?} is not finite")))
            }
        })
        .collect::<Result<_, _>>()?;
    if !counts.contains(&values.len()) {
        let want = counts.iter().map(|c| c.to_string()).collect::<Vec<_>>().join(" or ");
        return Err(bad(flag, format!("expected {want} comma-separated numbers, got {text:?}")));
    }
    Ok(values)
}

pub fn parse_vec3(flag: &'static str, text: &str) -> Result<[f64; 3], CliError> {
    let v = parse_numbers(flag, text, &[3])?;
    Ok([v[0], v[1], v[2]])
}

/// `X,Y,Z` (point light, w = 1) or `X,Y,Z,W`. A point light with `W != 0` is normalised to
/// `w = 1`; `W = 0` is a directional light coming from `(X, Y, Z)`, which must not be zero.
pub fn parse_light(text: &str) -> Result<Light, CliError> {
    let v = parse_numbers("--light", text, &[3, 4])?;
    let w = if v.len() == 4 { v[3] } else { 1.0 };
    if w == 0.0 {
        if v[..3].iter().all(|&c| c == 0.0) {
            return Err(bad("--light", "a directional light (w = 0) needs a non-zero direction"));
        }
        return Ok([v[0] as f32, v[1] as f32, v[2] as f32, 0.0]);
    }
    Ok([(v[0] / w) as f32, (v[1] / w) as f32, (v[2] / w) as f32, 1.0])
}

/// `WxH`, each side 1 to 16384.
pub fn parse_size(text: &str) -> Result<(u32, u32), CliError> {
    let err = || bad("--size", format!("expected WxH with 1 <= W, H <= 16384, got {text:?}"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(err)?;
    let w: u32 = w.trim().parse().map_err(|_| err())?;
    let h: u32 = h.trim().parse().map_err(|_| err())?;
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(err());
    }
    Ok((w, h))
}

/// `--fov`: strictly between 0 and 180 degrees.
pub fn check_fov(fov: f64) -> Result<f64, CliError> {
    if !(fov > 0.0 && fov < 180.0) {
        return Err(bad("--fov", format!("must be in (0, 180) degrees, got {fov}")));
    }
    Ok(fov)
}

/// `--ortho HEIGHT`: a finite number > 0 (the view's world-space height).
pub fn parse_ortho(text: &str) -> Result<f64, CliError> {
    let err =
        || bad("--ortho", format!("expected the view's height in world units, a finite number > 0, got {text:?}"));
    let h: f64 = text.trim().parse().map_err(|_| err())?;
    if !(h.is_finite() && h > 0.0) {
        return Err(err());
    }
    Ok(h)
}

/// `--ortho-far DISTANCE`: a finite number (the far plane's view distance; whether it lies
/// beyond the near plane is checked with the camera).
pub fn parse_ortho_far(text: &str) -> Result<f64, CliError> {
    let err = || bad("--ortho-far", format!("expected the far plane's view distance, a finite number, got {text:?}"));
    let far: f64 = text.trim().parse().map_err(|_| err())?;
    if !far.is_finite() {
        return Err(err());
    }
    Ok(far)
}

/// `--zmode` (with `--zpass`, which is `--zmode zpass`) as (force z-pass, auto z-pass).
pub fn parse_zmode(zmode: &str, zpass: bool) -> Result<(bool, bool), CliError> {
    match (zmode.trim(), zpass) {
        ("auto", false) => Ok((false, true)),
        ("zfail", false) => Ok((false, false)),
        ("zpass", _) | ("auto", true) => Ok((true, false)),
        ("zfail", true) => Err(bad("--zmode", "zfail contradicts --zpass")),
        (other, _) => Err(bad("--zmode", format!("expected zfail, zpass or auto, got {other:?}"))),
    }
}

/// `--volume-cull`: `on` or `off`.
pub fn parse_volume_cull(text: &str) -> Result<bool, CliError> {
    match text.trim() {
        "on" => Ok(true),
        "off" => Ok(false),
        other => Err(bad("--volume-cull", format!("expected on or off, got {other:?}"))),
    }
}

/// `--receivers`: `both` (a pixel shows the nearest triangle, either face) or `front` (the
/// nearest one facing the eye, as three.js draws a `FrontSide` material).
pub fn parse_receivers(text: &str) -> Result<Receivers, CliError> {
    match text.trim() {
        "both" => Ok(Receivers::Both),
        "front" => Ok(Receivers::Front),
        other => Err(bad("--receivers", format!("expected front or both, got {other:?}"))),
    }
}

/// `--backend`: `gl` or `wgpu`.
pub fn parse_backend(text: &str) -> Result<Backend, CliError> {
    match text.trim() {
        "gl" => Ok(Backend::Gl),
        "wgpu" => Ok(Backend::Wgpu),
        other => Err(bad("--backend", format!("expected gl or wgpu, got {other:?}"))),
    }
}

/// `--counter`: a fixed counter, or `auto`.
pub fn parse_counter(text: &str, flag: &'static str) -> Result<CounterChoice, CliError> {
    match text.trim() {
        "stencil8" => Ok(CounterChoice::Fixed(Counter::Stencil8)),
        "float32" => Ok(CounterChoice::Fixed(Counter::Float32)),
        "auto" => Ok(CounterChoice::Auto),
        other => Err(bad(flag, format!("expected stencil8, float32 or auto, got {other:?}"))),
    }
}

/// `--sm-bias`, `--sm-pcf`, `--sm-faces`.
pub fn parse_sm(a: &SmArgs) -> Result<SmOptions, CliError> {
    let (mut bias_constant, mut bias_slope) = (None, None);
    if let Some(text) = &a.sm_bias {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if parts.is_empty() || parts.len() > 2 {
            return Err(bad("--sm-bias", format!("expected C or C,S, got {text:?}")));
        }
        let num = |s: &str| -> Result<f32, CliError> {
            s.parse::<f32>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| bad("--sm-bias", format!("{s:?} in {text:?} is not a finite number >= 0")))
        };
        bias_constant = Some(num(parts[0])?);
        if let Some(s) = parts.get(1) {
            bias_slope = Some(num(s)?);
        }
    }
    let faces = match a.sm_faces.as_str() {
        "layered" => FacePasses::Layered,
        "six" => FacePasses::SixPasses,
        other => return Err(bad("--sm-faces", format!("expected layered or six, got {other:?}"))),
    };
    Ok(SmOptions { bias_constant, bias_slope, pcf: a.sm_pcf, faces })
}

/// `--method help` or `--method list`: print the method names instead of running.
pub fn asks_for_list(name: &str) -> bool {
    name == "help" || name == "list"
}

/// One GL method name, as [`crate::methods::make_method`] accepts it (any
/// `shadow-map-cube:RES[+pcf]`, or a registered name).
pub fn gl_method(name: &str, flag: &'static str) -> Result<String, CliError> {
    if umbra_gl::methods::shadow_map::ShadowMapConfig::from_name(name).is_none() {
        create_method(name).map_err(|e| bad(flag, e.to_string()))?;
    }
    Ok(name.to_string())
}

/// The names of a comma-separated list, trimmed, empty entries dropped; at least one.
fn method_list(text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
    if names.is_empty() {
        return Err(bad(flag, "no method named"));
    }
    Ok(names)
}

/// `all` (every registered GL method), or a comma-separated list of names, each checked.
pub fn gl_methods(text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    if text.trim() == "all" {
        return Ok(method_names().iter().map(|s| s.to_string()).collect());
    }
    let names = method_list(text, flag)?;
    for n in &names {
        create_method(n).map_err(|e| bad(flag, e.to_string()))?;
    }
    Ok(names)
}

/// `all` (every wgpu method), or a comma-separated list of names, each checked against the
/// wgpu registry (any `shadow-map-cube:RES[+pcf]`).
pub fn wgpu_methods(text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    if text.trim() == "all" {
        return Ok(umbra_wgpu::method_names().iter().map(|s| s.to_string()).collect());
    }
    let names = method_list(text, flag)?;
    for n in &names {
        if !umbra_wgpu::method_names().contains(&n.as_str()) && WgpuShadowMapConfig::from_name(n).is_none() {
            let gl_only = create_method(n).is_ok();
            return Err(bad(
                flag,
                format!(
                    "unknown shadow method {n:?} on the wgpu backend{}; known: {}",
                    if gl_only { " (it needs geometry or tessellation shaders: --backend gl)" } else { "" },
                    umbra_wgpu::method_names().join(", ")
                ),
            ));
        }
    }
    Ok(names)
}

/// The method list of `backend` ([`gl_methods`] or [`wgpu_methods`]).
pub fn methods_for(backend: Backend, text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    match backend {
        Backend::Gl => gl_methods(text, flag),
        Backend::Wgpu => wgpu_methods(text, flag),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_three_numbers_is_point() {
        assert_eq!(parse_light("1,2,3").unwrap(), [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(parse_light("2,4,6,2").unwrap(), [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(parse_light("0,-1,0,0").unwrap(), [0.0, -1.0, 0.0, 0.0]);
        assert!(parse_light("0,0,0,0").is_err());
        assert!(parse_light("1,2").is_err());
        assert!(parse_light("1,nan,2").is_err());
    }

    #[test]
    fn size_is_checked() {
        assert_eq!(parse_size("1280x720").unwrap(), (1280, 720));
        assert!(parse_size("0x720").is_err());
        assert!(parse_size("1280").is_err());
        assert!(parse_size("99999x1").is_err());
    }

    #[test]
    fn receivers_flag_values() {
        assert_eq!(parse_receivers("both").unwrap(), Receivers::Both);
        assert_eq!(parse_receivers(" front ").unwrap(), Receivers::Front);
        let e = parse_receivers("back").unwrap_err().to_string();
        assert!(e.contains("--receivers") && e.contains("expected front or both"), "{e}");
    }

    #[test]
    fn counter_flag_values() {
        assert_eq!(parse_counter("stencil8", "--counter").unwrap(), CounterChoice::Fixed(Counter::Stencil8));
        assert_eq!(parse_counter("float32", "--counter").unwrap(), CounterChoice::Fixed(Counter::Float32));
        assert_eq!(parse_counter("auto", "--counter").unwrap(), CounterChoice::Auto);
        assert!(parse_counter("stencil16", "--counter").is_err());
    }
}
