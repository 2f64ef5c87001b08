//! The orbit camera: yaw/pitch/distance around a target, rays from pixels and back.
//!
//! Conventions: right-handed, Y up, wgpu clip depth 0..1; pixels are physical, origin at the
//! top-left corner of the target, x right and y down. Yaw 0 and pitch 0 put the eye on +Z of
//! the target looking towards −Z; positive pitch looks from above.

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4Swizzles};

/// Radians of orbit per pixel dragged.
const ORBIT_RAD_PER_PX: f32 = 0.008;
/// How far short of the poles pitch is clamped (rad), so `look_at` keeps a defined up.
const POLE_MARGIN: f32 = 0.02;
/// Distance factor per zoom step (a mouse-wheel notch).
const ZOOM_PER_STEP: f32 = 0.9;
/// Zoom limits (m).
const MIN_DISTANCE: f32 = 0.02;
const MAX_DISTANCE: f32 = 1.0e4;

/// A ray in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point (the eye).
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Ray {
    /// The point at parameter `t` (metres along the ray).
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// Orbit camera around a target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Point orbited and looked at.
    pub target: Vec3,
    /// Rotation about +Y (rad); 0 puts the eye on the target's +Z side.
    pub yaw: f32,
    /// Elevation (rad), positive looks from above; kept inside (−π/2, π/2).
    pub pitch: f32,
    /// Eye–target distance (m).
    pub distance: f32,
    /// Vertical field of view (rad).
    pub fov_y: f32,
    /// Near clip distance (m).
    pub near: f32,
    /// Far clip distance (m).
    pub far: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self::looking_at(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO)
    }
}

impl Camera {
    /// A camera with its eye at `eye` looking at `target`.
    pub fn looking_at(eye: Vec3, target: Vec3) -> Self {
        let offset = eye - target;
        let distance = offset.length().max(MIN_DISTANCE);
        let pitch = (offset.y / distance)
            .clamp(-1.0, 1.0)
            .asin()
            .clamp(-Self::max_pitch(), Self::max_pitch());
        let yaw = offset.x.atan2(offset.z);
        let mut c = Self {
            target,
            yaw,
            pitch,
            distance,
            fov_y: 40f32.to_radians(),
            near: 0.01,
            far: 100.0,
        };
        c.fit_clip_planes(distance);
        c
    }

    /// A camera that fits the box `min..max` in view from a 3/4 angle, slightly from above,
    /// in an image at least as wide as tall.
    pub fn framing(min: Vec3, max: Vec3) -> Self {
        Self::framing_for(min, max, 1.0)
    }

