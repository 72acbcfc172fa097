//! The one error type of the `umbra` binary.

use umbra_geom::scene;

/// Every error the CLI reports. Displayed as `umbra: error: …` with a non-zero exit status.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error("{flag}: {message}")]
    BadFlag { flag: &'static str, message: String },
    #[error("{0}")]
    Scene(#[from] scene::SceneError),
    #[error("{0}")]
    Load(#[from] umbra_geom::load::LoadError),
    #[error("{0}")]
    Gl(String),
    #[error("{path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{0}")]
    Other(String),
}

/// A [`CliError::BadFlag`] for `flag`.
pub fn bad(flag: &'static str, message: impl Into<String>) -> CliError {
    CliError::BadFlag { flag, message: message.into() }
}
