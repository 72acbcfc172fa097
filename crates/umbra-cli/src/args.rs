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
    /// Time shadow methods along a camera path (frame and per-stage times), or run a paper's benchmark suite.
    Bench(BenchArgs),
    /// Open a window on a scene: orbit/fly camera, movable lights, method switching, shadow-mask view.
    View(ViewWindowArgs),
    /// Write paper 003's preprocessed scene (mesh, sides-data, caps-data, manifest.json) for the WebGL2 viewer.
    Export(ExportArgs),
}

/// Scene, camera and light flags shared by `render` and `verify`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Scene: `default`, `box`, `spheres:N`, `spheres:N:T`, or a mesh file (.obj .ply .stl .gltf .glb, optionally .gz).
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Light as X,Y,Z (point light, w = 1) or X,Y,Z,W (W = 0: directional, light coming from X,Y,Z),
    /// or `default`. Repeat for several lights. Default (and `default`): derived from the scene's bounds.
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
    /// An orthographic camera instead of the perspective one: the view's world-space height
    /// (> 0; the width follows the image's aspect). Eye, target and up as for the perspective
    /// camera; the eye is at infinity behind it, its near plane stays. cpu-silhouette, none
    /// and the shadow maps draw it (GL backend).
    #[arg(long, allow_hyphen_values = true)]
    pub ortho: Option<String>,
    /// With `--ortho`: the view distance of the far plane (finite, beyond the near plane)
    /// instead of the one fitted just beyond the scene's box. For judging a mask drawn with
    /// that far plane (`--external-mask`: umbra-three's `info.ortho.far`), whose depth steps
    /// follow it.
    #[arg(long, allow_hyphen_values = true)]
    pub ortho_far: Option<String>,
    /// Image size WxH.
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// Add a horizontal receiving plane at the scene's lowest Y, ten times its horizontal extent.
    #[arg(long)]
    pub ground: bool,
    /// Use z-pass stencil counting instead of z-fail (wrong when the camera is inside a shadow).
    #[arg(long)]
    pub zpass: bool,
    /// How shadow volumes count: `zfail` (always: Carmack's reverse, caps at infinity),
    /// `zpass` (always: wrong when the camera is inside a shadow volume) or `auto` (z-pass for
    /// each light whose volumes provably leave the eye out, z-fail for the others; exact, and
    /// faster: no caps, volumes clipped to the scene). `--zpass` is `--zmode zpass`.
    #[arg(long, default_value = "auto")]
    pub zmode: String,
    /// Cull and clamp the shadow volumes against each light's visible receivers: `on` (the
    /// default; cpu-silhouette on the GL backend: the same decision at every sample, less fill)
    /// or `off` (the unclamped volumes, to measure the difference). Other methods and the wgpu
    /// backend draw their volumes as they are either way.
    #[arg(long, default_value = "on")]
    pub volume_cull: String,
    /// Which faces a pixel can show: `both` (the nearest triangle, either face: triangle soups
    /// are two-sided) or `front` (the nearest triangle facing the eye, counter-clockwise on the
    /// screen: back faces culled in the depth pass, as three.js draws a `FrontSide` material).
    /// The reference judges the samples that depth pass drew. Casters cast from both faces
    /// either way. `front` is GL backend only.
    #[arg(long, default_value = "both")]
    pub receivers: String,
    /// Largest accepted input file in bytes, after decompression.
    #[arg(long)]
    pub max_input_bytes: Option<u64>,
}

/// Options of the shadow-map methods, shared by `render`, `verify` and `bench`.
#[derive(Args, Debug, Clone, Default)]
pub struct SmArgs {
    /// Shadow-map bias: constant C [, slope-scaled S] (glPolygonOffset units, factor).
    #[arg(long, allow_hyphen_values = true)]
    pub sm_bias: Option<String>,
    /// Shadow maps: 3x3 percentage-closer filtering (majority vote).
    #[arg(long)]
    pub sm_pcf: bool,
    /// Shadow maps: cube faces rendered in one layered pass (`layered`) or six passes (`six`).
    #[arg(long, default_value = "layered")]
    pub sm_faces: String,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub view: ViewArgs,
    #[command(flatten)]
    pub sm: SmArgs,
    /// Shadow method (see `umbra render --method help`). Default: the best one available.
    #[arg(long)]
    pub method: Option<String>,
    /// Shadow-volume counter: `stencil8` (the 8-bit stencil; wraps when 256 or more
    /// triangles lie between a sample and the light), `float32` (an exact f32 count resolved
    /// into the stencil) or `auto` (float32 only when a sound bound of that count reaches 256).
    #[arg(long, default_value = "auto")]
    pub counter: String,
    /// Output PNG file.
    #[arg(long, default_value = "umbra.png")]
    pub out: String,
    /// Drawing backend: `gl` (OpenGL 4.5 through EGL) or `wgpu` (Vulkan, Metal or DX12; Mesa's
    /// lavapipe without a GPU). wgpu has no geometry or tessellation shaders: their methods
    /// stay GL-only.
    #[arg(long, default_value = "gl")]
    pub backend: String,
}

