//! Patterns that repeat, built once. [`PatternCache`]: a table from each distinct pattern input
//! (the edge segments and factors, interior factors and collapsed edges of a patch) to its
//! built pattern, as the semi-uniform render queues keep one pattern per level and the
//! hardware tessellator one table per factor combination.
//!
//! Without it, the writer builds a pattern per visible patch and reuses it only for the next
//! patch of the same input on the same thread; in an adaptive frame neighbours differ, and
//! building is a large part of writing (CudaTess's transition strips, the hardware patterns'
//! rings). With it, the distinct inputs are found in one pass over the patches, built in
//! parallel, and every patch reads its pattern by index. [`RecentPatterns`]: the patterns one
//! thread built lately, for the writers and the a-posteriori error check, which meet inputs in
//! patch order and often the same input twice running.
//!
//! **No allocation in a steady frame loop.** The table, the index and each slot's buffers keep
//! their capacity from frame to frame. Inputs get slots in patch order, so the same sequence of
//! frames fills the same slots with the same patterns: a second walk along a camera path
//! allocates nothing, whichever threads built what.

use super::{CoreGrid, LocalTessellation, Pattern, PatternInput};
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// The bits of a pattern input that a pattern may read (everything but the patch index).
#[derive(Clone, Copy, PartialEq, Eq)]
struct Key {
    segments: [u32; 4],
    interior: [u32; 2],
    factors: [u64; 4],
    /// Collapsed edges (bits 0–3), domain (bit 4) and pinched corners (bits 8–11).
    flags: u16,
}

/// A hash of the bits of `input` a pattern may read (not the patch), for tables keyed by
/// pattern input ([`PatternCache`], [`RecentPatterns`]).
pub(crate) fn input_hash(input: &PatternInput) -> u64 {
    use std::hash::{BuildHasher, BuildHasherDefault};
    BuildHasherDefault::<WordHasher>::default().hash_one(Key::of(input))
}

impl std::hash::Hash for Key {
    /// Eight words, without the length prefixes and byte chunks the derived hash of the
    /// arrays writes: the key is hashed once per visible patch per frame.
    fn hash<H: Hasher>(&self, state: &mut H) {
        let pair = |a: u32, b: u32| a as u64 | (b as u64) << 32;
        let [s0, s1, s2, s3] = self.segments;
        state.write_u64(pair(s0, s1));
        state.write_u64(pair(s2, s3));
        state.write_u64(pair(self.interior[0], self.interior[1]));
        for f in self.factors {
            state.write_u64(f);
        }
        state.write_u64(self.flags as u64);
    }
}

impl Key {
    fn of(input: &PatternInput) -> Key {
        let bits = |set: &[bool; 4]| set.iter().enumerate().fold(0u16, |m, (e, &c)| m | (u16::from(c) << e));
        Key {
            segments: input.segments,
            interior: input.interior,
            factors: input.factors.map(f64::to_bits),
            flags: bits(&input.collapsed)
                | (u16::from(input.domain == crate::domain::Domain::Quad) << 4)
                | (bits(&input.pinched) << 8),
        }
    }
}

/// A multiply-rotate hash of the key's words. The standard library's SipHash resists
/// adversarial keys, which these are not, at several times the cost per lookup; the key is
/// hashed once per patch per frame, so it matters. (The field's hashers — FxHash and kin — are
/// not among this project's dependencies; this is their few lines.)
#[derive(Default)]
pub(crate) struct WordHasher(u64);

/// A hash map keyed by small integer keys through [`WordHasher`] (the library's other
/// hot lookups: a cage's edges, a refinement's child vertices).
pub(crate) type WordMap<K, V> = HashMap<K, V, BuildHasherDefault<WordHasher>>;

impl Hasher for WordHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u8(&mut self, x: u8) {
        self.write_u64(x as u64);
    }

    fn write_u32(&mut self, x: u32) {
        self.write_u64(x as u64);
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
}

/// Patch `p` has no cached pattern (invisible, or the pattern depends on the patch).
const NONE: u32 = u32::MAX;

/// Below this many triangles per visible patch on average, patterns are small enough that
/// building one costs about what finding it in the table costs, and the cache stays off.
pub(crate) const MIN_TRIANGLES_PER_PATCH: u32 = 24;