    /// A camera that fits the box `min..max` in view from a 3/4 angle, slightly from above,
    /// in an image of width/height `aspect` (a tall image is taken as it is; a wide one as
    /// square, so the box also fits when part of the width is covered, e.g. by a panel).
    pub fn framing_for(min: Vec3, max: Vec3, aspect: f32) -> Self {
        let (min, max) = if min.is_finite() && max.is_finite() && min.cmple(max).all() {
            (min, max)
        } else {
            (Vec3::splat(-1.0), Vec3::splat(1.0))
        };
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect.min(1.0)
        } else {
            1.0
        };
        let center = 0.5 * (min + max);
        let radius = (0.5 * (max - min).length()).max(0.05);
        let mut c = Self {
            target: center,
            yaw: 35f32.to_radians(),
            pitch: 22f32.to_radians(),
            distance: 1.0,
            fov_y: 40f32.to_radians(),
            near: 0.01,
            far: 100.0,
        };
        // The nearest distance at which every corner of the box is inside the view frustum
        // (vertical half-angle fov/2, horizontal tan scaled by the aspect), with a 6% margin:
        // a corner at (x, y, z) in view axes around the target needs
        // D ≥ z + max(|x| / aspect, |y|) / tan(fov/2).
        let (right, up) = c.right_up();
        let back = c.back();
        let t = (0.5 * c.fov_y).tan();
        let half = 0.5 * (max - min);
        let mut distance = radius;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { -half.x } else { half.x },
                if i & 2 == 0 { -half.y } else { half.y },
                if i & 4 == 0 { -half.z } else { half.z },
            );
            let (x, y, z) = (corner.dot(right), corner.dot(up), corner.dot(back));
            distance = distance.max(z + (x.abs() / aspect).max(y.abs()) / (0.94 * t));
        }
        c.distance = distance;
        c.fit_clip_planes(radius);
        c
    }

    /// Near/far planes for a scene of size `extent` around the target: wide enough for a
    /// ground grid, tight enough for depth precision.
    fn fit_clip_planes(&mut self, extent: f32) {
        self.near = (0.01 * self.distance).clamp(1e-3, 1.0);
        self.far = (self.distance + extent) * 50.0 + 20.0;
    }

    fn max_pitch() -> f32 {
        std::f32::consts::FRAC_PI_2 - POLE_MARGIN
    }

    /// Unit vector from the target towards the eye.
    fn back(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(cp * sy, sp, cp * cy)
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        self.target + self.distance * self.back()
    }

    /// Unit view direction (eye towards target).
    pub fn forward(&self) -> Vec3 {
        -self.back()
    }

    /// Unit camera right and up vectors in world space.
    pub fn right_up(&self) -> (Vec3, Vec3) {
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize();
        (right, right.cross(f))
    }

    /// World → view matrix (`look_at_rh`, Y up).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y)
    }

    /// View → clip matrix (`perspective_rh`, depth 0..1).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        glam::camera::rh::proj::directx::perspective(
            self.fov_y,
            aspect.max(1e-6),
            self.near,
            self.far,
        )
    }

    /// World → clip matrix for a target of `size` pixels.
    pub fn view_proj(&self, size: UVec2) -> Mat4 {
        self.projection(aspect(size)) * self.view()
    }

    /// The ray from the eye through `cursor` (physical pixels, origin top-left).
    pub fn ray(&self, cursor: Vec2, size: UVec2) -> Ray {
        let s = size.max(UVec2::ONE).as_vec2();
        let ndc = Vec2::new(2.0 * cursor.x / s.x - 1.0, 1.0 - 2.0 * cursor.y / s.y);
        let t = (0.5 * self.fov_y).tan();
        let (right, up) = self.right_up();
        let dir = self.forward() + ndc.x * t * aspect(size) * right + ndc.y * t * up;
        Ray {
            origin: self.eye(),
            dir: dir.normalize(),
        }
    }

    /// The pixel where world point `p` appears, or `None` if it is not in front of the eye.
    pub fn project(&self, p: Vec3, size: UVec2) -> Option<Vec2> {
        let clip = self.view_proj(size) * p.extend(1.0);
        if clip.w <= 1e-6 {
            return None;
        }
        let ndc = clip.xy() / clip.w;
        let s = size.max(UVec2::ONE).as_vec2();
        Some(Vec2::new(
            0.5 * (ndc.x + 1.0) * s.x,
            0.5 * (1.0 - ndc.y) * s.y,
        ))
    }

    /// Orbits by a mouse drag of `(dx, dy)` pixels: right turns the view left-to-right around
    /// the target, down raises the eye. Pitch stays short of the poles; distance is unchanged.
    pub fn orbit(&mut self, dx_px: f32, dy_px: f32) {
        self.yaw = (self.yaw - dx_px * ORBIT_RAD_PER_PX).rem_euclid(std::f32::consts::TAU);
        self.pitch =
            (self.pitch + dy_px * ORBIT_RAD_PER_PX).clamp(-Self::max_pitch(), Self::max_pitch());
    }

    /// Pans by a mouse drag of `(dx, dy)` pixels so the point under the cursor at the
    /// target's depth stays under the cursor.
    pub fn pan(&mut self, dx_px: f32, dy_px: f32, size: UVec2) {
        // At view depth D one pixel spans 2 D tan(fov/2) / height metres.
        let s = size.max(UVec2::ONE).as_vec2();
        let metres_per_px = 2.0 * self.distance * (0.5 * self.fov_y).tan() / s.y;
        let (right, up) = self.right_up();
        self.target += metres_per_px * (-dx_px * right + dy_px * up);
    }

    /// Zooms by `steps` wheel notches: positive moves closer, each step scales the distance
    /// by 0.9; the distance stays within [0.02 m, 10 km].
    pub fn zoom(&mut self, steps: f32) {
        if steps.is_finite() {
            self.distance =
                (self.distance * ZOOM_PER_STEP.powf(steps)).clamp(MIN_DISTANCE, MAX_DISTANCE);
            self.near = (0.01 * self.distance).clamp(1e-3, 1.0);
            self.far = self.far.max(self.distance * 50.0);
        }
    }
}

