//! Raw command-line flags, exactly as users type them. They are turned into a checked
//! [`crate::config`] in one place; nothing else reads them. Flag names are contracts
//! (users' scripts depend on them): extend, never rename.

use clap::{Args, Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "umbra", version, about = "Exact per-sample stencil shadow volumes for any triangle soup", long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene with shadows to a PNG.
    Render(RenderArgs),
    /// Print mesh statistics: triangles, welded vertices, edges, open and non-manifold edges, silhouette.
    Info(InfoArgs),
    /// Compare shadow methods against the CPU ray-traced reference, sample by sample.
    Verify(VerifyArgs),
}

/// Scene, camera and light flags shared by `render` and `verify`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene: `default`, `box`, `spheres:N`, `spheres:N:T`, or a mesh file (.obj .ply .stl .gltf .glb, optionally .gz).
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Light as X,Y,Z (point light, w = 1) or X,Y,Z,W (W = 0: directional, light coming from X,Y,Z).
    /// Repeat for several lights. Default: derived from the scene's bounds.
    #[arg(long, allow_hyphen_values = true)]
    pub light: Vec<String>,
    /// Camera position X,Y,Z. Default: derived from the scene's bounds.
    #[arg(long, allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// Point the camera looks at, X,Y,Z. Default: the centre of the scene.
    #[arg(long, allow_hyphen_values = true)]
    pub target: Option<String>,
    /// Camera up vector X,Y,Z.
    #[arg(long, allow_hyphen_values = true, default_value = "0,1,0")]
    pub up: String,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f64,
    /// Image size WxH.
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// Add a horizontal receiving plane at the scene's lowest Y, ten times its horizontal extent.
    #[arg(long)]
    pub ground: bool,
    /// Use z-pass stencil counting instead of z-fail (wrong when the camera is inside a shadow).
    #[arg(long)]
    pub zpass: bool,
    /// Largest accepted input file in bytes, after decompression.
    #[arg(long)]
    pub max_input_bytes: Option<u64>,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub view: ViewArgs,
    /// Shadow method (see `umbra render --method help`). Default: the best one available.
    #[arg(long)]
    pub method: Option<String>,
    /// Output PNG file.
    #[arg(long, default_value = "umbra.png")]
    pub out: String,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Scene spec or mesh file, as for `render --scene`.
    pub scene: String,
    /// Also count silhouette edges for this light (X,Y,Z or X,Y,Z,W).
    #[arg(long, allow_hyphen_values = true)]
    pub light: Option<String>,
    /// Add the receiving ground plane, as `render --ground`.
    #[arg(long)]
    pub ground: bool,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Largest accepted input file in bytes, after decompression.
    #[arg(long)]
    pub max_input_bytes: Option<u64>,
}

#[derive(Args, Debug)]
pub struct VerifyArgs {
    #[command(flatten)]
    pub view: ViewArgs,
    /// Methods to verify: NAME[,NAME...] or `all`.
    #[arg(long, default_value = "all")]
    pub method: String,
    /// Print a JSON array, one object per method.
    #[arg(long)]
    pub json: bool,
    /// Write a diff image: false shadow red, false light blue, boundary band grey.
    /// With several methods, the method name is inserted before the extension.
    #[arg(long)]
    pub diff: Option<String>,
}
