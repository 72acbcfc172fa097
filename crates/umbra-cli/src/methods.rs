//! Shadow methods by name, as `render`, `verify` and `bench` take them: the registry's names
//! (`umbra_gl::method_names`, parameterised ones like `shadow-map-cube:RES` included), and the
//! shadow-map options (`--sm-bias`, `--sm-pcf`, `--sm-faces`) checked once into [`SmOptions`].

use umbra_gl::methods::shadow_map::{FacePasses, ShadowMapConfig, ShadowMapCube};
use umbra_gl::{create_method, method_names, ShadowMethod};

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
