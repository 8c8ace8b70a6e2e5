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
//! Larger patterns are kept by their slot in the check's pattern table
//! ([`crate::pattern::cache::PatternCache`], which holds each distinct first pattern once),
//! from the second patch of that slot a thread checks: a frame of a few large patterns
//! repeated (the torus at 0.001 % of its diagonal: 18 patterns of about 214 triangles for
//! 2,048 patches) then looks up no parameter and forms no shape per patch, while a frame
//! whose patterns are all distinct pays nothing but a mark per slot.
//!
//! Written by hand: a direct-mapped table over the small inputs (an index of a few bits a
//! factor) with per-thread buffers kept from plan to plan is a few lines, and a general map
//! would hash every patch's input.

use super::bounds::TriangleShape;
use crate::pattern::cache::{boundary_params, small_input_index, Cached, LocalParams, SmallInputTable};
use crate::pattern::{LocalTessellation, Pattern, PatternInput};
use glam::DVec2;

/// What the check reads of a pattern: whether it is a grid, else its core grid and its
/// other triangles' shapes.
#[derive(Debug, Default)]
pub(crate) struct PatternData {
    /// [`Pattern::grid_cells`]: a grid's bound is its cells', and nothing else is kept.
    pub(crate) grid: Option<[u32; 2]>,
    /// [`Pattern::counts`].
    pub(crate) counts: (u32, u32),
    /// [`Pattern::core_cells`].
    pub(crate) core: Option<([u32; 2], u32)>,
    /// The shapes of the triangles after the core, largest first.
    pub(crate) shapes: Vec<TriangleShape>,
}

/// One thread's patterns of one plan, by input.
#[derive(Default)]
pub(crate) struct PatternShapes {
    table: SmallInputTable<PatternData>,
    /// Per slot of the check's pattern table, the call that last checked a patch of it on
    /// this thread, whether its data was made in that call, and the data.
    slots: Vec<(u64, bool, PatternData)>,
    /// Buffers of a build.
    local: LocalTessellation,
    params: Vec<DVec2>,
}

/// A patch's pattern as the check's pattern table holds it ([`PatternCache::params`]): the
/// pattern, its local vertices' parameters and its slot.
///
/// [`PatternCache::params`]: crate::pattern::cache::PatternCache::params
pub(crate) type CachedPattern<'a> = (Cached<'a>, LocalParams<'a>, usize);

impl PatternShapes {
    /// The data of `input`'s pattern under `pattern` for plan `generation`, made unless the
    /// table has it; None for a pattern that depends on the patch, and for an input the
    /// small table does not hold ([`small_input_index`]) unless the check's pattern table
    /// holds it (`cached()`, asked only then) and this thread checked another patch of that
    /// slot in this call.
    /// Cost: a table read; the first time in a plan, a grid test, or a pattern build (from
    /// `cached`: none), its parameters and a sort of its shapes.
    pub(crate) fn get<'c>(
        &mut self,
        generation: u64,
        pattern: &dyn Pattern,
        input: &PatternInput,
        cached: impl FnOnce() -> Option<CachedPattern<'c>>,
    ) -> Option<&PatternData> {
        if pattern.depends_on_patch() {
            return None;
        }
        let Some(index) = small_input_index(input) else {
            let (cached, params, slot) = cached()?;
            return self.of_slot(generation, pattern, cached, params, slot);
        };
        let PatternShapes { table, local, params, .. } = self;
        let data = table.get_or_build(generation, index, |data: &mut PatternData| {
            data.grid = pattern.grid_cells(input);
            data.counts = pattern.counts(input);
            data.core = None;
            data.shapes.clear();
            if data.grid.is_some() {
                return;
            }
            pattern.build(input, local);
            boundary_params(input, params);
            let params = LocalParams { boundary: params, interior: &local.interior };
            data.core = pattern.core_cells(input);
            let rest = super::tolerance::after_core(data.core, &local.triangles);
            data.set_shapes(rest, params);
        })?;
        Some(data)
    }

    /// [`PatternShapes::get`] of a pattern the check's table holds in `slot` (`cached`, its
    /// local parameters `params`): None the first time this thread sees the slot in call
    /// `generation` (most slots of a frame of distinct patterns are seen once), the data,
    /// made from `cached`, from the second time on. Cost: a read; the second time, the grid
    /// test, counts, and the shapes of the triangles after the core and their sort.
    fn of_slot(
        &mut self,
        generation: u64,
        pattern: &dyn Pattern,
        cached: Cached<'_>,
        params: LocalParams<'_>,
        slot: usize,
    ) -> Option<&PatternData> {
        if self.slots.len() <= slot {
            self.slots.resize_with(slot + 1, Default::default);
        }
        let (seen, made, data) = &mut self.slots[slot];
        if *seen != generation {
            (*seen, *made) = (generation, false);
            return None;
        }
        if !*made {
            *made = true;
            let input = cached.input;
            data.grid = pattern.grid_cells(input);
            data.counts = pattern.counts(input);
            data.core = None;
            data.shapes.clear();
            if data.grid.is_none() {
                data.core = pattern.core_cells(input);
                // The cache leaves out the triangles of a core grid.
                let rest = match cached.core {
                    Some(_) => &cached.local.triangles[..],
                    None => super::tolerance::after_core(data.core, &cached.local.triangles),
                };
                data.set_shapes(rest, params);
            }
        }
        Some(data)
    }
}

