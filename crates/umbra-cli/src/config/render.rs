//! [`RenderConfig`]: the flags of `umbra render`, checked.

use super::checked::{Checked, Listing};
use super::parse::{asks_for_list, gl_method, parse_backend, parse_counter, parse_sm, wgpu_methods};
use super::view::{check_ortho, check_receivers, ViewConfig};
use crate::args::RenderArgs;
use crate::backend::Backend;
use crate::error::CliError;
use crate::methods::{CounterChoice, SmOptions, DEFAULT_METHOD};

/// `umbra render`: one method's frame of a view, to a PNG.
pub struct RenderConfig {
    pub backend: Backend,
    /// A method the backend knows.
    pub method: String,
    pub sm: SmOptions,
    pub view: ViewConfig,
    pub counter: CounterChoice,
    /// The PNG to write.
    pub out: String,
}

impl RenderConfig {
    pub fn from_args(a: &RenderArgs) -> Result<Checked<Self>, CliError> {
        let backend = parse_backend(&a.backend)?;
        let method = a.method.as_deref().unwrap_or(DEFAULT_METHOD);
        if asks_for_list(method) {
            return Ok(Checked::List(Listing::Methods(backend)));
        }
        let sm = parse_sm(&a.sm)?;
        match backend {
            Backend::Gl => {
                gl_method(method, "--method")?;
            }
            Backend::Wgpu => {
                wgpu_methods(method, "--method")?;
            }
        }
        let view = ViewConfig::from_args(&a.view)?;
        check_receivers(backend, &view)?;
        check_ortho(backend, &view)?;
        let counter = parse_counter(&a.counter, "--counter")?;
        Ok(Checked::Run(Self { backend, method: method.to_string(), sm, view, counter, out: a.out.clone() }))
    }
}
