//! The viewer's camera and light controls, as plain math (no window, no GL): an orbit camera
//! (yaw about the world up axis, pitch clamped short of the poles, zoom by a factor per wheel
//! step), WASD fly moves (eye and target translate together), and light moves (point lights
//! translate; directional lights turn their direction).

use umbra_geom::Light;
use umbra_gl::glam::DVec3;

/// Pitch is kept this far (radians) from straight up or down, so the view direction never
/// becomes parallel to the up vector (the camera would be undefined there).
const POLE_MARGIN: f64 = 0.02;

/// Eye, target and up of the viewer's camera (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRig {
    /// Camera position.
    pub eye: [f64; 3],
    /// The point orbited around and looked at.
    pub target: [f64; 3],
    /// World up (the orbit's axis).
    pub up: [f64; 3],
}

impl CameraRig {
    fn up_axis(&self) -> DVec3 {
        DVec3::from(self.up).try_normalize().unwrap_or(DVec3::Y)
    }

    /// Unit view direction (eye towards target).
    pub fn forward(&self) -> DVec3 {
        (DVec3::from(self.target) - DVec3::from(self.eye)).try_normalize().unwrap_or(DVec3::NEG_Z)
    }

    /// Unit right vector of the view.
    pub fn right(&self) -> DVec3 {
        self.forward().cross(self.up_axis()).try_normalize().unwrap_or(DVec3::X)
    }

    /// Unit up vector of the image plane.
    pub fn screen_up(&self) -> DVec3 {
        self.right().cross(self.forward())
    }

    /// Distance from the eye to the target.
    pub fn distance(&self) -> f64 {
        DVec3::from(self.eye).distance(DVec3::from(self.target))
    }

    /// Turns the eye around the target: `yaw` about the up axis, `pitch` towards it
    /// (radians), keeping the distance; the pitch stops short of the poles.
    pub fn orbit(&mut self, yaw: f64, pitch: f64) {
        let up = self.up_axis();
        let target = DVec3::from(self.target);
        let offset = DVec3::from(self.eye) - target;
        let r = offset.length();
        if r == 0.0 {
            return;
        }
        let elevation = (offset.dot(up) / r).clamp(-1.0, 1.0).asin();
        let limit = std::f64::consts::FRAC_PI_2 - POLE_MARGIN;
        let new_elevation = (elevation + pitch).clamp(-limit, limit);
        // Horizontal direction of the offset, rotated by yaw about up.
        let horizontal = (offset - up * offset.dot(up)).try_normalize().unwrap_or_else(|| up.any_orthonormal_vector());
        let rotated = horizontal * yaw.cos() + up.cross(horizontal) * yaw.sin();
        let new_offset = (rotated * new_elevation.cos() + up * new_elevation.sin()) * r;
        self.eye = (target + new_offset).to_array();
    }

    /// Moves the eye towards (steps > 0) or away from the target by 10 % per step, never
    /// closer than `min_distance`.
    pub fn zoom(&mut self, steps: f64, min_distance: f64) {
        let target = DVec3::from(self.target);
        let offset = DVec3::from(self.eye) - target;
        let r = offset.length();
        if r == 0.0 {
            return;
        }
        let new_r = (r * 0.9f64.powf(steps)).max(min_distance);
        self.eye = (target + offset * (new_r / r)).to_array();
    }

    /// Translates eye and target together along the view's forward, right and up axes.
    pub fn fly(&mut self, forward: f64, right: f64, up: f64) {
        let d = self.forward() * forward + self.right() * right + self.up_axis() * up;
        self.eye = (DVec3::from(self.eye) + d).to_array();
        self.target = (DVec3::from(self.target) + d).to_array();
    }
}

/// Moves a light by `delta` (world space). A point light (w = 1) translates; a directional
/// light (w = 0, light coming from its xyz) turns: its unit direction plus `delta / scale`,
/// renormalised, so the same key press turns it by a similar angle whatever the scene size.
/// A move that would leave a zero direction leaves the light as it was.
pub fn move_light(light: Light, delta: [f64; 3], scale: f64) -> Light {
    let d = DVec3::from(delta);
    if light[3] == 0.0 {
        let dir = DVec3::new(light[0].into(), light[1].into(), light[2].into());
        let Some(unit) = dir.try_normalize() else { return light };
        match (unit + d / scale.max(f64::MIN_POSITIVE)).try_normalize() {
            Some(n) => [n.x as f32, n.y as f32, n.z as f32, 0.0],
            None => light,
        }
    } else {
        [light[0] + d.x as f32, light[1] + d.y as f32, light[2] + d.z as f32, light[3]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig() -> CameraRig {
        CameraRig { eye: [0.0, 1.0, 5.0], target: [0.0, 1.0, 0.0], up: [0.0, 1.0, 0.0] }
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9)
    }

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut r = rig();
        r.orbit(0.7, 0.3);
        assert!((r.distance() - 5.0).abs() < 1e-9);
        assert_eq!(r.target, [0.0, 1.0, 0.0]);
        assert!(r.eye[1] > 1.0, "pitched up: {:?}", r.eye);
        r.orbit(-0.7, -0.3);
        assert!(close(r.eye, rig().eye), "orbit is reversible: {:?}", r.eye);
    }

    #[test]
    fn orbit_quarter_turn_goes_round_the_up_axis() {
        let mut r = rig();
        r.orbit(std::f64::consts::FRAC_PI_2, 0.0);
        // Offset +Z turned 90 degrees about +Y (right-handed) is +X.
        assert!(close(r.eye, [5.0, 1.0, 0.0]), "{:?}", r.eye);
    }

    #[test]
    fn pitch_stops_short_of_the_pole() {
        let mut r = rig();
        r.orbit(0.0, 10.0);
        let offset = DVec3::from(r.eye) - DVec3::from(r.target);
        assert!(offset.normalize().dot(DVec3::Y) < 1.0 - 1e-5, "never straight above: {:?}", r.eye);
        assert!(DVec3::from(r.up).cross(r.forward()).length() > 1e-3, "view direction not parallel to up");
    }

    #[test]
    fn zoom_moves_towards_target_but_not_through_it() {
        let mut r = rig();
        r.zoom(1.0, 0.1);
        assert!((r.distance() - 4.5).abs() < 1e-9);
        r.zoom(1000.0, 0.1);
        assert!((r.distance() - 0.1).abs() < 1e-9);
        r.zoom(-2.0, 0.1);
        assert!(r.distance() > 0.1);
    }

    #[test]
    fn fly_translates_eye_and_target_together() {
        let mut r = rig();
        r.fly(1.0, 2.0, 0.5);
        assert!(close(r.eye, [2.0, 1.5, 4.0]), "{:?}", r.eye);
        assert!(close(r.target, [2.0, 1.5, -1.0]), "{:?}", r.target);
    }

    #[test]
    fn point_lights_translate_directional_lights_turn() {
        assert_eq!(move_light([1.0, 2.0, 3.0, 1.0], [0.5, 0.0, -1.0], 10.0), [1.5, 2.0, 2.0, 1.0]);
        let turned = move_light([0.0, 2.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0);
        assert_eq!(turned[3], 0.0);
        let len = (turned[0].powi(2) + turned[1].powi(2) + turned[2].powi(2)).sqrt();
        assert!((len - 1.0).abs() < 1e-6 && turned[0] > 0.5, "{turned:?}");
        // A move that cancels the direction leaves the light alone.
        assert_eq!(move_light([0.0, 1.0, 0.0, 0.0], [0.0, -1.0, 0.0], 1.0), [0.0, 1.0, 0.0, 0.0]);
    }
}