/// The frame's distinct patterns. See the [module documentation](self).
#[derive(Default)]
pub(crate) struct PatternCache {
    index: HashMap<Key, u32, BuildHasherDefault<WordHasher>>,
    /// The input of each slot in use (`inputs.len()` slots), its patch index the first
    /// patch's.
    inputs: Vec<PatternInput>,
    /// Every slot ever used; slots past `inputs.len()` keep their buffers for later frames.
    /// A slot holds [`Pattern::build_after_core`]: a pattern with a [`Pattern::core_grid`]
    /// without its core's triangles (`cores`), which the writer writes by the rule.
    slots: Vec<LocalTessellation>,
    /// Per slot in use, the pattern's core grid, whose triangles its slot leaves out.
    cores: Vec<Option<CoreGrid>>,
    /// Each patch's slot, or [`NONE`]; empty when the cache is off for the frame.
    of_patch: Vec<u32>,
    /// Per slot, the positions in the flat index list (`triangles.as_flattened()`) of the
    /// pattern's boundary vertices (corners and edge samples); see [`boundary_positions`].
    boundary: Vec<Vec<u32>>,
    /// Per slot, the parameters of the pattern's boundary vertices ([`boundary_params`],
    /// filled on request).
    params: Vec<Vec<DVec2>>,
    /// Per slot in use, whether `params` holds its table.
    has_params: Vec<bool>,
    /// Per slot in use, the index in `grids` of its core grid's points, which its slot
    /// leaves out ([`Pattern::build_after_core`]), or [`NONE`]: the slot's own list.
    interiors: Vec<u32>,
    /// The interior points of each distinct core grid of the frame ([`CoreGrid::interior_points`]),
    /// `grid_of.len()` in use; the others keep their buffers for later frames.
    grids: Vec<Vec<DVec2>>,
    /// Each distinct core grid's index in `grids`, by its cells (`nu << 32 | nv`).
    grid_of: WordMap<u64, u32>,
    /// The cells of each grid in use, in `grids`' order.
    grid_cells: Vec<[u32; 2]>,
    /// The chunks of [`PatternCache::extend_inputs`]' parallel pass.
    chunks: Vec<ChunkInputs>,
}

/// The parameters of every local vertex of `built` (made for `input`), in local order:
/// corners, each edge's inner samples at `k / n`, the interior. Cost: O(vertices).
pub(crate) fn local_params(input: &PatternInput, built: &LocalTessellation, params: &mut Vec<DVec2>) {
    boundary_params(input, params);
    params.extend_from_slice(&built.interior);
}

/// The parameters of the boundary vertices of a pattern for `input`, in local order: corners,
/// then each edge's inner samples at `k / n` — with the pattern's interior list
/// ([`LocalParams`]) the table the a-posteriori error check evaluates triangles on
/// (`criterion::tolerance`), computed once per distinct pattern instead of once per patch.
/// Cost: O(boundary vertices).
pub(crate) fn boundary_params(input: &PatternInput, params: &mut Vec<DVec2>) {
    let d = input.domain;
    let nc = d.corner_count();
    params.clear();
    params.extend((0..nc).map(|c| d.corner(c)));
    for e in 0..nc {
        let n = input.segments[e];
        params.extend((1..n).map(|k| d.edge_point(e, k as f64 / n as f64)));
    }
}

/// The parameter of every local vertex of a pattern, without copying its interior: the
/// boundary vertices' table ([`boundary_params`]) and the pattern's interior list.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalParams<'a> {
    pub(crate) boundary: &'a [DVec2],
    pub(crate) interior: &'a [DVec2],
}

impl LocalParams<'_> {
    /// The parameter of local vertex `l`. Cost: O(1).
    #[inline(always)]
    pub(crate) fn get(&self, l: u32) -> DVec2 {
        let l = l as usize;
        match self.boundary.get(l) {
            Some(&p) => p,
            None => self.interior[l - self.boundary.len()],
        }
    }
}

/// The positions in `built`'s flat index list whose local vertex is a boundary vertex (below
/// `input.interior_base()`). A writer maps every index by one addition — interior vertices
/// are numbered alike locally and in the output — and then corrects only these positions
/// through the patch's table: the addition vectorizes, and a fine pattern has few boundary
/// indices. Cost: O(triangles).
pub(crate) fn boundary_positions(input: &PatternInput, built: &LocalTessellation, out: &mut Vec<u32>) {
    let first = input.interior_base();
    out.clear();
    let flat = built.triangles.as_flattened();
    out.extend((0..flat.len() as u32).filter(|&i| flat[i as usize] < first));
}

