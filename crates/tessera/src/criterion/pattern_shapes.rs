//! The a-posteriori check's per-pattern data for small patterns: each pattern's triangle
//! shapes ([`TriangleShape`]), precomputed once per plan and thread and read by every
//! patch with that pattern.
//!
//! A patch's bound is the largest over its pattern's triangles of a bound that reads the
//! patch only through its [`super::bounds::TriangleErrors`] and the triangle only through its
//! shape. A frame of small patterns (the killeroo herd: 5.5 triangles a patch; the
//! Catmull-Clark torus at half a pixel: 13) has few distinct patterns and tens of thousands
//! of patches, so the shapes are kept per pattern: a patch finds its pattern's by one table
//! read (no hash, no pattern build, no parameter lookup per corner), and its bound is the
//! closed form of each shape. The shapes are in order of their longest side, largest first,
//! so that the first triangles set the running largest bound and the others stop at their
//! first, cheapest bound ([`super::bounds::TriangleErrors::shape_exceeds`]); the largest
//! bound is the same in any order.
//!
//! Written by hand: a direct-mapped table over the small inputs (an index of a few bits a
//! factor) with per-thread buffers kept from plan to plan is a few lines, and a general map
//! would hash every patch's input.

use super::bounds::TriangleShape;
use crate::domain::Domain;
use crate::pattern::cache::{boundary_params, LocalParams};
use crate::pattern::{LocalTessellation, Pattern, PatternInput};
use glam::DVec2;

/// The largest factor (edge segments and interior) of a pattern the table holds.
const LARGEST_FACTOR: u32 = 8;

/// Bits of a factor in the table's index (factors `1..=8` as `0..=7`).
const FACTOR_BITS: u32 = 3;

/// Index bits: the domain, four edges and two interior factors.
const INDEX_BITS: u32 = 1 + 6 * FACTOR_BITS;

/// A pattern's data in the table: its core grid ([`Pattern::core_cells`]) and the range of
/// its other triangles' shapes.
#[derive(Debug, Clone, Copy)]
struct Entry {
    index: u32,
    core: Option<([u32; 2], u32)>,
    shapes: (u32, u32),
}

/// One thread's patterns of one plan, by input.
#[derive(Default)]
pub(crate) struct PatternShapes {
    /// The entry of each index (stale where it does not point back at the index).
    slots: Vec<u16>,
    entries: Vec<Entry>,
    shapes: Vec<TriangleShape>,
    /// The plan the entries belong to ([`crate::pattern::cache::next_generation`]).
    generation: u64,
    local: LocalTessellation,
    params: Vec<DVec2>,
}

/// A pattern's data: its core grid's cells and triangle count, and the shapes of its other
/// triangles, largest first.
pub(crate) type Shapes<'a> = (Option<([u32; 2], u32)>, &'a [TriangleShape]);

impl PatternShapes {
    /// The table's index of `input`: None unless every factor is in `1..=8`, the factors
    /// are the integer segments, and no edge is collapsed and no corner pinched (inputs the
    /// index cannot tell apart).
    fn index(input: &PatternInput) -> Option<u32> {
        let small = |n: u32| (1..=LARGEST_FACTOR).contains(&n);
        let plain = !input.collapsed.iter().any(|&c| c) && !input.pinched.iter().any(|&p| p);
        let integer = (0..4).all(|l| input.factors[l] == input.segments[l] as f64);
        let [s0, s1, s2, s3] = input.segments;
        let factors = [s0, s1, s2, s3, input.interior[0], input.interior[1]];
        if !(plain && integer && factors.iter().all(|&n| small(n))) {
            return None;
        }
        let index =
            factors.iter().fold(u32::from(input.domain == Domain::Tri), |i, &n| i << FACTOR_BITS | (n - 1));
        Some(index)
    }

    /// The data of `input`'s pattern under `pattern` for plan `generation`, built into the
    /// table unless it is there; None for an input the table does not hold ([`Self::index`])
    /// or a pattern that depends on the patch. Cost: one table read; a pattern build, its
    /// parameters and a sort of its shapes the first time in a plan.
    pub(crate) fn get(
        &mut self,
        generation: u64,
        pattern: &dyn Pattern,
        input: &PatternInput,
    ) -> Option<Shapes<'_>> {
        let index = Self::index(input)?;
        if pattern.depends_on_patch() {
            return None;
        }
        if self.generation != generation {
            self.generation = generation;
            self.entries.clear();
            self.shapes.clear();
        }
        if self.slots.is_empty() {
            self.slots.resize(1 << INDEX_BITS, 0);
        }
        let slot = self.slots[index as usize] as usize;
        let slot = match self.entries.get(slot) {
            Some(e) if e.index == index => slot,
            _ => {
                let slot = self.entries.len();
                if slot > u16::MAX as usize {
                    return None;
                }
                self.build(pattern, input, index);
                self.slots[index as usize] = slot as u16;
                slot
            }
        };
        let e = self.entries[slot];
        Some((e.core, &self.shapes[e.shapes.0 as usize..e.shapes.1 as usize]))
    }

    /// Builds `input`'s pattern and appends its entry.
    fn build(&mut self, pattern: &dyn Pattern, input: &PatternInput, index: u32) {
        pattern.build(input, &mut self.local);
        boundary_params(input, &mut self.params);
        let params = LocalParams { boundary: &self.params, interior: &self.local.interior };
        let core = pattern.core_cells(input);
        let start = self.shapes.len();
        let rest = super::tolerance::after_core(core, &self.local.triangles);
        self.shapes.extend(rest.iter().map(|t| TriangleShape::of(t.map(|l| params.get(l)))));
        self.shapes[start..].sort_by(|a, b| b.longest_side_squared().total_cmp(&a.longest_side_squared()));
        let shapes = (start as u32, self.shapes.len() as u32);
        self.entries.push(Entry { index, core, shapes });
    }
}

