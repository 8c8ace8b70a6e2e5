//! The Taylor bound ([`tessera::criterion::taylor`]) is an upper bound: on every patch and
//! mesh model, for random parameter triangles of every size and shape and for whole grids,
//! the error measured densely (the linear interpolant against the surface at 300–1,300
//! points a triangle) never exceeds it; and it is tight where triangles are small, and on
//! coarse triangles and grids through its refinements (a cubic's hull, a bicubic's split).

mod common;

use glam::DVec2;
use tessera::criterion::taylor::TaylorBound;
use tessera::io::{LoadOptions, SurfaceKind};
use tessera::surface::patch_tree::{Leaf, LeafPatch};
use tessera::surface::triangle_tree::TriangleLeafPatch;
use tessera::surface::{Domain, Patch, SurfaceSet};
use tessera::test_support::Lcg;

/// Largest `|S − L|` over the triangle `t` at the points of an order-`order` barycentric grid.
fn measured(patch: &Patch, t: [DVec2; 3], order: u32) -> f64 {
    let x = t.map(|q| patch.position(q));
    let mut worst = 0.0f64;
    for i in 0..=order {
        for j in 0..=order - i {
            let (a, b) = (i as f64 / order as f64, j as f64 / order as f64);
            let c = 1.0 - a - b;
            let q = t[0] * a + t[1] * b + t[2] * c;
            worst = worst.max((x[0] * a + x[1] * b + x[2] * c).distance(patch.position(q)));
        }
    }
    worst
}

fn inside(domain: Domain, q: DVec2) -> bool {
    let slack = 1e-12; // grid points computed as i·h may pass 1 in the last bit
    q.min_element() >= 0.0
        && q.max_element() <= 1.0 + slack
        && (domain == Domain::Quad || q.x + q.y <= 1.0 + slack)
}

/// A random triangle of the domain about `size` across (corners inside the domain).
fn random_triangle(rng: &mut Lcg, domain: Domain, size: f64) -> [DVec2; 3] {
    loop {
        let c = DVec2::new(rng.unit(), rng.unit());
        let t = [0, 1, 2].map(|_| c + (DVec2::new(rng.unit(), rng.unit()) - 0.5) * size);
        if t.iter().all(|&q| inside(domain, q)) {
            return t;
        }
    }
}

/// Largest [`measured`] error over every triangle of the `nu × nv` grid of the domain: a
/// quad's cells split either way, a triangle's the lattice's way (the halves inside it).
fn measured_grid(patch: &Patch, domain: Domain, [nu, nv]: [u32; 2], order: u32) -> f64 {
    let (hu, hv) = (1.0 / nu as f64, 1.0 / nv as f64);
    let mut error = 0.0f64;
    for i in 0..nu {
        for j in 0..nv {
            let o = DVec2::new(i as f64 * hu, j as f64 * hv);
            let [a, b, c, d] = [o, o + DVec2::new(hu, 0.0), o + DVec2::new(0.0, hv), o + DVec2::new(hu, hv)];
            let halves = if domain == Domain::Quad {
                &[[a, b, c], [b, d, c], [a, b, d], [a, d, c]][..]
            } else {
                &[[a, b, c], [b, d, c]][..]
            };
            for &t in halves {
                if t.iter().all(|&q| inside(domain, q)) {
                    error = error.max(measured(patch, t, order));
                }
            }
        }
    }
    error
}

/// The bound over triangle `t` is at least the error [`measured`] finds at order `order` (up
/// to `1e-9` of it and `floor`, the rounding of flat patches); returns both.
fn assert_triangle_holds(
    patch: &Patch,
    taylor: &TaylorBound,
    t: [DVec2; 3],
    order: u32,
    floor: f64,
    name: &str,
) -> (f64, f64) {
    let bound = taylor.triangle_error(t);
    let error = measured(patch, t, order);
    assert!(error <= bound * (1.0 + 1e-9) + floor, "{name}: {t:?} measured {error:e} > bound {bound:e}");
    (error, bound)
}