impl PatternCache {
    /// Empties the cache: every [`PatternCache::get`] answers None.
    pub(crate) fn clear(&mut self) {
        self.index.clear();
        self.inputs.clear();
        self.cores.clear();
        self.has_params.clear();
        self.of_patch.clear();
        self.interiors.clear();
        self.grid_of.clear();
        self.grid_cells.clear();
    }

    /// Forgets which item has which pattern (every [`PatternCache::get`] answers None) but
    /// keeps the patterns for a later [`PatternCache::extend_inputs`].
    pub(crate) fn forget_items(&mut self) {
        self.of_patch.clear();
    }

    /// Fills the cache for items `0..count` with the inputs `input_of(i)` (None: no pattern
    /// for item `i`), building each distinct input once; with `params`, also the parameters of
    /// every local vertex of each pattern (the a-posteriori check's table, see
    /// [`PatternCache::params`]). Precondition: the pattern does not depend on the patch.
    /// Cost: one hash lookup per item (parallel), one per chunk's distinct input
    /// (sequential), then the distinct builds (parallel).
    pub(crate) fn fill_inputs(
        &mut self,
        pattern: &dyn Pattern,
        count: usize,
        input_of: impl Fn(usize) -> Option<PatternInput> + Sync,
        params: bool,
    ) {
        self.clear();
        self.extend_inputs(pattern, count, input_of, params);
    }

    /// [`PatternCache::fill_inputs`] keeping the patterns the cache holds: only inputs new
    /// to it are built (and, with `params`, the parameter tables it lacks). For a second use
    /// of one frame's patterns with the same pattern (the engine's write after the
    /// a-posteriori check, which built most of them): the key is every bit of the input a
    /// pattern reads, so a kept pattern is the one a build would make.
    /// Precondition: the cache was filled for `pattern`, which does not depend on the patch.
    /// Cost: one hash lookup per item (parallel), one per chunk's distinct input
    /// (sequential), then the new builds (parallel).
    pub(crate) fn extend_inputs(
        &mut self,
        pattern: &dyn Pattern,
        count: usize,
        input_of: impl Fn(usize) -> Option<PatternInput> + Sync,
        params: bool,
    ) {
        debug_assert!(!pattern.depends_on_patch());
        let (kept, kept_grids) = (self.inputs.len(), self.grid_cells.len());
        // Each chunk's distinct inputs in parallel, in the order they first occur, and each
        // item's place among its chunk's (`of_patch` holds those places meanwhile).
        let chunks = count.div_ceil(DEDUP_CHUNK);
        if self.chunks.len() < chunks {
            self.chunks.resize_with(chunks, ChunkInputs::default);
        }
        self.of_patch.resize(count, NONE);
        let parts = self.of_patch.par_chunks_mut(DEDUP_CHUNK).zip(&mut self.chunks[..chunks]).enumerate();
        parts.for_each(|(c, (places, chunk))| chunk.find(c * DEDUP_CHUNK, places, &input_of));
        // Then the table's slots, chunk after chunk: the slots of the sequential pass (the
        // inputs in the order they first occur), a lookup per chunk's distinct input.
        for c in 0..chunks {
            let chunk = &mut self.chunks[c];
            chunk.slots.clear();
            for &(key, input) in &chunk.distinct {
                let next = self.inputs.len() as u32;
                let slot = *self.index.entry(key).or_insert(next);
                if slot == next {
                    let core = pattern.core_grid(&input);
                    self.inputs.push(input);
                    self.cores.push(core);
                    let interior =
                        core.map_or(NONE, |core| grid_index(&mut self.grid_of, &mut self.grid_cells, core));
                    self.interiors.push(interior);
                }
                chunk.slots.push(slot);
            }
        }
        // Each item's slot from its place in its chunk.
        let parts = self.of_patch.par_chunks_mut(DEDUP_CHUNK).zip(&self.chunks[..chunks]);
        parts.for_each(|(places, chunk)| {
            for place in places.iter_mut().filter(|p| **p != NONE) {
                *place = chunk.slots[*place as usize];
            }
        });
        // The new grids' points, in parallel with each other (a few a frame are large).
        let grids = self.grid_cells.len();
        if self.grids.len() < grids {
            self.grids.resize_with(grids, Vec::new);
        }
        let new_grids =
            (&mut self.grids[kept_grids..grids]).into_par_iter().zip(&self.grid_cells[kept_grids..grids]);
        new_grids.for_each(|(points, &cells)| {
            points.clear();
            super::core_grid::grid_interior(cells, points);
        });
        let used = self.inputs.len();
        if self.slots.len() < used {
            self.slots.resize_with(used, LocalTessellation::default);
        }
        if self.boundary.len() < used {
            self.boundary.resize_with(used, Vec::new);
        }
        if params && self.params.len() < used {
            self.params.resize_with(used, Vec::new);
        }
        self.has_params.resize(used, false);
        let new = (&mut self.slots[kept..used]).into_par_iter().zip(&self.inputs[kept..used]);
        let new = new.zip(&mut self.boundary[kept..used]);
        if params {
            let new_params =
                (&mut self.params[kept..used]).into_par_iter().zip(&mut self.has_params[kept..used]);
            new.zip(new_params).with_min_len(4).for_each(|(((local, input), boundary), (params, has))| {
                pattern.build_after_core(input, local);
                boundary_positions(input, local, boundary);
                boundary_params(input, params);
                *has = true;
            });
            // Kept patterns built without their tables (none in the check's own rounds).
            let kept_params = (&mut self.params[..kept]).into_par_iter().zip(&mut self.has_params[..kept]);
            kept_params.zip(&self.inputs[..kept]).with_min_len(16).for_each(|((params, has), input)| {
                if !*has {
                    boundary_params(input, params);
                    *has = true;
                }
            });
        } else {
            new.with_min_len(4).for_each(|((local, input), boundary)| {
                pattern.build_after_core(input, local);
                boundary_positions(input, local, boundary);
            });
        }
    }