thread_local! {
    static SHAPES: std::cell::RefCell<PatternShapes> = std::cell::RefCell::new(PatternShapes::default());
}

/// Runs `f` with this thread's table (a fresh one if the thread's is in use further up its
/// stack, as when rayon runs another task inside a join).
pub(crate) fn with_pattern_shapes<R>(f: impl FnOnce(&mut PatternShapes) -> R) -> R {
    SHAPES.with(|cell| match cell.try_borrow_mut() {
        Ok(mut shapes) => f(&mut shapes),
        Err(_) => f(&mut PatternShapes::default()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::bounds::HessianBound;
    use crate::pattern::transition::Transition;

    /// Every small input of both domains gets its own entry, and the entry's core and
    /// shapes are the pattern's: the core's cells as the pattern gives them, and the
    /// other triangles' shapes, as a multiset, with the largest first.
    #[test]
    fn each_small_input_reads_its_own_patterns_shapes() {
        let mut table = PatternShapes::default();
        let mut seen = std::collections::HashSet::new();
        let mut inputs = Vec::new();
        for a in 1..=LARGEST_FACTOR {
            for b in [1, 3, 8] {
                for c in [2, 5] {
                    inputs.push(PatternInput::new(Domain::Tri, [a, b, c, 1], [a.max(b).max(c); 2]));
                    inputs.push(PatternInput::new(Domain::Quad, [a, b, c, 4], [a.min(c), b.min(4)]));
                }
            }
        }
        for (round, input) in inputs.iter().chain(&inputs).enumerate() {
            let index = PatternShapes::index(input).expect("small");
            if round < inputs.len() {
                assert!(seen.insert(index), "{input:?} shares index {index}");
            }
            let (core, shapes) = table.get(1, &Transition, input).expect("held");
            assert_eq!(core, Transition.core_cells(input), "{input:?}");
            let mut built = LocalTessellation::default();
            Transition.build(input, &mut built);
            let mut params = Vec::new();
            boundary_params(input, &mut params);
            let params = LocalParams { boundary: &params, interior: &built.interior };
            let rest = crate::criterion::tolerance::after_core(core, &built.triangles);
            let mut expected: Vec<_> =
                rest.iter().map(|t| TriangleShape::of(t.map(|l| params.get(l)))).collect();
            assert_eq!(shapes.len(), expected.len(), "{input:?}");
            for s in shapes {
                let at = expected.iter().position(|e| e == s).expect("a shape of the pattern");
                expected.swap_remove(at);
            }
            let longest: Vec<f64> = shapes.iter().map(|s| s.longest_side_squared()).collect();
            assert!(longest.windows(2).all(|w| w[0] >= w[1]), "{input:?}: not largest first");
        }
        // The entries belong to their plan: another generation builds them again.
        let input = &inputs[3];
        let before = table.entries.len();
        table.get(2, &Transition, input).expect("held");
        assert_eq!(table.entries.len(), 1, "a new plan starts an empty table (was {before})");
        let m = HessianBound { uu: 3.0, uv: 1.0, vv: 2.0 }.triangle_errors();
        assert!(table
            .get(2, &Transition, input)
            .unwrap()
            .1
            .iter()
            .all(|s| m.shape_exceeds(s, -1.0).is_some()));
    }

    /// Inputs the index cannot tell apart are not held: large factors, fractional factors,
    /// collapsed edges, pinched corners.
    #[test]
    fn inputs_outside_the_index_are_not_held() {
        let mut table = PatternShapes::default();
        let plain = PatternInput::new(Domain::Quad, [2, 3, 2, 3], [2, 3]);
        assert!(table.get(1, &Transition, &plain).is_some());
        let large = PatternInput::new(Domain::Quad, [9, 3, 2, 3], [2, 3]);
        let fractional = PatternInput { factors: [2.5, 3.0, 2.0, 3.0], ..plain };
        let collapsed = PatternInput { collapsed: [false, true, false, false], ..plain };
        let pinched = PatternInput { pinched: [false, false, true, false], ..plain };
        for input in [large, fractional, collapsed, pinched] {
            assert!(table.get(1, &Transition, &input).is_none(), "{input:?}");
        }
    }
}
