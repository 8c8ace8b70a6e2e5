//! Triangle strips: one index buffer, strips separated by [`RESTART`] (the primitive-restart
//! value of Vulkan, Metal, D3D and wgpu for 32-bit indices), and the decoder to a list.
//!
//! Winding follows the graphics APIs: in a strip `v0 v1 v2 v3 …`, triangle `i` is
//! `(v_i, v_{i+1}, v_{i+2})` for even `i` and `(v_{i+1}, v_i, v_{i+2})` for odd `i`, so every
//! triangle keeps the first one's orientation. Triangles with a repeated index are the
//! strips' joints and virtual-vertex fillers (ESC, paper 002); they draw nothing, and the
//! decoder drops them.

/// Separates strips in a strip index buffer.
pub const RESTART: u32 = u32::MAX;

/// Decodes strips into triangles, dropping those with a repeated index. Cost: O(len).
pub fn decode(strips: &[u32]) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(strips.len());
    decode_into(strips, &mut out);
    out
}

/// [`decode`] appending to `out`.
pub fn decode_into(strips: &[u32], out: &mut Vec<[u32; 3]>) {
    for strip in strips.split(|&i| i == RESTART) {
        for (i, w) in strip.windows(3).enumerate() {
            let t = if i % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] };
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                out.push(t);
            }
        }
    }
}

/// Number of triangles [`decode`] gives, without allocating.
pub fn decoded_count(strips: &[u32]) -> usize {
    strips
        .split(|&i| i == RESTART)
        .map(|s| s.windows(3).filter(|w| w[0] != w[1] && w[1] != w[2] && w[0] != w[2]).count())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alternate_triangles_are_flipped_and_joints_dropped() {
        // Windows: 012, 123 (odd: 213), 233 and 334 (joints, dropped), 345 (even).
        let strips = [0, 1, 2, 3, 3, 4, 5, RESTART, 5, 6, 7, 8];
        let tris = decode(&strips);
        assert_eq!(tris, vec![[0, 1, 2], [2, 1, 3], [3, 4, 5], [5, 6, 7], [7, 6, 8]]);
        assert_eq!(decoded_count(&strips), 5);
    }

    #[test]
    fn short_and_empty_strips_decode_to_nothing() {
        assert!(decode(&[]).is_empty());
        assert!(decode(&[RESTART, 1, 2, RESTART, RESTART]).is_empty());
    }
}