    /// Patch `p`'s pattern input, pattern and the pattern's [`boundary_positions`], when the
    /// cache holds them for this frame (the input's `patch` is the first patch's of that
    /// input: set it to `p`).
    pub(crate) fn get(&self, p: usize) -> Option<Cached<'_>> {
        let slot = *self.of_patch.get(p)? as usize;
        (slot != NONE as usize).then(|| Cached {
            input: &self.inputs[slot],
            local: &self.slots[slot],
            interior: match self.interiors[slot] {
                NONE => &self.slots[slot].interior,
                grid => &self.grids[grid as usize],
            },
            boundary: &self.boundary[slot],
            core: self.cores[slot],
        })
    }

    /// Item `i`'s pattern and its local vertices' parameters, when the last
    /// [`PatternCache::fill_inputs`] made them (with `params`), with the pattern's slot (the
    /// same for every item of that input until the cache is cleared).
    pub(crate) fn params(&self, i: usize) -> Option<(Cached<'_>, LocalParams<'_>, usize)> {
        let slot = *self.of_patch.get(i)? as usize;
        (slot != NONE as usize && self.has_params[slot]).then(|| {
            let cached = self.get(i).expect("the slot is in use");
            (cached, LocalParams { boundary: &self.params[slot], interior: cached.interior }, slot)
        })
    }

    /// How many distinct patterns this frame built (0 when the cache is off).
    #[cfg(test)]
    pub(crate) fn distinct(&self) -> usize {
        self.inputs.len()
    }
}

/// The index in a cache's `grids` of `core`'s grid points ([`CoreGrid::interior_points`]), a
/// new one where the frame has no such grid yet (`grid_of` and `grid_cells`: the cache's; its
/// points made after the inputs' pass, [`PatternCache::extend_inputs`]). Cost: O(1).
fn grid_index(grid_of: &mut WordMap<u64, u32>, grid_cells: &mut Vec<[u32; 2]>, core: CoreGrid) -> u32 {
    let [nu, nv] = core.cells;
    let next = grid_of.len() as u32;
    let index = *grid_of.entry((nu as u64) << 32 | nv as u64).or_insert(next);
    if index == next {
        grid_cells.push(core.cells);
    }
    index
}

/// Items a task of [`PatternCache::extend_inputs`]' parallel pass takes.
const DEDUP_CHUNK: usize = 512;

