// The embedding example's own pipeline (examples/gpu_frames.rs): the GPU engine's vertex
// buffer bound as a plain vertex buffer in `tessera_gpu::VERTEX_LAYOUT`, a head light.

struct View {
    // `tessera::camera::Camera::view_projection`, in f32.
    view_proj: mat4x4<f32>,
    // Towards the light.
    light: vec4<f32>,
};

@group(0) @binding(0) var<uniform> view: View;

struct Out {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
};

@vertex
fn vs(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) uv: vec2<f32>) -> Out {
    var out: Out;
    out.clip = view.view_proj * vec4<f32>(position, 1.0);
    out.normal = normal;
    return out;
}

@fragment
fn fs(in: Out, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.normal);
    let lambert = abs(dot(n, view.light.xyz));
    let base = vec3<f32>(0.80, 0.63, 0.47);
    return vec4<f32>(base * (0.2 + 0.8 * lambert), 1.0);
}
