//! Shadow methods by name, as `render`, `verify` and `bench` take them: the registry's names
//! (`umbra_gl::method_names`, parameterised ones like `shadow-map-cube:RES` included), the
//! shadow-map options (`--sm-bias`, `--sm-pcf`, `--sm-faces`) checked once into [`SmOptions`],
//! and the shadow-volume counter (`--counter stencil8|float32|auto`, [`CounterChoice`]):
//! `auto` takes float32 exactly when [`umbra_geom::winding_bound`] cannot prove every count
//! below 256 for some light (so it never gives a silently wrapped image).

use std::time::Instant;
use umbra_gl::methods::shadow_map::{FacePasses, ShadowMapConfig, ShadowMapCube};

use umbra_geom::winding_bound::{winding_bound, BoundOptions, STENCIL8_LIMIT};
use umbra_geom::Light;
use umbra_gl::counter::Counter;
use umbra_gl::{create_method, method_names, Classification, ShadowMethod};

use crate::args::SmArgs;
use crate::config::CliError;

fn bad(flag: &'static str, message: impl Into<String>) -> CliError {
    CliError::BadFlag { flag, message: message.into() }
}

/// Options of the shadow-map methods (`--sm-bias`, `--sm-pcf`, `--sm-faces`); `None` keeps the
/// method's default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmOptions {
    pub bias_constant: Option<f32>,
    pub bias_slope: Option<f32>,
    pub pcf: bool,
    pub faces: FacePasses,
}

impl Default for SmOptions {
    fn default() -> Self {
        Self { bias_constant: None, bias_slope: None, pcf: false, faces: FacePasses::Layered }
    }
}

impl SmOptions {
    pub fn from_args(a: &SmArgs) -> Result<Self, CliError> {
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
        Ok(Self { bias_constant, bias_slope, pcf: a.sm_pcf, faces })
    }
}

/// Builds a method by name (`flag` names the flag it came from, for the error); shadow-map
/// names get the `--sm-*` options.
pub fn make_method(name: &str, sm: &SmOptions, flag: &'static str) -> Result<Box<dyn ShadowMethod>, CliError> {
    if let Some(mut c) = ShadowMapConfig::from_name(name) {
        if let Some(b) = sm.bias_constant {
            c.bias_constant = b;
        }
        if let Some(s) = sm.bias_slope {
            c.bias_slope = s;
        }
        c.pcf = sm.pcf;
        c.faces = sm.faces;
        return Ok(Box::new(ShadowMapCube::new(c)));
    }
    create_method(name).map_err(|e| bad(flag, e.to_string()))
}

/// True if the registry can build `name` (listed or parameterised).
pub fn method_exists(name: &str) -> bool {
    create_method(name).is_ok()
}

/// `all` (every registered method), or a comma-separated list of names, each checked.
pub fn parse_methods(text: &str, flag: &'static str) -> Result<Vec<String>, CliError> {
    if text.trim() == "all" {
        return Ok(method_names().iter().map(|s| s.to_string()).collect());
    }
    let names: Vec<String> = text.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
    if names.is_empty() {
        return Err(bad(flag, "no method named"));
    }
    for n in &names {
        create_method(n).map_err(|e| bad(flag, e.to_string()))?;
    }
    Ok(names)
}

/// `--method help` (or `list`): prints every registered method, one per line, and returns
/// true; any other name returns false.
pub fn list_if_help(name: &str) -> bool {
    if name == "help" || name == "list" {
        for n in method_names() {
            println!("{n}");
        }
        return true;
    }
    false
}

/// [`list_if_help`] for `backend`: the wgpu backend lists its own methods.
pub fn list_if_help_for(backend: crate::wgpu_backend::Backend, name: &str) -> bool {
    if backend == crate::wgpu_backend::Backend::Wgpu && (name == "help" || name == "list") {
        for n in umbra_wgpu::method_names() {
            println!("{n}");
        }
        return true;
    }
    list_if_help(name)
}

/// `--counter`: a fixed counter, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CounterChoice {
    Fixed(Counter),
    Auto,
}

impl CounterChoice {
    pub fn parse(text: &str, flag: &'static str) -> Result<Self, CliError> {
        match text.trim() {
            "stencil8" => Ok(CounterChoice::Fixed(Counter::Stencil8)),
            "float32" => Ok(CounterChoice::Fixed(Counter::Float32)),
            "auto" => Ok(CounterChoice::Auto),
            other => Err(bad(flag, format!("expected stencil8, float32 or auto, got {other:?}"))),
        }
    }
}