/// The bound over the whole `n` grid of `domain` is at least the error [`measured_grid`]
/// finds at order `order` (up to `1e-9` of it and `floor`, the rounding of flat patches);
/// returns both.
fn assert_grid_holds(
    patch: &Patch,
    taylor: &TaylorBound,
    domain: Domain,
    n: [u32; 2],
    order: u32,
    floor: f64,
    name: &str,
) -> (f64, f64) {
    let bound = taylor.grid_error(domain == Domain::Tri, n);
    let error = measured_grid(patch, domain, n, order);
    assert!(error <= bound * (1.0 + 1e-9) + floor, "{name}: grid {n:?} measured {error:e} > bound {bound:e}");
    (error, bound)
}

/// The bound's second derivatives at `x` are the patch's: central differences of step `h`
/// (where the stencil lies in one smooth piece), to 1e-4 of their size.
fn assert_second_derivatives(patch: &Patch, taylor: &TaylorBound, x: DVec2, h: f64, name: &str) {
    let f = |dx: f64, dy: f64| patch.position(x + DVec2::new(dx, dy));
    let want = [
        (f(h, 0.0) - 2.0 * f(0.0, 0.0) + f(-h, 0.0)) / (h * h),
        (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h),
        (f(0.0, h) - 2.0 * f(0.0, 0.0) + f(0.0, -h)) / (h * h),
    ];
    let got = taylor.second_derivatives(x);
    let scale = want.iter().map(|w| w.length()).fold(1.0, f64::max);
    for k in 0..3 {
        assert!(got[k].distance(want[k]) < 1e-4 * scale, "{name} at {x}: {k}: {got:?} {want:?}");
    }
}

