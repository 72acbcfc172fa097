//! Shadow methods by name, as `render`, `verify` and `bench` take them: the registry's names
//! (`umbra_gl::method_names`, parameterised ones like `shadow-map-cube:RES` included), the
//! shadow-map options (`--sm-bias`, `--sm-pcf`, `--sm-faces`) as [`SmOptions`],
//! and the shadow-volume counter (`--counter stencil8|float32|auto`, [`CounterChoice`]):
//! `auto` takes float32 exactly when [`umbra_geom::winding_bound`] cannot prove every count
//! below 256 for some light (so it never gives a silently wrapped image).

use std::time::Instant;
use umbra_gl::methods::shadow_map::{FacePasses, ShadowMapConfig, ShadowMapCube};

use umbra_geom::winding_bound::{winding_bound, BoundOptions, STENCIL8_LIMIT};
use umbra_geom::Light;
use umbra_gl::counter::Counter;
use umbra_gl::{create_method, method_names, Classification, ShadowMethod};

use crate::backend::Backend;
use crate::error::{bad, CliError};

/// The method `render` and `view` use when none is named: the best one available.
pub const DEFAULT_METHOD: &str = "cpu-silhouette";

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

/// `--method help` (or `list`): every method of `backend`, one per line on stdout.
pub fn list_methods(backend: Backend) {
    let names = match backend {
        Backend::Gl => method_names(),
        Backend::Wgpu => umbra_wgpu::method_names(),
    };
    for n in names {
        println!("{n}");
    }
}

/// `--counter`: a fixed counter, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CounterChoice {
    Fixed(Counter),
    Auto,
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
