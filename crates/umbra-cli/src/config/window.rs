//! [`WindowConfig`]: the flags of `umbra view`, checked.

use std::path::PathBuf;

use super::checked::{Checked, Listing};
use super::parse::{asks_for_list, gl_methods, parse_counter};
use super::view::ViewConfig;
use crate::args::ViewWindowArgs;
use crate::backend::Backend;
use crate::error::CliError;
use crate::methods::{CounterChoice, DEFAULT_METHOD};

/// `umbra view`: the interactive window on the view `render` would draw.
pub struct WindowConfig {
    /// The initial method (a GL method name).
    pub method: String,
    pub counter: CounterChoice,
    /// The view, with the positional SCENE in place of `--scene` when given.
    pub view: ViewConfig,
    pub script: Option<PathBuf>,
    pub screenshot: Option<PathBuf>,
    /// Start in the shadow-mask view.
    pub mask: bool,
}

impl WindowConfig {
    pub fn from_args(a: &ViewWindowArgs) -> Result<Checked<Self>, CliError> {
        let method = a.method.as_deref().unwrap_or(DEFAULT_METHOD);
        if asks_for_list(method) {
            return Ok(Checked::List(Listing::Methods(Backend::Gl)));
        }
        gl_methods(method, "--method")?;
        let counter = parse_counter(&a.counter, "--counter")?;
        let mut flags = a.view.clone();
        if let Some(scene) = &a.scene_arg {
            flags.scene = scene.clone();
        }
        let view = ViewConfig::from_args(&flags)?;
        Ok(Checked::Run(Self {
            method: method.to_string(),
            counter,
            view,
            script: a.script.as_ref().map(PathBuf::from),
            screenshot: a.screenshot.as_ref().map(PathBuf::from),
            mask: a.mask,
        }))
    }
}