/// One chunk of items in [`PatternCache::extend_inputs`]: its distinct inputs, then their
/// slots in the table. Kept from call to call (its buffers and map keep their capacity).
#[derive(Default)]
struct ChunkInputs {
    /// The chunk's distinct inputs by key, in the order they first occur.
    distinct: Vec<(Key, PatternInput)>,
    /// Each distinct key's place in `distinct`.
    places: WordMap<Key, u32>,
    /// The same for the inputs [`small_input_index`] numbers, by that number: one word to
    /// hash and compare instead of the key's eight (the cow's adaptive frames have only
    /// such inputs).
    small_places: WordMap<u32, u32>,
    /// Each distinct input's slot in the table (`distinct`'s order).
    slots: Vec<u32>,
}

impl ChunkInputs {
    /// Finds the distinct inputs of items `first ..` (one per element of `places`) and writes
    /// each item's place among them into `places` ([`NONE`] for an item without an input).
    fn find(
        &mut self,
        first: usize,
        places: &mut [u32],
        input_of: &(impl Fn(usize) -> Option<PatternInput> + Sync),
    ) {
        self.distinct.clear();
        self.places.clear();
        self.small_places.clear();
        // Neighbouring items often share an input: a comparison with the last key costs
        // less than the hash and the probe.
        let mut last: Option<(Key, u32)> = None;
        let mut last_small: Option<(u32, u32)> = None;
        for (k, place) in places.iter_mut().enumerate() {
            let Some(input) = input_of(first + k) else {
                *place = NONE;
                continue;
            };
            // Equal small numbers are equal keys and the other way round, and no other key
            // equals one with a small number: the two maps share out the inputs.
            *place = match small_input_index(&input) {
                Some(index) => {
                    place_of(&mut self.small_places, &mut last_small, index, &mut self.distinct, &input)
                }
                None => place_of(&mut self.places, &mut last, Key::of(&input), &mut self.distinct, &input),
            };
        }
    }
}

/// The place of `input` (by `key`) among a chunk's `distinct` inputs, added there where it is
/// new: the previous item's place where its key was the same (`last`), else by the map.
// Inlined: it runs once per item, and called it cost the cow's frames 3 %.
#[inline(always)]
fn place_of<K: Copy + Eq + std::hash::Hash>(
    places: &mut WordMap<K, u32>,
    last: &mut Option<(K, u32)>,
    key: K,
    distinct: &mut Vec<(Key, PatternInput)>,
    input: &PatternInput,
) -> u32 {
    if let Some((_, at)) = last.filter(|(seen, _)| *seen == key) {
        return at;
    }
    let next = distinct.len() as u32;
    let at = *places.entry(key).or_insert(next);
    if at == next {
        distinct.push((Key::of(input), *input));
    }
    *last = Some((key, at));
    at
}

/// A pattern in the cache ([`PatternCache::get`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cached<'a> {
    /// The input it was built for (its `patch` the first patch's of that input).
    pub(crate) input: &'a PatternInput,
    /// [`Pattern::build_after_core`]: the triangles after the core (and the interior
    /// vertices where there is no core: read `interior`).
    pub(crate) local: &'a LocalTessellation,
    /// The pattern's interior vertices: the core grid's points (shared by every pattern
    /// with that grid) or the slot's own.
    pub(crate) interior: &'a [DVec2],
    /// The [`boundary_positions`] of `local`'s triangles.
    pub(crate) boundary: &'a [u32],
    /// The core grid whose triangles `local` leaves out, where the pattern has one.
    pub(crate) core: Option<CoreGrid>,
}

impl Cached<'_> {
    /// The pattern's triangles after the core, and how many core triangles come before them.
    pub(crate) fn after_core(&self) -> (&[[u32; 3]], u32) {
        (&self.local.triangles, self.core.map_or(0, |c| c.triangle_count()))
    }
}

/// The largest factor (edge segments and interior) of an input [`small_input_index`] numbers.
const SMALL_INPUT_FACTOR: u32 = 8;

/// Bits of a factor in [`small_input_index`] (factors `1..=8` as `0..=7`).
const SMALL_FACTOR_BITS: u32 = 3;

/// Bits of [`small_input_index`]: the domain, four edges and two interior factors.
const SMALL_INPUT_INDEX_BITS: u32 = 1 + 6 * SMALL_FACTOR_BITS;