/// The counter a frame uses, and for `auto` why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CounterDecision {
    pub counter: Counter,
    /// `auto`: the largest winding bound over the lights (see [`umbra_geom::winding_bound`]).
    pub bound: Option<u64>,
    /// `auto`: time to compute the bounds (ms).
    pub bound_ms: f64,
}

/// Resolves `choice` for a mesh (the triangles the GPU draws) and its lights: `auto` is
/// float32 when the bound of any light reaches 256, stencil8 otherwise (provably exact).
pub fn choose_counter(
    choice: CounterChoice,
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    lights: &[Light],
) -> Result<CounterDecision, CliError> {
    match choice {
        CounterChoice::Fixed(counter) => Ok(CounterDecision { counter, bound: None, bound_ms: 0.0 }),
        CounterChoice::Auto => {
            let start = Instant::now();
            let mut worst = 0;
            for &light in lights {
                let b = winding_bound(positions, triangles, light, &BoundOptions::default())
                    .map_err(|e| CliError::Other(format!("counter bound: {e}")))?;
                worst = worst.max(b.bound);
            }
            let bound_ms = start.elapsed().as_secs_f64() * 1e3;
            let counter = if worst >= STENCIL8_LIMIT { Counter::Float32 } else { Counter::Stencil8 };
            Ok(CounterDecision { counter, bound: Some(worst), bound_ms })
        }
    }
}

/// What `verify --json` / `bench --json` print as "counter" for `method`: the counter's name
/// for methods that count in the stencil ([`Classification::StencilZero`]), "none" for the
/// others (their own stencil scheme, or no stencil: the counter does not apply).
pub fn counter_label(method: &dyn ShadowMethod, counter: Counter) -> &'static str {
    match method.classification() {
        Classification::StencilZero => counter.name(),
        _ => "none",
    }
}

/// One line on stderr saying what `auto` decided (nothing for a fixed counter).
pub fn report_counter(d: &CounterDecision) {
    if let Some(bound) = d.bound {
        let cmp = if bound >= STENCIL8_LIMIT { ">=" } else { "<" };
        eprintln!(
            "umbra: counter {} (auto: winding bound {bound} {cmp} {STENCIL8_LIMIT}, {:.1} ms)",
            d.counter.name(),
            d.bound_ms
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counter_flag_values() {
        assert_eq!(CounterChoice::parse("stencil8", "--counter").unwrap(), CounterChoice::Fixed(Counter::Stencil8));
        assert_eq!(CounterChoice::parse("float32", "--counter").unwrap(), CounterChoice::Fixed(Counter::Float32));
        assert_eq!(CounterChoice::parse("auto", "--counter").unwrap(), CounterChoice::Auto);
        assert!(CounterChoice::parse("stencil16", "--counter").is_err());
    }

    #[test]
    fn auto_counter_follows_the_bound() {
        // n separate horizontal quads stacked over each other, light above.
        let quads = |n: u32| {
            let (mut p, mut t) = (Vec::new(), Vec::new());
            for k in 0..n {
                let (y, b) = (k as f32 * 0.01, p.len() as u32);
                p.extend([[0.0, y, 0.0], [1.0, y, 0.0], [1.0, y, 1.0], [0.0, y, 1.0]]);
                t.extend([[b, b + 2, b + 1], [b, b + 3, b + 2]]);
            }
            (p, t)
        };
        let light = [[0.5f32, 100.0, 0.5, 1.0]];
        let (p, t) = quads(50);
        let d = choose_counter(CounterChoice::Auto, &p, &t, &light).unwrap();
        assert_eq!(d.counter, Counter::Stencil8, "{d:?}");
        let (p, t) = quads(300);
        let d = choose_counter(CounterChoice::Auto, &p, &t, &light).unwrap();
        assert_eq!(d.counter, Counter::Float32, "{d:?}");
        assert!(d.bound.unwrap() >= 300);
        let d = choose_counter(CounterChoice::Fixed(Counter::Stencil8), &p, &t, &light).unwrap();
        assert_eq!((d.counter, d.bound), (Counter::Stencil8, None));
    }
}
