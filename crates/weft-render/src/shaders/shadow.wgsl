// Weft's shadow pass: surfaces rendered into the sun's depth map.

struct Light {
    light_view_proj: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> light: Light;

@vertex
fn vs_shadow(@location(0) pos: vec3<f32>) -> @builtin(position) vec4<f32> {
    return light.light_view_proj * vec4<f32>(pos, 1.0);
}
