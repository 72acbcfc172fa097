//! The viewer's overlay text — frame time, method, triangles, silhouette edges, lights, view
//! mode — shown as the window title.
//!
//! Why the title and not egui: egui's GL back end `egui_glow` 0.37 (its newest release) is
//! built on glow 0.17, umbra on glow 0.18; a `glow::Context` of one version cannot be passed
//! to the other, and a second glow 0.17 context on the same GL context would double the GL
//! bindings for a status line. The title needs no text rasterizer, works on X11 and Wayland
//! and stays out of the frame (a screenshot is exactly the rendered view).
//!
//! Silhouette edges are counted on the CPU with the deterministic multiplicity test of paper
//! 001 (Alg. 2-4, `umbra_geom::silhouette::silhouette_stats`): the number of edges with a
//! non-zero multiplicity, summed over the lights.

use umbra_geom::adjacency::EdgeAdjacency;
use umbra_geom::silhouette::silhouette_stats;
use umbra_geom::{Light, WeldedMesh};

/// Everything the overlay shows.
#[derive(Clone, Debug, PartialEq)]
pub struct OverlayInfo<'a> {
    /// Scene name (spec or file).
    pub scene: &'a str,
    /// Current shadow method.
    pub method: &'a str,
    /// Smoothed frame time in milliseconds (None before the second frame).
    pub frame_ms: Option<f64>,
    /// Triangles drawn (after welding).
    pub triangles: usize,
    /// Silhouette edges summed over the lights (None while not yet counted).
    pub silhouette_edges: Option<usize>,
    /// Number of lights.
    pub lights: usize,
    /// Index of the light the keys and shift-drag move.
    pub selected_light: usize,
    /// Whether the shadow-mask view is on.
    pub mask_view: bool,
    /// Whether the selected light's shadow-volume wireframe is drawn (F).
    pub wireframe: bool,
    /// Whether the volumes are culled against the receivers (C; `--volume-cull`).
    pub volume_cull: bool,
    /// Last problem worth showing (e.g. a method that failed and was switched back).
    pub status: Option<&'a str>,
}

/// The overlay line.
pub fn title(i: &OverlayInfo<'_>) -> String {
    let ms = i.frame_ms.map_or_else(|| "-".to_string(), |ms| format!("{ms:.1} ms"));
    let edges = i.silhouette_edges.map_or_else(|| "-".to_string(), |e| e.to_string());
    let mut s = format!(
        "umbra view | {} | {} | {ms} | {} triangles | {edges} silhouette edges | light {}/{}",
        i.scene,
        i.method,
        i.triangles,
        (i.selected_light + 1).min(i.lights),
        i.lights
    );
    if i.mask_view {
        s.push_str(" | shadow mask");
    }
    if i.wireframe {
        // The wireframe is drawn over the shaded view only (see app.rs).
        s.push_str(if i.mask_view { " | wireframe (shaded view only)" } else { " | volume wireframe" });
    }
    if !i.volume_cull {
        s.push_str(" | volume cull off");
    }
    if let Some(status) = i.status {
        s.push_str(" | ");
        s.push_str(status);
    }
    s
}

/// Silhouette edges of `mesh` summed over `lights`.
pub fn silhouette_edges(mesh: &WeldedMesh, adjacency: &EdgeAdjacency, lights: &[Light]) -> usize {
    lights.iter().map(|&l| silhouette_stats(mesh, adjacency, l).0).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info() -> OverlayInfo<'static> {
        OverlayInfo {
            scene: "default",
            method: "cpu-silhouette",
            frame_ms: Some(12.345),
            triangles: 1234,
            silhouette_edges: Some(56),
            lights: 2,
            selected_light: 1,
            mask_view: false,
            wireframe: false,
            volume_cull: true,
            status: None,
        }
    }

    #[test]
    fn title_names_every_figure() {
        let t = title(&info());
        assert_eq!(
            t,
            "umbra view | default | cpu-silhouette | 12.3 ms | 1234 triangles | 56 silhouette edges | light 2/2"
        );
    }

    #[test]
    fn title_before_measurements_and_with_mask_and_status() {
        let t = title(&OverlayInfo {
            frame_ms: None,
            silhouette_edges: None,
            mask_view: true,
            status: Some("x failed"),
            ..info()
        });
        assert!(t.contains("| - |") && t.contains("- silhouette edges"), "{t}");
        assert!(t.ends_with("| shadow mask | x failed"), "{t}");
    }

    #[test]
    fn title_says_when_the_wireframe_is_on() {
        assert!(title(&OverlayInfo { wireframe: true, ..info() }).ends_with("| volume wireframe"));
        let both = title(&OverlayInfo { wireframe: true, mask_view: true, ..info() });
        assert!(both.ends_with("| shadow mask | wireframe (shaded view only)"), "{both}");
    }

    #[test]
    fn title_says_when_the_volume_cull_is_off() {
        assert!(!title(&info()).contains("volume cull"));
        let off = title(&OverlayInfo { volume_cull: false, status: Some("x"), ..info() });
        assert!(off.ends_with("| volume cull off | x"), "{off}");
    }

    #[test]
    fn a_closed_box_has_a_silhouette_per_light() {
        let mesh = umbra_geom::weld::weld(&umbra_geom::scene::cuboid([0.0; 3], [1.0; 3]));
        let adj = EdgeAdjacency::build(&mesh);
        // A point light straight above the box's top face sees it only: the silhouette is
        // the top face's 4 edges.
        let above = [0.0, 5.0, 0.0, 1.0];
        assert_eq!(silhouette_edges(&mesh, &adj, &[above]), 4);
        // A light off a corner sees three faces: a six-edge silhouette.
        let corner = [5.0, 5.0, 5.0, 1.0];
        assert_eq!(silhouette_edges(&mesh, &adj, &[corner]), 6);
        assert_eq!(silhouette_edges(&mesh, &adj, &[above, corner]), 10);
        assert_eq!(silhouette_edges(&mesh, &adj, &[]), 0);
    }
}
