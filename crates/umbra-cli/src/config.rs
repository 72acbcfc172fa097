//! Raw flags → checked configuration, in one place: one `XxxConfig::from_args` per command
//! turns its [`crate::args`] into values the command can trust. Every number is parsed and
//! range-checked here, defaults are derived from the scene's bounds here, and a command
//! module receives only its configuration.
//!
//! | command | flags | configuration |
//! | --- | --- | --- |
//! | `render` | [`crate::args::RenderArgs`] | [`RenderConfig`] |
//! | `verify` | [`crate::args::VerifyArgs`] | [`VerifyConfig`] |
//! | `bench` | [`crate::args::BenchArgs`] | [`BenchConfig`] |
//! | `info` | [`crate::args::InfoArgs`] | [`InfoConfig`] |
//! | `view` | [`crate::args::ViewWindowArgs`] | [`WindowConfig`] |
//! | `export` | [`crate::args::ExportArgs`] | [`ExportConfig`] |
//!
//! The view flags `render`, `verify`, `view` and `export` share become one [`ViewConfig`];
//! the parsers of single flag values are in `config/parse.rs`.

mod bench;
mod checked;
mod export;
mod info;
mod parse;
mod render;
mod verify;
mod view;
mod window;

pub use bench::{split_cull_off, BenchConfig, BenchMode};
pub use checked::{Checked, Listing};
pub use export::ExportConfig;
pub use info::InfoConfig;
pub use render::RenderConfig;
pub use verify::VerifyConfig;
pub use view::ViewConfig;
pub use window::WindowConfig;