#[test]
fn the_taylor_bound_holds_on_every_model() {
    let mut rng = Lcg(2027);
    let mut small_ratios = Vec::new();
    // Coarse triangles and grids, where the refinements (hull, split) carry the bound.
    let mut coarse_ratios = Vec::new();
    for path in common::all_surface_models() {
        let set = common::load(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        // Every patch of a small model, about 60 of a large one.
        let step = (set.patches.len() / 60).max(1);
        let mut covered = 0;
        for patch in set.patches.iter().step_by(step) {
            let taylor = TaylorBound::of(patch);
            if !taylor.is_some() {
                continue;
            }
            covered += 1;
            let domain = patch.domain();
            for size in [1.0, 0.4, 0.1, 0.02] {
                let t = random_triangle(&mut rng, domain, size);
                let (error, bound) = assert_triangle_holds(patch, &taylor, t, 24, 1e-15, &name);
                if size <= 0.02 && bound > 0.0 {
                    small_ratios.push(error / bound);
                }
                if size >= 0.4 && bound > 0.0 {
                    coarse_ratios.push((domain, error / bound));
                }
            }
            // A whole grid: a quad's cells split either way, a triangle's the lattice's way.
            let n = [1 + rng.below(6) as u32, 1 + rng.below(6) as u32];
            let n = if domain == Domain::Tri { [n[0], n[0]] } else { n };
            let (error, bound) = assert_grid_holds(patch, &taylor, domain, n, 12, 1e-15, &name);
            if bound > 0.0 {
                coarse_ratios.push((domain, error / bound));
            }
        }
        assert!(covered > 0, "{name}: no patch with a Taylor bound");
        println!("{name}: {covered} patches");
    }
    // Small triangles: the remainder is small, so the bound is near the truth (the triangle
    // inequality inside a triangle, and the order-24 sampling, are the rest of the slack).
    small_ratios.sort_by(f64::total_cmp);
    let median = small_ratios[small_ratios.len() / 2];
    let tenth = small_ratios[small_ratios.len() / 10];
    println!(
        "{} small triangles: measured / bound median {median:.3}, 10th percentile {tenth:.3}",
        small_ratios.len()
    );
    assert!(
        median >= 0.8 && tenth >= 0.5,
        "measured / bound on small triangles: median {median}, 10th percentile {tenth}"
    );
    for domain in [Domain::Quad, Domain::Tri] {
        let mut ratios: Vec<f64> = coarse_ratios.iter().filter(|r| r.0 == domain).map(|r| r.1).collect();
        ratios.sort_by(f64::total_cmp);
        let median = ratios[ratios.len() / 2];
        let tenth = ratios[ratios.len() / 10];
        println!(
            "{} coarse triangles and grids, {domain:?} domain: measured / bound median {median:.3}, \
             10th percentile {tenth:.3}",
            ratios.len()
        );
        assert!(
            median >= 0.85 && tenth >= 0.75,
            "measured / bound on coarse {domain:?} triangles and grids: median {median}, 10th percentile {tenth}"
        );
    }
}

/// Catmull-Clark patch trees: a triangle or grid cell inside one Bézier leaf takes the leaf's
/// bound, in the leaf's parameters, whatever the patch's turn, transposition or quadrant; one
/// across leaves or on an end cap the sampled refinement of the tree's second-derivative
/// bound. Measured as above, on cages with extraordinary vertices, creases, n-gons and end
/// caps; and the leaves' second derivatives, taken to the patch's parameters, are the
/// patch's. (`criterion::taylor`'s unit tests check which triangles a leaf answers for.)
#[test]
fn the_taylor_bound_holds_on_catmull_clark_trees() {
    let mut rng = Lcg(2028);
    let cages = [
        "catmark_pole8.obj",
        "catmark_torus_creases0.obj",
        "catmark_nonquads.obj",
        "catmark_xord_interior.obj",
        "catmark_cube_creases1.obj",
        "catmark_gregory_test3.obj",
        "catmark_rook.obj",
    ];
    let mut ratios = Vec::new();
    let mut stencils = 0;
    for cage in cages {
        let path = common::model(&format!("subdivision/{cage}"));
        let options = LoadOptions { surface: SurfaceKind::CatmullClark, ..Default::default() };
        let set = tessera::io::load(&path, options).unwrap();
        let mut covered = 0;
        for patch in &set.patches {
            let Patch::Subdivision(tree) = patch else { continue };
            let taylor = TaylorBound::of(patch);
            covered += 1;
            for size in [0.5, 0.1, 0.02, 0.005] {
                for _ in 0..4 {
                    let t = random_triangle(&mut rng, Domain::Quad, size);
                    let (error, bound) = assert_triangle_holds(patch, &taylor, t, 16, 1e-15, cage);
                    if size <= 0.02 && bound > 0.0 {
                        ratios.push(error / bound);
                    }
                    // The leaf's second derivatives, taken to the patch's parameters, are the
                    // patch's (central differences, where the stencil's box lies in one
                    // Bézier leaf).
                    let x = (t[0] + t[1] + t[2]) / 3.0;
                    let h = 1e-4;
                    let (lo, hi) = (x - DVec2::splat(h), x + DVec2::splat(h));
                    let leaf = |q: DVec2| tree.locate(q).0 as *const Leaf;
                    let box_in_leaf = [DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)]
                        .iter()
                        .all(|&q| leaf(q) == leaf(lo))
                        && matches!(tree.locate(lo).0.patch, LeafPatch::Bezier(_));
                    if box_in_leaf && size <= 0.1 {
                        stencils += 1;
                        assert_second_derivatives(patch, &taylor, x, h, cage);
                    }
                }
            }
            let n = [1 + rng.below(12) as u32, 1 + rng.below(12) as u32];
            assert_grid_holds(patch, &taylor, Domain::Quad, n, 8, 1e-15, cage);
        }
        assert!(covered > 0, "{cage}: no patch tree");
    }
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    println!(
        "{} small triangles: measured / bound median {median:.3}; {stencils} second-derivative checks",
        ratios.len()
    );
    assert!(stencils >= 100, "only {stencils} second-derivative checks inside one leaf");
    assert!(median >= 0.8, "measured / bound on small triangles of trees: median {median}");
}

