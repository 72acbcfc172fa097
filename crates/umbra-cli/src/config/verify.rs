//! [`VerifyConfig`]: the flags of `umbra verify`, checked.

use super::checked::{Checked, Listing};
use super::parse::{asks_for_list, methods_for, parse_backend, parse_counter, parse_sm};
use super::view::{check_ortho, check_receivers, ViewConfig};
use crate::args::VerifyArgs;
use crate::backend::Backend;
use crate::error::{bad, CliError};
use crate::methods::{CounterChoice, SmOptions};

/// `umbra verify`: methods against the ray-traced reference on one view.
pub struct VerifyConfig {
    pub backend: Backend,
    /// Methods the backend knows, in the order given.
    pub methods: Vec<String>,
    pub sm: SmOptions,
    pub view: ViewConfig,
    /// `--subpixel-bits`: 4 to 16, GL backend only.
    pub subpixel_bits: Option<u32>,
    pub counter: CounterChoice,
    pub json: bool,
    /// `--diff`: the diff image's path (a method's and a light's name inserted when several).
    pub diff: Option<String>,
    /// `--explain`: mismatches explained per method and light.
    pub explain: usize,
    /// `--external-mask`: a PNG judged as one more row.
    pub external_mask: Option<String>,
}

impl VerifyConfig {
    pub fn from_args(a: &VerifyArgs) -> Result<Checked<Self>, CliError> {
        let backend = parse_backend(&a.backend)?;
        if asks_for_list(a.method.trim()) {
            return Ok(Checked::List(Listing::Methods(backend)));
        }
        let methods = methods_for(backend, &a.method, "--method")?;
        let sm = parse_sm(&a.sm)?;
        let view = ViewConfig::from_args(&a.view)?;
        check_receivers(backend, &view)?;
        check_ortho(backend, &view)?;
        // GL 4.5 requires at least 4 bits (its state tables); 16 is beyond any rasterizer's grid.
        if let Some(bits) = a.subpixel_bits {
            if !(4..=16).contains(&bits) {
                return Err(bad("--subpixel-bits", format!("{bits}: expected 4 to 16 (GL_SUBPIXEL_BITS)")));
            }
            if backend == Backend::Wgpu {
                return Err(bad("--subpixel-bits", "applies to --backend gl (external masks)"));
            }
        }
        let counter = parse_counter(&a.counter, "--counter")?;
        Ok(Checked::Run(Self {
            backend,
            methods,
            sm,
            view,
            subpixel_bits: a.subpixel_bits,
            counter,
            json: a.json,
            diff: a.diff.clone(),
            explain: a.explain,
            external_mask: a.external_mask.clone(),
        }))
    }
}