/// A number below `2^SMALL_INPUT_INDEX_BITS` for each input of a small pattern, the same for
/// inputs that differ only in their patch: a table of small patterns is then a direct read,
/// no hash. None unless every factor is in `1..=8`, the factors are the integer segments,
/// and no edge is collapsed and no corner pinched (what the number cannot tell apart).
/// Cost: O(1).
#[inline]
pub(crate) fn small_input_index(input: &PatternInput) -> Option<u32> {
    // Branch-free tests: every patch of a frame asks, once in the check and once in the
    // engine.
    let flags = |b: [bool; 4]| u32::from_ne_bytes(b.map(u8::from));
    let plain = flags(input.collapsed) | flags(input.pinched) == 0;
    let integer = (0..4).fold(true, |all, l| all & (input.factors[l] == input.segments[l] as f64));
    let [s0, s1, s2, s3] = input.segments;
    // Factors 1..=8 as 0..=7; a zero wraps to a large number.
    let factors = [s0, s1, s2, s3, input.interior[0], input.interior[1]].map(|n| n.wrapping_sub(1));
    let small = factors.iter().fold(0, |any, &n| any | n) < SMALL_INPUT_FACTOR;
    if !(plain & integer & small) {
        return None;
    }
    let tri = u32::from(input.domain == crate::domain::Domain::Tri);
    Some(factors.iter().fold(tri, |i, &n| i << SMALL_FACTOR_BITS | n))
}

/// Slots of [`RecentPatterns`]: a power of two.
const RECENT_PATTERNS: usize = 64;

/// The patterns a thread built recently, in a direct-mapped table by input hash: a build is
/// replaced only by one of another input with the same slot. Written by hand: a cache of
/// this shape (fixed size, no eviction policy, buffers kept per slot) is a few lines, and
/// the crates of the field with caches allocate per entry.
#[derive(Default)]
pub(crate) struct RecentPatterns {
    slots: Vec<RecentPattern>,
    /// The slot of the last request: neighbouring patches often share an input, and a
    /// comparison costs less than the hash.
    last: usize,
    /// The small inputs' patterns ([`small_input_index`]) of the current call.
    small: SmallInputTable<RecentPattern>,
}

#[derive(Default)]
pub(crate) struct RecentPattern {
    /// The call and input (its patch 0) `local` was built for; None when it holds nothing
    /// reusable (never built, or built for a pattern that depends on the patch).
    key: Option<(u64, PatternInput)>,
    pub(crate) local: LocalTessellation,
    /// `local`'s boundary vertices' parameters ([`boundary_params`]), valid when
    /// `with_params`.
    params: Vec<DVec2>,
    with_params: bool,
    /// [`Pattern::interior_grid`] of the input, found with the build: the engine asks it of
    /// every patch.
    pub(crate) interior_grid: Option<[u32; 2]>,
}

impl RecentPatterns {
    /// The slot holding `input`'s pattern for call `generation` (and its parameters, with
    /// `params`), built into it unless it is there already.
    pub(crate) fn get(
        &mut self,
        generation: u64,
        pattern: &dyn Pattern,
        input: &PatternInput,
        params: bool,
    ) -> &RecentPattern {
        let reusable = !pattern.depends_on_patch();
        // The key is made where it is needed: a copy of the input on every call read back,
        // just after the caller wrote it, stalled the load (different widths).
        let key = || (generation, PatternInput { patch: 0, ..*input });
        if let Some(index) = small_input_index(input).filter(|_| reusable) {
            let built = self.small.get_or_build(generation, index, |b: &mut RecentPattern| {
                b.build(pattern, input, Some(key()))
            });
            if let Some(slot) = built {
                slot.with_params(input, params);
                return slot;
            }
        }
        if self.slots.is_empty() {
            self.slots.resize_with(RECENT_PATTERNS, RecentPattern::default);
        }
        let key = key();
        let index = match reusable {
            true if self.slots[self.last].key == Some(key) => self.last,
            true => input_hash(input) as usize % RECENT_PATTERNS,
            false => 0,
        };
        self.last = index;
        let slot = &mut self.slots[index];
        if !reusable || slot.key != Some(key) {
            slot.build(pattern, input, reusable.then_some(key));
        }
        slot.with_params(input, params);
        slot
    }
}

