// The renderer's one pipeline (`tessera_render::Renderer`): vertex pulling from the mesh's
// storage buffers, so that each corner knows its barycentric coordinate (for the wireframe)
// and its triangle (for patch and level colours) without extra vertex data. The shading
// functions mirror `tessera_render::shading`, name for name.

struct Frame {
    // `tessera::camera::Camera::view_projection`, in f32.
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // Towards the light: `shading::light_direction`.
    light: vec4<f32>,
    // x: colour mode (`ColorMode::code`), y: wireframe on, z: per-triangle patches bound.
    flags: vec4<u32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
// `tessera_gpu::VERTEX_LAYOUT`: position, normal, uv; 8 floats a vertex.
@group(0) @binding(1) var<storage, read> vertices: array<f32>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read> triangle_patch: array<u32>;
@group(0) @binding(4) var<storage, read> patch_level: array<f32>;
// `args.wgsl`'s draw info: first index, base vertex.
@group(0) @binding(5) var<storage, read> draw_info: array<u32, 4>;

const MAX_SURFACE: f32 = 0.96;
const WIRE_WIDTH: f32 = 1.0;
const WIRE_COLOR: vec3<f32> = vec3<f32>(0.20, 0.18, 0.18);

struct Corner {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) bary: vec3<f32>,
    @location(3) @interpolate(flat) base: vec3<f32>,
};

// `shading::hsv`.
fn hsv(h: f32, s: f32, v: f32) -> vec3<f32> {
    let p = (vec3<f32>(h * 6.0) + vec3<f32>(5.0, 3.0, 1.0)) % vec3<f32>(6.0);
    let q = clamp(min(p, vec3<f32>(4.0) - p), vec3<f32>(0.0), vec3<f32>(1.0));
    return vec3<f32>(v) - v * s * q;
}

// `shading::base_colour`.
fn base_colour(mode: u32, patch_id: u32, level: f32) -> vec3<f32> {
    if (mode == 1u) {
        return hsv(fract(f32(patch_id) * 0.618034), 0.45, 0.85);
    }
    if (mode == 2u) {
        let t = clamp(level, 0.0, 1.0);
        let a = vec3<f32>(0.25, 0.45, 0.85);
        let b = vec3<f32>(0.35, 0.75, 0.35);
        let c = vec3<f32>(0.85, 0.30, 0.25);
        if (t < 0.5) { return mix(a, b, 2.0 * t); }
        return mix(b, c, 2.0 * t - 1.0);
    }
    return vec3<f32>(0.80, 0.63, 0.47);
}

// `shading::shade`.
fn shade(base: vec3<f32>, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>, back: bool) -> vec3<f32> {
    let diffuse = max(dot(n, l), 0.0);
    var h = l + v;
    if (dot(h, h) > 0.0) { h = normalize(h); }
    let specular = 0.30 * pow(max(dot(n, h), 0.0), 40.0);
    let tint = select(1.0, 0.6, back);
    let c = base * tint * (0.18 + 0.82 * diffuse) + vec3<f32>(specular * tint);
    return min(c, vec3<f32>(MAX_SURFACE));
}

// `shading::wire_coverage`.
fn wire_coverage(distance_px: f32) -> f32 {
    return clamp(WIRE_WIDTH * 0.5 + 0.5 - distance_px, 0.0, 1.0);
}

@vertex
fn vs(@builtin(vertex_index) k: u32) -> Corner {
    let index = indices[draw_info[0] + k] + draw_info[1];
    let o = index * 8u;
    let p = vec3<f32>(vertices[o], vertices[o + 1u], vertices[o + 2u]);
    let n = vec3<f32>(vertices[o + 3u], vertices[o + 4u], vertices[o + 5u]);
    let t = k / 3u;
    var patch_id = 0u;
    if (frame.flags.z != 0u) { patch_id = triangle_patch[t]; }
    var level = 0.0;
    if (frame.flags.x == 2u) { level = patch_level[patch_id]; }
    var out: Corner;
    out.clip = frame.view_proj * vec4<f32>(p, 1.0);
    out.world = p;
    out.normal = n;
    let c = k % 3u;
    out.bary = vec3<f32>(f32(c == 0u), f32(c == 1u), f32(c == 2u));
    out.base = base_colour(frame.flags.x, patch_id, level);
    return out;
}

@fragment
fn fs(in: Corner) -> @location(0) vec4<f32> {
    // Derivatives first, in uniform control flow.
    let face = cross(dpdx(in.world), dpdy(in.world));
    let width = fwidth(in.bary);
    var n = in.normal;
    // A zero normal (a collapsed corner) falls back to the face's.
    if (dot(n, n) < 1e-20) { n = face; }
    n = normalize(n);
    let v = normalize(frame.eye.xyz - in.world);
    let back = dot(n, v) < 0.0;
    if (back) { n = -n; }
    var colour = shade(in.base, n, v, frame.light.xyz, back);
    if (frame.flags.y != 0u) {
        let d = in.bary / max(width, vec3<f32>(1e-12));
        let coverage = wire_coverage(min(d.x, min(d.y, d.z)));
        colour = mix(colour, WIRE_COLOR, coverage);
    }
    return vec4<f32>(colour, 1.0);
}