/// The sampled refinement of the second-derivative bound, for the kinds without a Taylor
/// expansion: rational bicubics (the teapot and the torus with weights that vary with
/// position). (A Loop tree's triangles across leaves and on Gregory triangles take it too:
/// the next test.) Measured as above (flat patches, whose bound is 0, measure rounding: 1e-13).
#[test]
fn the_sampled_bound_holds_on_rational_patches() {
    let mut rng = Lcg(2029);
    let mut sets = Vec::new();
    for rel in ["patches/teapot.patches", "bench/torus_64x32.patches"] {
        let file = tessera::io::patches::read_patches(&common::model(rel)).unwrap();
        sets.push((
            rel.to_string(),
            SurfaceSet::from_patch_file(&tessera::scene::position_weights(&file), Default::default()),
        ));
    }
    let (mut ratios, mut hessian_ratios) = (Vec::new(), Vec::new());
    for (name, set) in sets {
        let step = (set.patches.len() / 40).max(1);
        for patch in set.patches.iter().step_by(step) {
            let taylor = TaylorBound::of(patch);
            let hessian = tessera::criterion::bounds::hessian(patch);
            let domain = patch.domain();
            for size in [1.0, 0.3, 0.05] {
                let t = random_triangle(&mut rng, domain, size);
                let (error, bound) = assert_triangle_holds(patch, &taylor, t, 16, 1e-13, &name);
                assert!(
                    bound <= hessian.triangle_error(t) * (1.0 + 1e-12),
                    "{name}: never above the second-derivative bound"
                );
                if bound > 0.0 {
                    ratios.push(error / bound);
                    hessian_ratios.push(error / hessian.triangle_error(t));
                }
            }
            let n = 1 + rng.below(5) as u32;
            assert_grid_holds(patch, &taylor, domain, [n, n], 8, 1e-13, &name);
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (refined, plain) = (median(ratios), median(hessian_ratios));
    println!("measured / bound median {refined:.3}, with the second-derivative bound alone {plain:.3}");
    // These kinds' second-derivative bounds are loose, and the refinement keeps 1/16 of it
    // as its margin: it gains, not all.
    assert!(refined >= 4.0 * plain, "measured / bound: refined {refined}, plain {plain}");
}

/// Loop patches: a regular one (one quartic box-spline piece, in the patch's parameters
/// whether or not its tree is swapped) takes its quartic's Taylor expansion; an isolated one
/// answers a triangle from the quartic leaf that holds it, in that leaf's parameters, and
/// anything else (across leaves, on a Gregory triangle) from the sampled bound. Measured as
/// above on every Loop cage and the Killeroo cage, each patch as it is and flipped: the bound
/// holds, its second derivatives are the patch's, and on small triangles it is tight.
#[test]
fn the_taylor_bound_holds_on_loop_patches() {
    let mut rng = Lcg(2030);
    let (mut regular_ratios, mut isolated_ratios, mut sampled_ratios) = (Vec::new(), Vec::new(), Vec::new());
    let (mut swapped, mut stencils) = (0, 0);
    let mut files = tessera::test_support::data_files("subdivision", &["loop_"]);
    files.push(common::model("meshes/killeroo_cage.obj"));
    for path in files {
        let cage = path.file_name().unwrap().to_string_lossy().into_owned();
        let options = LoadOptions { surface: SurfaceKind::Loop, ..Default::default() };
        // (A non-manifold cage is refused: nothing to bound.)
        let Ok(set) = tessera::io::load(&path, options) else { continue };
        let step = (set.patches.len() / 40).max(1);
        // Each patch as it is and flipped (its tree swapped: `u` and `v` exchanged).
        let patches = set.patches.iter().step_by(step).flat_map(|p| [p.clone(), p.flipped()]);
        for patch in patches {
            let patch = &patch;
            let Patch::Loop(tree) = patch else { continue };
            let regular = tree.regular().is_some();
            swapped += usize::from(tree.is_swapped());
            let taylor = TaylorBound::of(patch);
            let hessian = tessera::criterion::bounds::hessian(patch);
            for size in [1.0, 0.3, 0.05, 0.01] {
                let t = random_triangle(&mut rng, Domain::Tri, size);
                let (error, bound) = assert_triangle_holds(patch, &taylor, t, 16, 1e-13, &cage);
                // One quartic leaf holds the triangle (by the leaf of each corner).
                let one_leaf = {
                    let leaves = t.map(|q| tree.find(q).0);
                    leaves.iter().all(|&l| l == leaves[0])
                        && matches!(tree.leaves()[leaves[0]].patch, TriangleLeafPatch::Quartic(_))
                };
                if size <= 0.05 && bound > 0.0 && one_leaf {
                    let ratios = if regular { &mut regular_ratios } else { &mut isolated_ratios };
                    ratios.push(error / bound);
                    sampled_ratios.push(error / hessian.triangle_error(t));
                }
                // The leaf's second derivatives, taken to the patch's parameters, are the
                // patch's (central differences, where the stencil lies in one quartic leaf).
                let x = (t[0] + t[1] + t[2]) / 3.0;
                let h = 1e-4;
                let stencil = [-1.0, 0.0, 1.0].map(|a| [-1.0, 0.0, 1.0].map(|b| x + DVec2::new(a, b) * h));
                let in_leaf =
                    stencil.as_flattened().iter().all(|&q| {
                        q.min_element() >= 0.0 && q.x + q.y <= 1.0 && tree.find(q).0 == tree.find(x).0
                    }) && matches!(tree.leaves()[tree.find(x).0].patch, TriangleLeafPatch::Quartic(_));
                if in_leaf && size <= 0.3 {
                    stencils += 1;
                    assert_second_derivatives(patch, &taylor, x, h, &cage);
                }
            }
            let n = 1 + rng.below(6) as u32;
            assert_grid_holds(patch, &taylor, Domain::Tri, [n, n], 8, 1e-13, &cage);
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let counts = (regular_ratios.len(), isolated_ratios.len());
    let (regular, isolated, plain) =
        (median(regular_ratios), median(isolated_ratios), median(sampled_ratios));
    println!(
        "small triangles in one quartic leaf ({counts:?} regular, isolated): measured / bound median \
         {regular:.3} regular, {isolated:.3} isolated (second-derivative bound {plain:.3}); \
         {swapped} swapped trees, {stencils} second-derivative checks"
    );
    assert!(swapped > 0 && stencils >= 100, "{swapped} swapped, {stencils} second-derivative checks");
    assert!(regular >= 0.8 && isolated >= 0.8, "measured / bound: {regular} regular, {isolated} isolated");
}

/// Asserts that edge `e` of `patch` (over `domain`) cut into `n` equal parts is within
/// `bound/(8n²)` of its chords (what a boundary-curve bound promises), measured at 33 points a
/// part; returns measured / promised, None where the promise is zero.
fn assert_curve_within(
    name: &str,
    patch: &Patch,
    domain: Domain,
    e: usize,
    n: u32,
    bound: f64,
) -> Option<f64> {
    let at = |t: f64| patch.position(domain.edge_point(e, t));
    let mut worst = 0.0f64;
    for k in 0..n {
        let (t0, t1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let (a, b) = (at(t0), at(t1));
        for j in 0..=32 {
            let s = j as f64 / 32.0;
            worst = worst.max(at(t0 + (t1 - t0) * s).distance(a * (1.0 - s) + b * s));
        }
    }
    let promised = bound / (8.0 * (n * n) as f64);
    assert!(
        worst <= promised * (1.0 + 1e-9) + 1e-12,
        "{name}: edge {e}, {n} parts: {worst:e} > {promised:e}"
    );
    (promised > 0.0).then(|| worst / promised)
}

/// The boundary curves' bounds the proposals read (`tolerance::curve_bounds`: a regular Loop
/// patch's quartic edges, an isolated one's leaves along each edge) bound what they promise:
/// a boundary curve cut into `n` equal parts is within `M/(8n²)` of its chords, measured at 33
/// points a part, on every Loop patch of the Loop cages and the Killeroo cage, as it is and
/// flipped.
#[test]
fn loop_boundary_curve_bounds_hold() {
    let mut files = tessera::test_support::data_files("subdivision", &["loop_"]);
    files.push(common::model("meshes/killeroo_cage.obj"));
    let mut rng = Lcg(2031);
    let (mut checked, mut ratios) = (0, Vec::new());
    for path in files {
        let options = LoadOptions { surface: SurfaceKind::Loop, ..Default::default() };
        let Ok(set) = tessera::io::load(&path, options) else { continue };
        let step = (set.patches.len() / 60).max(1);
        let patches: Vec<Patch> =
            set.patches.iter().step_by(step).flat_map(|p| [p.clone(), p.flipped()]).collect();
        let flipped = SurfaceSet::from_patches(patches, Default::default());
        let hessians: Vec<_> = flipped.patches.iter().map(tessera::criterion::bounds::hessian).collect();
        let curves = tessera::criterion::tolerance::curve_bounds(&flipped, &hessians);
        for (patch, m) in flipped.patches.iter().zip(&curves) {
            for (e, &bound) in m.iter().enumerate().take(3) {
                let n = 1 + rng.below(6) as u32;
                let name = path.display().to_string();
                ratios.extend(assert_curve_within(&name, patch, Domain::Tri, e, n, bound));
                checked += 1;
            }
        }
    }
    ratios.sort_by(f64::total_cmp);
    println!("{checked} boundary curves; measured / promised median {:.3}", ratios[ratios.len() / 2]);
    assert!(checked > 300, "only {checked} curves");
}

/// A Catmull-Clark patch's boundary-curve bounds (`tolerance::curve_bounds`: the cubic sides
/// of the leaves along each edge, `bounds::tree_curve_bounds`) bound what they promise: a
/// boundary curve cut into `n` equal parts is within `M/(8n²)` of its chords, measured at 33
/// points a part, on every isolated patch of the Catmull-Clark cages, in every view an engine
/// makes of a tree (transposed, turned, a quarter). They are tighter than the patch's own
/// second-derivative bound along the edge, which the proposals read before: the median
/// ratio is reported and must be below one half.
#[test]
fn catmull_clark_boundary_curve_bounds_hold() {
    use tessera::criterion::{bounds, tolerance};
    let files = tessera::test_support::data_files("subdivision", &["catmark_"]);
    let mut rng = Lcg(2032);
    let (mut checked, mut ratios, mut tighter) = (0, Vec::new(), Vec::new());
    for path in files {
        let options = LoadOptions { surface: SurfaceKind::CatmullClark, ..Default::default() };
        let Ok(set) = tessera::io::load(&path, options) else { continue };
        let trees: Vec<_> = set
            .patches
            .iter()
            .filter_map(|p| match p {
                Patch::Subdivision(t) => Some(t),
                _ => None,
            })
            .collect();
        let step = (trees.len() / 12).max(1);
        for tree in trees.into_iter().step_by(step) {
            let views = [
                (**tree).clone(),
                tree.transposed(),
                tree.rotated(1),
                tree.rotated(3).transposed(),
                tree.quadrant(rng.below(4)),
                tree.quadrant(rng.below(4)).quadrant(rng.below(4)).rotated(2),
            ];
            for view in views {
                let patch = Patch::Subdivision(Box::new(view));
                let h = bounds::hessian(&patch);
                let m = tolerance::patch_curve_bounds(&patch, &h);
                for (e, &bound) in m.iter().enumerate() {
                    let n = 1 + rng.below(6) as u32;
                    let name = path.display().to_string();
                    ratios.extend(assert_curve_within(&name, &patch, Domain::Quad, e, n, bound));
                    checked += 1;
                    let whole = if e % 2 == 0 { h.uu } else { h.vv };
                    if whole > 0.0 {
                        tighter.push(bound / whole);
                    }
                }
            }
        }
    }
    ratios.sort_by(f64::total_cmp);
    tighter.sort_by(f64::total_cmp);
    let (measured, against) = (ratios[ratios.len() / 2], tighter[tighter.len() / 2]);
    println!("{checked} boundary curves; measured / promised median {measured:.3}; bound / the patch's own {against:.3}");
    assert!(checked > 1000, "only {checked} curves");
    assert!(against < 0.75, "the leaves' sides bound the curves at {against} of the patch's bound");
}

/// On cages with Gregory end caps the Taylor bound's plans take a small share of the
/// second-derivative bound's triangles at the same guarantee: a boundary curve is bounded by
/// the leaves' sides along it and the sampled bound's margin is `1/64` of the (loose)
/// second-derivative bound. Transition at 0.1 %, each share below its ceiling (before both
/// changes: 0.31, 0.32, 0.49, 0.46), the error measured against the limit surface within
/// the tolerance and at least 0.6 of the certified bound.
#[test]
fn the_taylor_bound_plans_cages_with_end_caps_tightly() {
    use tessera::engine::{tessellate, EngineOptions};
    use tessera::scheme::{Criterion, ErrorBound, PlanOptions, Scheme};
    let cages = [
        ("subdivision/catmark_cube.obj", SurfaceKind::CatmullClark, 0.25),
        ("subdivision/catmark_helmet.obj", SurfaceKind::CatmullClark, 0.25),
        ("subdivision/loop_pole8.obj", SurfaceKind::Loop, 0.1),
        ("subdivision/loop_xord_interior.obj", SurfaceKind::Loop, 0.1),
    ];
    for (cage, surface, ceiling) in cages {
        let set =
            tessera::io::load(&common::model(cage), LoadOptions { surface, ..Default::default() }).unwrap();
        let (lo, hi) = set.bounds();
        let eps = 1e-3 * lo.distance(hi);
        let mut triangles = [0usize; 2];
        for (k, bound) in [ErrorBound::Hessian, ErrorBound::Taylor].into_iter().enumerate() {
            // The second-derivative bound needs more than the default cap on the helmet.
            let options = PlanOptions { bound, max_factor: 1024, ..PlanOptions::default() };
            let planned = Scheme::Transition.plan(&set, &Criterion::Tolerance(eps), &options).unwrap();
            let report = planned.report.expect("a tolerance plan reports its bound");
            assert_eq!(report.capped_patches, 0, "{cage} {bound:?}");
            let options = EngineOptions { corner_params: true, ..Default::default() };
            let mesh = tessellate(&set, &planned.plan, &planned.pattern, options).unwrap();
            triangles[k] = mesh.triangle_count();
            if bound == ErrorBound::Taylor {
                let err = tessera::verify::approximation_error(&mesh, &set, 5).unwrap();
                assert!(err.max <= eps, "{cage}: measured {:.3e} > {eps:.3e}", err.max);
                let tight = err.max / report.worst_bound;
                assert!(tight >= 0.6, "{cage}: measured / bound {tight:.3}");
            }
        }
        let share = triangles[1] as f64 / triangles[0] as f64;
        println!("{cage}: {} against {} triangles ({share:.3})", triangles[1], triangles[0]);
        assert!(
            share <= ceiling,
            "{cage}: the Taylor bound's plan has {share:.3} of the Hessian bound's triangles"
        );
    }
}
