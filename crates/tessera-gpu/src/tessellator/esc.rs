//! The ESC pattern's data on the device (`esc.wgsl`): what a plan and its
//! [`tessera::pattern::esc::Esc`] pattern decided, packed as bits after the plan's segments
//! and factors in the segments buffer, and checked against the preconditions the shader
//! relies on.

use super::pipelines::{ESC_GRID_WORDS, ESC_MAX_SIDE};
use crate::error::{GpuError, Result};
use tessera::criterion::esc::edge_lattice;
use tessera::criterion::Plan;
use tessera::pattern::esc::{Esc, PatchGrid};
use tessera::pattern::Pattern;
use tessera::surface::{Domain, SurfaceSet};

/// What `esc.wgsl` reads: each edge's lattice mask (bit `I` for numerator `I` of its lattice,
/// canonical direction), each patch's insertion grid ([`ESC_GRID_WORDS`] words, bit
/// `j·(3n + 1) + i` for lattice point `(i, j)`), and each patch's pattern triangles (for
/// the read-back's count of triangles left out at collapsed curves).
pub(super) struct EscData {
    pub(super) masks: Vec<u32>,
    pub(super) grids: Vec<u32>,
    pub(super) triangles: Vec<u32>,
}

fn mismatch(what: String) -> GpuError {
    tessera::Error::PlanMismatch { what }.into()
}

/// Packs `plan` and `pattern` (an [`Esc`], the criterion's pair) for the shader, checking
/// that every patch is a quad with a lattice `3n` within [`ESC_MAX_SIDE`] equal to its
/// interior factors and its grid's, that every edge's numerators rise from 0 to its lattice
/// size, and that every patch's grid holds on its boundary exactly its edges' samples (the
/// shader numbers boundary vertices from the grid, the layout from the edges).
/// Errors: [`GpuError::Unsupported`] for another pattern, [`tessera::Error::PlanMismatch`]
/// naming the edge or patch. Cost: O(E · 3n + P · (3n + 1)²).
pub(super) fn pack(set: &SurfaceSet, plan: &Plan, pattern: &dyn Pattern) -> Result<EscData> {
    let Some(esc) = pattern.as_any().and_then(|a| a.downcast_ref::<Esc>()) else {
        return Err(GpuError::Unsupported { what: format!("the {} pattern as ESC's", pattern.name()) });
    };
    let patches = set.patches.len();
    if esc.patches() != patches {
        return Err(mismatch(format!("an ESC pattern of {} patches for {patches}", esc.patches())));
    }
    let mut masks = Vec::with_capacity(plan.segments.len());
    for (e, (&s, &f)) in plan.segments.iter().zip(&plan.factors).enumerate() {
        let start = plan.lattice_offsets.get(e).copied().unwrap_or(u32::MAX) as usize;
        let numerators = plan.lattice.get(start..start.saturating_add(s as usize + 1));
        let side = f as u32;
        let rising = numerators.is_some_and(|n| {
            n.first() == Some(&0) && n.last() == Some(&side) && n.windows(2).all(|w| w[0] < w[1])
        });
        if f != side as f32 || side == 0 || side > ESC_MAX_SIDE || side % 3 != 0 || !rising {
            return Err(mismatch(format!(
                "edge {e}: lattice {f} with numerators {numerators:?} (ESC's rise from 0 to 3n ≤ {ESC_MAX_SIDE})"
            )));
        }
        masks.push(numerators.unwrap_or_default().iter().fold(0, |m, &i| m | 1 << i));
    }
    let words = ESC_GRID_WORDS as usize;
    let mut grids = vec![0u32; words * patches];
    let mut triangles = Vec::with_capacity(patches);
    for p in 0..patches {
        let grid = esc.grid(p);
        let side = grid.side();
        let quad = set.patches[p].domain() == Domain::Quad;
        if !quad || side > ESC_MAX_SIDE || plan.interior[p] != [side; 2] {
            return Err(mismatch(format!(
                "patch {p}: {} with interior factors {:?} and an ESC grid of lattice {side} (ESC takes quads, \
                 its interior factors the grid's 3n ≤ {ESC_MAX_SIDE})",
                if quad { "a quad" } else { "a triangle" },
                plan.interior[p]
            )));
        }
        for j in 0..=side {
            for i in 0..=side {
                if grid.get(i, j) {
                    let bit = (j * (side + 1) + i) as usize;
                    grids[words * p + bit / 32] |= 1 << (bit % 32);
                }
            }
        }
        for (le, pe) in set.topology.patch_edges[p].iter().enumerate() {
            let e = pe.edge as usize;
            if plan.factors[e] != side as f32 {
                return Err(mismatch(format!(
                    "patch {p}: lattice {side} on edge {e} of lattice {}",
                    plan.factors[e]
                )));
            }
            for kl in 0..=side {
                let k = if pe.reversed { side - kl } else { kl };
                let (i, j) = edge_lattice(le, kl, side);
                if grid.get(i, j) != (masks[e] >> k & 1 != 0) {
                    return Err(mismatch(format!(
                        "patch {p}: its ESC grid and edge {e}'s samples disagree at lattice point ({i}, {j})"
                    )));
                }
            }
        }
        triangles.push(esc.triangles(p));
    }
    Ok(EscData { masks, grids, triangles })
}

/// The [`Esc`] pattern of grids packed as [`pack`] packs them (`words`, [`ESC_GRID_WORDS`] a
/// patch) with each patch's lattice `3n` its interior factor. Cost: O(P · (3n + 1)²).
pub(super) fn unpack(words: &[u32], interior: &[[u32; 2]]) -> Esc {
    let per_patch = ESC_GRID_WORDS as usize;
    let grids = interior
        .iter()
        .enumerate()
        .map(|(p, &[side, _])| {
            let mut grid = PatchGrid::coarse((side / 3).max(1));
            let side = grid.side();
            for j in 0..=side {
                for i in 0..=side {
                    let bit = (j * (side + 1) + i) as usize;
                    grid.set(i, j, words[per_patch * p + bit / 32] >> (bit % 32) & 1 != 0);
                }
            }
            grid
        })
        .collect();
    Esc::new(grids)
}