/// Flags of `umbra view` (see umbra_view for the controls).
#[derive(Args, Debug)]
pub struct ViewWindowArgs {
    /// Scene spec or mesh file, as for `render --scene` (takes precedence over --scene).
    #[arg(value_name = "SCENE")]
    pub scene_arg: Option<String>,
    /// Scene, camera, light and size flags as for `render`; --size is the window's initial size.
    #[command(flatten)]
    pub view: ViewArgs,
    /// Initial shadow method (number keys and M switch it in the window).
    #[arg(long)]
    pub method: Option<String>,
    /// Camera path: one frame per line, `eye x y z target x y z` (or the six numbers, as in
    /// bench/*.flythrough); `#` comments.
    #[arg(long)]
    pub script: Option<String>,
    /// Write the window's frame after the script's last pose (or the first frame) to this PNG, then exit.
    #[arg(long)]
    pub screenshot: Option<String>,
    /// Start in the shadow-mask view (V toggles it): white = lit by every light, black = by none.
    #[arg(long)]
    pub mask: bool,
    /// Shadow-volume counter, as for `render`: `stencil8`, `float32` or `auto` (decided once,
    /// for the initial lights: float32 when a sound bound of the count reaches 256).
    #[arg(long, default_value = "auto")]
    pub counter: String,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Scene spec or mesh file, as for `render --scene` (optional with `--backend`).
    pub scene: Option<String>,
    /// The same as the positional SCENE, spelled as every other subcommand spells it.
    #[arg(long = "scene", value_name = "SCENE")]
    pub scene_flag: Option<String>,
    /// Print the device the backend draws on: `gl` (the GL renderer) or `wgpu` (the adapter).
    #[arg(long)]
    pub backend: Option<String>,
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
    #[command(flatten)]
    pub sm: SmArgs,
    /// Methods to verify: NAME[,NAME...] or `all`.
    #[arg(long, default_value = "all")]
    pub method: String,
    /// Shadow-volume counter: `stencil8` (the 8-bit stencil; wraps when 256 or more
    /// triangles lie between a sample and the light), `float32` (an exact f32 count resolved
    /// into the stencil) or `auto` (float32 only when a sound bound of that count reaches 256).
    #[arg(long, default_value = "auto")]
    pub counter: String,
    /// Print a JSON array, one object per method.
    #[arg(long)]
    pub json: bool,
    /// Write a diff image: false shadow red, false light blue, boundary band grey.
    /// With several methods, the method name is inserted before the extension.
    #[arg(long)]
    pub diff: Option<String>,
    /// Print, on stderr, what is known about up to N mismatching samples outside the band per
    /// method and light (triangle, position, distance to its edges, first occluder).
    #[arg(long, default_value_t = 0)]
    pub explain: usize,
    /// Also compare a shadow mask made elsewhere with the reference, as one more row named by
    /// the file: a PNG of the view's size, top row first, pure white = lit, any other colour =
    /// shadowed (the WebGL2 viewer's `mask=1` view read back). One light only.
    #[arg(long)]
    pub external_mask: Option<String>,
    /// The band's sub-pixel precision, as `GL_SUBPIXEL_BITS` (4 to 16), when the samples being
    /// judged were rasterized by another implementation than this context: an
    /// `--external-mask` from a browser, with the `SUBPIXEL_BITS` its WebGL 2 context reports
    /// (SwiftShader: 4). Every row of the run is judged with it. Default: the context's own.
    #[arg(long)]
    pub subpixel_bits: Option<u32>,
    /// Drawing backend: `gl` (OpenGL 4.5 through EGL) or `wgpu` (Vulkan, Metal or DX12; Mesa's
    /// lavapipe without a GPU). wgpu has no geometry or tessellation shaders: their methods
    /// stay GL-only.
    #[arg(long, default_value = "gl")]
    pub backend: String,
}

