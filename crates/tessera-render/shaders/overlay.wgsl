// The on-screen text line (`tessera_render::overlay::Overlay`): a full-screen triangle whose
// fragments inside the text box look their character up in `chars` and its glyph column in
// `font` (5×7 glyphs, one u32 per column, bit 0 the top row; `overlay::FONT`). Pixels of the
// box around the glyphs are a translucent dark panel.

struct Text {
    // x, y of the box's top left in pixels, the pixel scale, characters per line.
    place: vec4<u32>,
    // lines, unused.
    lines: vec4<u32>,
};

@group(0) @binding(0) var<uniform> text: Text;
@group(0) @binding(1) var<storage, read> chars: array<u32>;
@group(0) @binding(2) var<storage, read> font: array<u32>;

const CELL_W: u32 = 6u;
const CELL_H: u32 = 9u;
const PAD: u32 = 3u;

@vertex
fn vs(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(k & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let scale = max(text.place.z, 1u);
    let cols = text.place.w;
    let rows = text.lines.x;
    let px = vec2<i32>(i32(p.x) - i32(text.place.x), i32(p.y) - i32(text.place.y)) / i32(scale);
    let w = i32(cols * CELL_W + 2u * PAD);
    let h = i32(rows * CELL_H + 2u * PAD);
    if (px.x < 0 || px.y < 0 || px.x >= w || px.y >= h) {
        discard;
    }
    let panel = vec4<f32>(0.08, 0.08, 0.10, 0.72);
    let q = vec2<i32>(px.x - i32(PAD), px.y - i32(PAD));
    if (q.x < 0 || q.y < 0) { return panel; }
    let col = u32(q.x) / CELL_W;
    let row = u32(q.y) / CELL_H;
    let gx = u32(q.x) % CELL_W;
    let gy = u32(q.y) % CELL_H;
    if (col >= cols || row >= rows || gx >= 5u || gy >= 7u) { return panel; }
    let code = chars[row * cols + col];
    let bits = font[code * 5u + gx];
    if (((bits >> gy) & 1u) != 0u) {
        return vec4<f32>(0.95, 0.95, 0.92, 1.0);
    }
    return panel;
}