impl RecentPattern {
    /// Builds `input`'s pattern here, for `key` (None: not to be reused).
    fn build(&mut self, pattern: &dyn Pattern, input: &PatternInput, key: Option<(u64, PatternInput)>) {
        pattern.build(input, &mut self.local);
        self.key = key;
        self.with_params = false;
        self.interior_grid = pattern.interior_grid(input);
    }

    /// Finds the parameters of the local vertices, with `params`, unless they are here.
    fn with_params(&mut self, input: &PatternInput, params: bool) {
        if params && !self.with_params {
            boundary_params(input, &mut self.params);
            self.with_params = true;
        }
    }
}

/// Bits of the indices one page of a [`SmallInputTable`] holds.
const PAGE_BITS: u32 = 10;

/// A page of a [`SmallInputTable`]: the places of `2^PAGE_BITS` consecutive indices.
type Page = [u16; 1 << PAGE_BITS];

/// Items of a call by [`small_input_index`], each built once a call and none evicted: a
/// direct read where a hashed table would hash every patch's input. Stale entries (an
/// earlier call's) are told by their key; the items' buffers are kept from call to call.
/// Memory: the items, and a 2 KiB page of places for each 1,024 consecutive indices in use
/// (the interior factors and the last edge's are the index's low bits, so a frame's inputs
/// share few pages), not the 1 MiB a flat table of every index would take on every thread.
pub(crate) struct SmallInputTable<T> {
    /// Each index's place in `items` by page (stale unless `keys` there holds the index).
    pages: Vec<Option<Box<Page>>>,
    keys: Vec<u32>,
    /// The first `count` are the current call's.
    items: Vec<T>,
    count: usize,
    generation: u64,
}

impl<T> Default for SmallInputTable<T> {
    fn default() -> Self {
        SmallInputTable { pages: Vec::new(), keys: Vec::new(), items: Vec::new(), count: 0, generation: 0 }
    }
}

impl<T: Default> SmallInputTable<T> {
    /// The item of `index` for call `generation` (a call's number, [`next_generation`]),
    /// made by `build` (on a reused or default item) unless the call made it already; None
    /// once the call has made as many items as a `u16` numbers. Cost: two reads; the build
    /// the first time in a call.
    pub(crate) fn get_or_build(
        &mut self,
        generation: u64,
        index: u32,
        build: impl FnOnce(&mut T),
    ) -> Option<&mut T> {
        if self.generation != generation {
            self.generation = generation;
            self.count = 0;
        }
        if self.pages.is_empty() {
            self.pages.resize_with(1 << (SMALL_INPUT_INDEX_BITS - PAGE_BITS), || None);
        }
        let page =
            self.pages[(index >> PAGE_BITS) as usize].get_or_insert_with(|| Box::new([0; 1 << PAGE_BITS]));
        let entry = &mut page[(index & ((1 << PAGE_BITS) - 1)) as usize];
        let place = *entry as usize;
        if place < self.count && self.keys[place] == index {
            return Some(&mut self.items[place]);
        }
        let place = self.count;
        if place > u16::MAX as usize {
            return None;
        }
        *entry = place as u16;
        if place == self.items.len() {
            self.items.push(T::default());
            self.keys.push(0);
        }
        self.count += 1;
        self.keys[place] = index;
        build(&mut self.items[place]);
        Some(&mut self.items[place])
    }
}

impl RecentPattern {
    /// The parameters of the pattern's local vertices (requested with `params`).
    pub(crate) fn params(&self) -> LocalParams<'_> {
        debug_assert!(self.with_params);
        LocalParams { boundary: &self.params, interior: &self.local.interior }
    }
}

static GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A number no earlier call got.
pub(crate) fn next_generation() -> u64 {
    GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1
}

thread_local! {
    static RECENT: std::cell::RefCell<RecentPatterns> = std::cell::RefCell::new(RecentPatterns::default());
}

/// Runs `f` with this thread's recent patterns (a fresh table if the thread's is in use
/// further up its stack, as when rayon runs another task inside a join). The a-posteriori
/// error check builds through it; the engine keeps its own in its per-thread scratch.
pub(crate) fn with_recent_patterns<R>(f: impl FnOnce(&mut RecentPatterns) -> R) -> R {
    with_thread_table(&RECENT, f)
}