impl PatternData {
    /// The shapes of `triangles` (local vertices, parameters `params`), largest first.
    fn set_shapes(&mut self, triangles: &[[u32; 3]], params: LocalParams<'_>) {
        self.shapes.extend(triangles.iter().map(|t| TriangleShape::of(t.map(|l| params.get(l)))));
        // Unstable: a stable sort allocates its scratch, and the order of equal keys does not
        // change the largest bound.
        self.shapes.sort_unstable_by(|a, b| b.longest_side_squared().total_cmp(&a.longest_side_squared()));
    }
}

thread_local! {
    static SHAPES: std::cell::RefCell<PatternShapes> = std::cell::RefCell::new(PatternShapes::default());
}

/// Runs `f` with this thread's table (a fresh one if the thread's is in use further up its
/// stack, as when rayon runs another task inside a join).
pub(crate) fn with_pattern_shapes<R>(f: impl FnOnce(&mut PatternShapes) -> R) -> R {
    crate::pattern::cache::with_thread_table(&SHAPES, f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::criterion::bounds::HessianBound;
    use crate::domain::Domain;
    use crate::pattern::transition::Transition;

    /// Asserts that `got` is `input`'s pattern's data: the core's cells as the pattern
    /// gives them, and the other triangles' shapes, as a multiset, largest first.
    fn assert_shapes_of(input: &PatternInput, data: &PatternData) {
        assert_eq!(data.grid, Transition.grid_cells(input), "{input:?}");
        assert_eq!(data.counts, Transition.counts(input), "{input:?}");
        if data.grid.is_some() {
            assert!(data.core.is_none() && data.shapes.is_empty(), "{input:?}: a grid keeps nothing else");
            return;
        }
        let (core, shapes) = (data.core, &data.shapes[..]);
        assert_eq!(core, Transition.core_cells(input), "{input:?}");
        let mut built = LocalTessellation::default();
        Transition.build(input, &mut built);
        let mut params = Vec::new();
        boundary_params(input, &mut params);
        let params = LocalParams { boundary: &params, interior: &built.interior };
        let rest = crate::criterion::tolerance::after_core(core, &built.triangles);
        let mut expected: Vec<_> = rest.iter().map(|t| TriangleShape::of(t.map(|l| params.get(l)))).collect();
        assert_eq!(shapes.len(), expected.len(), "{input:?}");
        for s in shapes {
            let at = expected.iter().position(|e| e == s).expect("a shape of the pattern");
            expected.swap_remove(at);
        }
        let longest: Vec<f64> = shapes.iter().map(|s| s.longest_side_squared()).collect();
        assert!(longest.windows(2).all(|w| w[0] >= w[1]), "{input:?}: not largest first");
    }

    /// Every small input of both domains gets its own entry, the first time and again; a
    /// later plan's entries take the places of an earlier plan's, and none reads another's.
    #[test]
    fn each_small_input_reads_its_own_patterns_shapes() {
        let mut table = PatternShapes::default();
        let mut seen = std::collections::HashSet::new();
        let mut inputs = Vec::new();
        for a in 1..=8 {
            for b in [1, 3, 8] {
                for c in [2, 5] {
                    inputs.push(PatternInput::new(Domain::Tri, [a, b, c, 1], [a.max(b).max(c); 2]));
                    inputs.push(PatternInput::new(Domain::Quad, [a, b, c, 4], [a.min(c), b.min(4)]));
                }
            }
            // Grids: every edge as its interior.
            inputs.push(PatternInput::new(Domain::Tri, [a, a, a, 1], [a; 2]));
            inputs.push(PatternInput::new(Domain::Quad, [a, 9 - a, a, 9 - a], [a, 9 - a]));
        }
        for (round, input) in inputs.iter().chain(&inputs).enumerate() {
            let index = small_input_index(input).expect("small");
            if round < inputs.len() {
                assert!(seen.insert(index), "{input:?} shares index {index}");
            }
            assert_shapes_of(input, table.get(1, &Transition, input, || None).expect("held"));
        }
        // The next plan, in another order: each input's entry now sits where another's
        // was in the first plan.
        for input in inputs.iter().rev() {
            assert_shapes_of(input, table.get(2, &Transition, input, || None).expect("held"));
        }
        let m = HessianBound { uu: 3.0, uv: 1.0, vv: 2.0 }.triangle_errors();
        let shapes = &table.get(2, &Transition, &inputs[5], || None).expect("held").shapes;
        assert!(!shapes.is_empty() && shapes.iter().all(|s| m.shape_exceeds(s, -1.0).is_some()));
        let grids =
            inputs.iter().filter(|i| table.get(2, &Transition, i, || None).unwrap().grid.is_some()).count();
        assert!(grids > 0 && grids < inputs.len(), "{grids} grids: both kinds are tested");
    }

    /// Inputs past the small table are kept by their slot in the check's pattern table: not
    /// on a thread's first patch of the slot in a call, and from its second on with the
    /// pattern's own data (a grid, or the core and the other triangles' shapes), in every
    /// later call alike.
    #[test]
    fn large_patterns_are_kept_by_slot_from_their_second_patch() {
        let inputs = [
            PatternInput::new(Domain::Quad, [12, 9, 11, 10], [12, 9]),
            PatternInput::new(Domain::Quad, [16, 16, 16, 16], [16, 16]),
            PatternInput::new(Domain::Tri, [9, 11, 10, 1], [11, 11]),
            PatternInput::new(Domain::Quad, [3, 20, 5, 9], [4, 20]),
        ];
        let n = inputs.len();
        assert!(inputs.iter().all(|i| small_input_index(i).is_none()), "all past the small table");
        let mut cache = crate::pattern::cache::PatternCache::default();
        cache.fill_inputs(&Transition, 2 * n, |i| Some(inputs[i % n]), true);
        let mut table = PatternShapes::default();
        let mut grids = 0;
        for generation in [1, 2] {
            for i in 0..2 * n {
                let cached = cache.params(i).expect("filled with parameters");
                let data = table.get(generation, &Transition, &inputs[i % n], || Some(cached));
                if i < n {
                    assert!(data.is_none(), "{:?}: the slot's first patch", inputs[i % n]);
                } else {
                    let data = data.expect("the slot's second patch");
                    grids += usize::from(data.grid.is_some());
                    assert_shapes_of(&inputs[i % n], data);
                }
            }
        }
        assert!(grids > 0 && grids < 2 * n, "{grids} grids: both kinds are tested");
    }

    /// Inputs the index cannot tell apart are not held: large factors, fractional factors,
    /// collapsed edges, pinched corners.
    #[test]
    fn inputs_outside_the_index_are_not_held() {
        let mut table = PatternShapes::default();
        let plain = PatternInput::new(Domain::Quad, [2, 3, 2, 3], [2, 3]);
        assert!(table.get(1, &Transition, &plain, || None).is_some());
        let large = PatternInput::new(Domain::Quad, [9, 3, 2, 3], [2, 3]);
        let fractional = PatternInput { factors: [2.5, 3.0, 2.0, 3.0], ..plain };
        let collapsed = PatternInput { collapsed: [false, true, false, false], ..plain };
        let pinched = PatternInput { pinched: [false, false, true, false], ..plain };
        for input in [large, fractional, collapsed, pinched] {
            assert!(table.get(1, &Transition, &input, || None).is_none(), "{input:?}");
        }
    }
}
