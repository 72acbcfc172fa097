//! `umbra info`: mesh statistics that matter for shadow volumes.

use serde::Serialize;
use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::silhouette::silhouette_stats;
use umbra_geom::weld::weld;
use umbra_gl::methods::ts_silhouette::patch_bytes;
use umbra_gl::methods::vs_silhouette::plan_portable_layout;

use crate::backend::Backend;
use crate::config::InfoConfig;
use crate::error::CliError;
use crate::scenes::load_scene;

/// The JSON keys are a contract (`umbra info --json`).
#[derive(Serialize, Debug, PartialEq)]
pub struct InfoReport {
    /// After triangulation, before dropping degenerate ones.
    pub triangles: usize,
    /// After welding.
    pub vertices: usize,
    pub degenerate_triangles: usize,
    pub edges: usize,
    pub open_edges: usize,
    pub nonmanifold_edges: usize,
    pub max_opposites: usize,
    /// `ts-silhouette`'s input (paper 001 Fig. 4-5 patches over an element buffer), bytes.
    pub patch_bytes: usize,
    /// `vs-silhouette`'s sides-data, paper 003 Eq. 8: `16 (2 + max_mult) e` bytes, with `e` the
    /// edge records (edges with more opposite vertices than `max_mult` split over several).
    pub sides_data_bytes: usize,
    /// `vs-silhouette`'s caps-data, paper 003 Eq. 9: `48 t` bytes.
    pub caps_data_bytes: usize,
    /// The `maxMult` of Eq. 8 that `vs-silhouette` picks for this scene.
    pub max_mult: usize,
    /// The `e` of Eq. 8.
    pub sides_data_records: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub silhouette_edges: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multiplicity_sum: Option<u64>,
}

/// `umbra info --backend gl|wgpu`: the device the backend draws on, as (key, value) lines.
fn device_report(backend: Backend) -> Result<Vec<(String, String)>, CliError> {
    match backend {
        Backend::Wgpu => crate::wgpu_backend::adapter_report(),
        Backend::Gl => {
            let ctx = umbra_gl::HeadlessContext::new().map_err(|e| CliError::Gl(e.to_string()))?;
            Ok(vec![("renderer".into(), ctx.renderer_string())])
        }
    }
}

pub fn run(a: &InfoConfig) -> Result<(), CliError> {
    let device = a.backend.map(device_report).transpose()?;
    let Some(scene) = a.scene.as_deref() else {
        // Without a scene the configuration has a backend: the device alone.
        let device = device.unwrap_or_default();
        if a.json {
            let map: serde_json::Map<String, serde_json::Value> =
                device.into_iter().map(|(k, v)| (k.replace(' ', "_"), serde_json::Value::String(v))).collect();
            println!("{}", serde_json::Value::Object(map));
        } else {
            for (k, v) in device {
                println!("{k:<22}{v}");
            }
        }
        return Ok(());
    };
    if let (Some(device), false) = (&device, a.json) {
        for (k, v) in device {
            println!("{k:<22}{v}");
        }
    }
    let light = a.light;
    let mesh = load_scene(scene, a.ground, a.max_input_bytes)?;
    let welded = weld(&mesh);
    let adj = EdgeAdjacency::build(&welded);
    let silhouette = light.map(|l| silhouette_stats(&welded, &adj, l));
    // The layout vs-silhouette's `prepare` uses with the guaranteed 16 vertex attributes.
    let layout = plan_portable_layout(&adj, welded.triangles.len());
    let report = InfoReport {
        triangles: mesh.triangles.len(),
        vertices: welded.positions.len(),
        degenerate_triangles: welded.degenerate_triangles,
        edges: adj.len(),
        open_edges: adj.open_edges(),
        nonmanifold_edges: adj.nonmanifold_edges(),
        max_opposites: adj.max_opposites(),
        patch_bytes: patch_bytes(&adj),
        sides_data_bytes: layout.sides_bytes,
        caps_data_bytes: layout.caps_bytes,
        max_mult: layout.max_mult,
        sides_data_records: layout.records,
        silhouette_edges: silhouette.map(|s| s.0),
        multiplicity_sum: silhouette.map(|s| s.1),
    };
    if a.json {
        let mut value = serde_json::to_value(&report).map_err(|e| CliError::Other(e.to_string()))?;
        if let (Some(device), serde_json::Value::Object(map)) = (device, &mut value) {
            // `--backend`: the device under "device" (the statistics' keys are unchanged).
            let d: serde_json::Map<String, serde_json::Value> =
                device.into_iter().map(|(k, v)| (k.replace(' ', "_"), serde_json::Value::String(v))).collect();
            map.insert("device".into(), serde_json::Value::Object(d));
        }
        println!("{value}");
    } else {
        println!("scene                 {scene}");
        println!("triangles             {}", report.triangles);
        println!("vertices (welded)     {}", report.vertices);
        println!("degenerate triangles  {}", report.degenerate_triangles);
        println!("edges                 {}", report.edges);
        println!("open edges            {}", report.open_edges);
        println!("non-manifold edges    {}", report.nonmanifold_edges);
        println!("max opposite vertices {}", report.max_opposites);
        println!("patch bytes           {} (ts-silhouette input)", report.patch_bytes);
        println!(
            "sides-data bytes      {} (vs-silhouette, Eq. 8: 16 x (2 + {}) x {} records)",
            report.sides_data_bytes, report.max_mult, report.sides_data_records
        );
        println!(
            "caps-data bytes       {} (vs-silhouette, Eq. 9: 48 x {} triangles)",
            report.caps_data_bytes,
            welded.triangles.len()
        );
        if let (Some(e), Some(s)) = (report.silhouette_edges, report.multiplicity_sum) {
            println!("silhouette edges      {e}");
            println!("sum of |multiplicity| {s}");
        }
    }
    Ok(())
}