/// Runs `f` with this thread's `table` (a fresh one if the thread's is in use further up its
/// stack, as when rayon runs another task inside a join).
pub(crate) fn with_thread_table<T: Default, R>(
    table: &'static std::thread::LocalKey<std::cell::RefCell<T>>,
    f: impl FnOnce(&mut T) -> R,
) -> R {
    table.with(|cell| match cell.try_borrow_mut() {
        Ok(mut table) => f(&mut table),
        Err(_) => f(&mut T::default()),
    })
}

impl std::fmt::Debug for PatternCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PatternCache").field("distinct", &self.inputs.len()).finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::Domain;
    use crate::pattern::uniform::Uniform;

    /// A pinched corner changes the triangulation ([`crate::pattern::cut_pinched_corners`]),
    /// so an input that differs from another only there is built apart, not shared.
    #[test]
    fn inputs_that_differ_only_in_pinched_corners_are_built_apart() {
        let plain = PatternInput::new(Domain::Quad, [2; 4], [2, 2]);
        let pinched = PatternInput { pinched: [false, true, false, false], ..plain };
        let mut cache = PatternCache::default();
        cache.fill_inputs(&Uniform, 2, |i| Some(if i == 0 { plain } else { pinched }), false);
        let (a, b) = (cache.get(0).unwrap(), cache.get(1).unwrap());
        assert_eq!(*a.input, plain);
        assert_eq!(*b.input, pinched);
        assert_ne!(a.local.triangles, b.local.triangles, "the pinched corner was not cut");
        let mut recent = RecentPatterns::default();
        let plain_triangles = recent.get(7, &Uniform, &plain, false).local.triangles.clone();
        assert_ne!(recent.get(7, &Uniform, &pinched, false).local.triangles, plain_triangles);
    }

    /// A pattern with a core grid is kept without its core, and the whole pattern is the
    /// core by its rule followed by what the cache holds; the parameters read through
    /// [`LocalParams`] are the whole table's.
    #[test]
    fn a_core_grid_is_left_out_and_its_rule_restores_the_pattern() {
        use crate::pattern::transition::Transition;
        let inputs = [
            PatternInput::new(Domain::Quad, [3, 5, 4, 7], [4, 6]),
            PatternInput::new(Domain::Quad, [6, 6, 6, 6], [6, 6]),
            PatternInput {
                pinched: [true, false, false, false],
                ..PatternInput::new(Domain::Quad, [2, 5, 3, 4], [3, 4])
            },
            PatternInput::new(Domain::Tri, [3, 5, 4, 1], [5, 5]),
        ];
        let mut cache = PatternCache::default();
        cache.fill_inputs(&Transition, inputs.len(), |i| Some(inputs[i]), true);
        let mut cores = 0;
        for (i, input) in inputs.iter().enumerate() {
            let mut whole = LocalTessellation::default();
            Transition.build(input, &mut whole);
            let (cached, params, _) = cache.params(i).expect("filled with parameters");
            let (rest, count) = cached.after_core();
            let mut flat = vec![0; 3 * count as usize];
            if let Some(core) = cached.core {
                core.write(input.interior_base(), |l| l, &mut flat);
                cores += 1;
            }
            flat.extend_from_slice(rest.as_flattened());
            assert_eq!(flat, whole.triangles.as_flattened(), "{input:?}");
            assert_eq!(cached.interior, whole.interior, "{input:?}");
            let mut table = Vec::new();
            local_params(input, &whole, &mut table);
            let read: Vec<DVec2> = (0..table.len() as u32).map(|l| params.get(l)).collect();
            assert_eq!(read, table, "{input:?}");
        }
        assert_eq!(cores, 2, "the unpinned quads have core grids, the others none");
        // Extended with inputs of new grids and of a grid it has: each reads its own grid.
        let more = [inputs[0], PatternInput::new(Domain::Quad, [5, 5, 2, 3], [5, 7]), inputs[1]];
        cache.forget_items();
        cache.extend_inputs(&Transition, more.len(), |i| Some(more[i]), false);
        for (i, input) in more.iter().enumerate() {
            let mut whole = LocalTessellation::default();
            Transition.build(input, &mut whole);
            assert_eq!(cache.get(i).expect("extended").interior, whole.interior, "{input:?}");
        }
    }
}