fn aspect(size: UVec2) -> f32 {
    let s = size.max(UVec2::ONE).as_vec2();
    s.x / s.y
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: UVec2 = UVec2::new(640, 480);

    fn cam() -> Camera {
        Camera::looking_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.1, 0.3, -0.2))
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn looking_at_reproduces_eye_and_target() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let c = cam();
        assert!(close(c.eye(), eye, 1e-5), "{:?}", c.eye());
        assert!((c.distance - (eye - c.target).length()).abs() < 1e-5);
        // view maps the eye to the origin and the target onto −Z.
        let v = c.view();
        assert!(close(v.transform_point3(eye), Vec3::ZERO, 1e-5));
        let t = v.transform_point3(c.target);
        assert!(close(t, Vec3::new(0.0, 0.0, -c.distance), 1e-5), "{t:?}");
    }

    #[test]
    fn yaw_zero_pitch_zero_looks_down_minus_z() {
        let c = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        assert!(c.yaw.abs() < 1e-6 && c.pitch.abs() < 1e-6);
        assert!(close(c.forward(), -Vec3::Z, 1e-6));
    }

    #[test]
    fn centre_ray_is_forward() {
        let c = cam();
        let r = c.ray(SIZE.as_vec2() * 0.5, SIZE);
        assert!(close(r.origin, c.eye(), 1e-5));
        assert!(
            close(r.dir, c.forward(), 1e-5),
            "{:?} vs {:?}",
            r.dir,
            c.forward()
        );
        assert!((r.dir.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn project_inverts_ray() {
        let c = cam();
        for px in [
            Vec2::new(0.0, 0.0),
            Vec2::new(320.0, 240.0),
            Vec2::new(17.5, 402.25),
            Vec2::new(639.0, 5.0),
        ] {
            let r = c.ray(px, SIZE);
            for t in [0.5, 3.0, 40.0] {
                let back = c.project(r.at(t), SIZE).expect("in front of the eye");
                assert!((back - px).length() < 2e-2, "{px:?} t={t} -> {back:?}");
            }
        }
    }

    #[test]
    fn project_rejects_points_behind_the_eye() {
        let c = cam();
        assert!(c.project(c.eye() - c.forward(), SIZE).is_none());
        assert!(c.project(c.target, SIZE).is_some());
    }

    #[test]
    fn corner_rays_span_the_field_of_view() {
        let c = cam();
        let top = c.ray(Vec2::new(320.0, 0.0), SIZE);
        let bottom = c.ray(Vec2::new(320.0, 480.0), SIZE);
        let angle = top.dir.angle_between(bottom.dir);
        assert!((angle - c.fov_y).abs() < 1e-4, "{angle} vs {}", c.fov_y);
    }

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut c = cam();
        let (target, d) = (c.target, c.distance);
        for (dx, dy) in [(40.0, 10.0), (-300.0, 5000.0), (0.0, -9000.0)] {
            c.orbit(dx, dy);
            assert!(((c.eye() - target).length() - d).abs() < 1e-4);
            assert_eq!(c.target, target);
            assert!(c.pitch.abs() < std::f32::consts::FRAC_PI_2);
            assert!(c.view().is_finite());
        }
    }

    #[test]
    fn orbit_right_moves_eye_around_y() {
        let mut c = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
        c.orbit(100.0, 0.0);
        // The eye stays level and the angle turned is 100 px × rate.
        assert!(c.eye().y.abs() < 1e-5);
        let turned = Vec3::Z.angle_between(c.eye().normalize());
        assert!((turned - 100.0 * ORBIT_RAD_PER_PX).abs() < 1e-4);
    }

    #[test]
    fn pan_keeps_target_depth_point_under_cursor() {
        let mut c = cam();
        let cursor = Vec2::new(200.0, 150.0);
        // The world point under the cursor at the target's depth.
        let r = c.ray(cursor, SIZE);
        let t = c.distance / r.dir.dot(c.forward());
        let p = r.at(t);
        let (dx, dy) = (37.0, -21.0);
        let d = c.distance;
        c.pan(dx, dy, SIZE);
        let moved = c.project(p, SIZE).expect("visible");
        assert!(
            (moved - (cursor + Vec2::new(dx, dy))).length() < 1e-2,
            "{moved:?}"
        );
        assert!((c.distance - d).abs() < 1e-6);
    }

    #[test]
    fn zoom_is_multiplicative_and_clamped() {
        let mut c = cam();
        let d = c.distance;
        c.zoom(1.0);
        assert!((c.distance - 0.9 * d).abs() < 1e-5);
        c.zoom(-1.0);
        assert!((c.distance - d).abs() < 1e-5);
        c.zoom(1000.0);
        assert_eq!(c.distance, MIN_DISTANCE);
        c.zoom(-1.0e5);
        assert_eq!(c.distance, MAX_DISTANCE);
        c.zoom(f32::NAN);
        assert_eq!(c.distance, MAX_DISTANCE);
    }

    #[test]
    fn framing_sees_every_corner_of_the_box() {
        let (min, max) = (Vec3::new(-1.0, 0.0, -0.5), Vec3::new(1.0, 2.0, 0.5));
        let c = Camera::framing(min, max);
        assert!(close(c.target, Vec3::new(0.0, 1.0, 0.0), 1e-6));
        assert!(c.pitch > 0.0, "looks from above");
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            );
            let px = c.project(p, SIZE).expect("in front");
            assert!(
                px.x > 0.0 && px.y > 0.0 && px.x < 640.0 && px.y < 480.0,
                "corner {p:?} at {px:?}"
            );
            let depth = (p - c.eye()).dot(c.forward());
            assert!(depth > c.near && depth < c.far);
        }
    }

    #[test]
    fn framing_a_tall_image_sees_every_corner_of_a_wide_box() {
        let (min, max) = (Vec3::new(-2.0, 0.0, -0.5), Vec3::new(2.0, 1.0, 0.5));
        let tall = UVec2::new(300, 800);
        let fits = |c: &Camera| {
            (0..8).all(|i| {
                let p = Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                );
                let px = c.project(p, tall).expect("in front");
                px.x > 0.0 && px.y > 0.0 && px.x < 300.0 && px.y < 800.0
            })
        };
        assert!(fits(&Camera::framing_for(min, max, 300.0 / 800.0)));
        // Framed as if square, the box's ends fall outside the tall image.
        assert!(!fits(&Camera::framing(min, max)));
    }
}