/// Flags of `umbra bench` (frame benchmarks; see docs/benchmarks.md "Frame benchmarks").
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Scene: `default`, `box`, `spheres:N`, `spheres:N:T`, or a mesh file.
    #[arg(long, default_value = "default")]
    pub scene: String,
    /// Methods: NAME[,NAME...] or `all` (default `all`; with --suite: replaces the suite's methods).
    /// Shadow maps: `shadow-map-cube:RES`, any RES.
    #[arg(long)]
    pub methods: Option<String>,
    /// Camera path: `orbit` (around exteriors, inside interiors) or a fly-through file
    /// (one keyframe per line: eye x y z, target x y z; `#` comments).
    #[arg(long, default_value = "orbit")]
    pub flythrough: String,
    /// Measured frames per method (default 24; suites have their own defaults).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Warm-up frames per method, not measured (default 2; suites: 1).
    #[arg(long)]
    pub warmup: Option<usize>,
    /// Image size WxH (default 1280x720; with --suite: overrides the runs' sizes).
    #[arg(long)]
    pub size: Option<String>,
    /// Stage-time every N-th measured frame with an extra synchronous frame (0 = never;
    /// default 1, suites: 0 except 003-stages).
    #[arg(long)]
    pub stage_every: Option<usize>,
    /// Print a JSON array, one object per method (and run).
    #[arg(long)]
    pub json: bool,
    /// Write every frame and stage time to this CSV file.
    #[arg(long)]
    pub csv: Option<String>,
    /// Write SVG plots: FILE.svg (frame time along the path, or the suite's sweep) and FILE-stages.svg.
    #[arg(long)]
    pub plot: Option<String>,
    /// Run a benchmark suite (`list` lists them): 001-spheres, 001-objects, 001-vs-sm, 001-overall, 003-scenes, 003-stages.
    #[arg(long)]
    pub suite: Option<String>,
    /// With --suite: only these runs, 1-based, comma-separated.
    #[arg(long)]
    pub runs: Option<String>,
    /// Light as X,Y,Z or X,Y,Z,W (repeatable). Default: derived from the scene's bounds.
    #[arg(long, allow_hyphen_values = true)]
    pub light: Vec<String>,
    /// Add the receiving ground plane, as `render --ground`.
    #[arg(long)]
    pub ground: bool,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f64,
    /// An orthographic camera of this world-space height instead of the perspective one, as
    /// `render --ortho`.
    #[arg(long, allow_hyphen_values = true)]
    pub ortho: Option<String>,
    /// z-pass stencil counting instead of z-fail.
    #[arg(long)]
    pub zpass: bool,
    /// How shadow volumes count: `zfail` (always: Carmack's reverse, caps at infinity),
    /// `zpass` (always: wrong when the camera is inside a shadow volume) or `auto` (z-pass for
    /// each light whose volumes provably leave the eye out, z-fail for the others; exact, and
    /// faster: no caps, volumes clipped to the scene). `--zpass` is `--zmode zpass`.
    #[arg(long, default_value = "auto")]
    pub zmode: String,
    /// Cull and clamp the shadow volumes against each light's visible receivers: `on` (the
    /// default; cpu-silhouette on the GL backend: the same decision at every sample, less fill),
    /// `off` (the unclamped volumes), or `both` (each method that culls runs both ways in the
    /// one interleaved schedule, the second as `NAME@cull-off`). Other methods and the wgpu
    /// backend draw their volumes as they are either way.
    #[arg(long, default_value = "on")]
    pub volume_cull: String,
    /// Shadow-volume counter: `stencil8` (the 8-bit stencil; wraps when 256 or more
    /// triangles lie between a sample and the light), `float32` (an exact f32 count resolved
    /// into the stencil) or `auto` (float32 only when a sound bound of that count reaches 256).
    #[arg(long, default_value = "auto")]
    pub counter: String,
    /// Largest accepted input file in bytes, after decompression.
    #[arg(long)]
    pub max_input_bytes: Option<u64>,
    #[command(flatten)]
    pub sm: SmArgs,
    /// Test hook: print the interleaving order to stderr (`bench-order warmup|frame ROUND METHOD`).
    #[arg(long, hide = true)]
    pub trace_order: bool,
    /// Print one line per drawn frame to stderr as it finishes
    /// (`umbra bench: LABEL warmup|frame ROUND METHOD MS ms`), so a long run's partial
    /// results survive in a log when it is stopped.
    #[arg(long)]
    pub log: bool,
    /// Drawing backend: `gl` (OpenGL 4.5 through EGL) or `wgpu` (Vulkan, Metal or DX12; Mesa's
    /// lavapipe without a GPU). wgpu has no geometry or tessellation shaders: their methods
    /// stay GL-only.
    #[arg(long, default_value = "gl")]
    pub backend: String,
}

/// Flags of `umbra export` (see crate::export).
#[derive(Args, Debug)]
pub struct ExportArgs {
    /// Scene spec or mesh file, as for `render --scene`.
    #[arg(value_name = "SCENE")]
    pub scene: Option<String>,
    /// Output directory (created if needed).
    #[arg(long)]
    pub out: Option<String>,
    /// Add the receiving ground plane, as `render --ground`.
    #[arg(long)]
    pub ground: bool,
    /// Suggested light `X,Y,Z[,W]` written to the manifest. Default: as `render`.
    #[arg(long, allow_hyphen_values = true)]
    pub light: Option<String>,
    /// Suggested camera position X,Y,Z. Default: as `render`.
    #[arg(long, allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// Suggested camera target X,Y,Z. Default: as `render`.
    #[arg(long, allow_hyphen_values = true)]
    pub target: Option<String>,
    /// Suggested orthographic camera of this world-space height (manifest `camera.ortho_height`),
    /// as `render --ortho`. Default: perspective.
    #[arg(long, allow_hyphen_values = true)]
    pub ortho: Option<String>,
    /// Largest accepted input file in bytes, after decompression.
    #[arg(long)]
    pub max_input_bytes: Option<u64>,
    /// Instead of exporting: read DIR/manifest.json back and check it and every buffer file's size.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "out"])]
    pub check: Option<String>,
}
